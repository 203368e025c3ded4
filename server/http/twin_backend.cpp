// The in-process twin as a BenchBackend; see bench_backend.hpp.
#include "emulator/twin_bench.hpp"
#include "server/http/bench_backend.hpp"

namespace synbench::http {
namespace {

class TwinBackend final : public BenchBackend {
 public:
  explicit TwinBackend(const emulator::TwinConfig& config) : twin_(config), b1_(config.load.b1_Nms_per_rad) {}
  drivers::BenchDevices devices() override { return twin_.devices(); }
  drivers::Clock& clock() override { return twin_.clock(); }
  nlohmann::json describe() const override {
    const auto dev = [](const char* role, const char* kind) {
      return nlohmann::json{{"role", role}, {"kind", kind}, {"backend", "twin"}, {"link", "in-process"}, {"profile", nullptr}};
    };
    return nlohmann::json::array({dev("synrm", "synrm_drive"), dev("load", "load_drive"), dev("meter", "vfc_meter"),
                                  dev("trigger", "window_trigger"), dev("truth", "truth_probe")});
  }
  double load_b1_Nms_per_rad() const override { return b1_; }

 private:
  emulator::TwinBench twin_;
  double b1_;
};

}  // namespace

std::unique_ptr<BenchBackend> make_twin_backend(const emulator::TwinConfig& config) {
  return std::make_unique<TwinBackend>(config);
}

}  // namespace synbench::http
