// Messages of synbench's error category.
#include "drivers/error.hpp"

#include <string>

namespace synbench {
namespace {

class Category final : public std::error_category {
 public:
  const char* name() const noexcept override { return "synbench"; }
  std::string message(int ev) const override {
    switch (static_cast<errc>(ev)) {
      case errc::ok: return "ok";
      case errc::timeout: return "device did not answer within the response timeout";
      case errc::disconnected: return "link to the device is down";
      case errc::protocol: return "malformed or mismatched reply";
      case errc::exception_reply: return "device answered with an exception";
      case errc::invalid_argument: return "value outside the signal's limits";
      case errc::not_supported: return "the device has no such signal";
      case errc::device_fault: return "the device reports a latched fault";
      case errc::busy: return "a measurement window is already open";
      case errc::not_ready: return "result not yet available";
    }
    return "unknown synbench error";
  }
};

}  // namespace

const std::error_category& error_category() noexcept {
  static const Category category;
  return category;
}

}  // namespace synbench
