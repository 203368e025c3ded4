// Read planning, decoding and encoding of profile signals.
#include "drivers/profile_devices/signal_io.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "drivers/error.hpp"
#include "drivers/profile/signal_codes.hpp"

namespace synbench::drivers {

ReadPlan::ReadPlan(const DeviceProfile& profile, std::initializer_list<std::string_view> names) {
  plan(profile, std::span<const std::string_view>(names.begin(), names.size()));
}

ReadPlan::ReadPlan(const DeviceProfile& profile, std::span<const std::string_view> names) {
  plan(profile, names);
}

void ReadPlan::plan(const DeviceProfile& profile, std::span<const std::string_view> names) {
  slots_.resize(names.size());
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const ProfileSignal* s = profile.find(names[i]);
    if (!s || !s->readable()) continue;
    slots_[i].signal = s;
    order.push_back(i);
  }
  auto key = [&](std::size_t i) {
    const ProfileSignal& s = *slots_[i].signal;
    return std::make_tuple(s.unit_id, static_cast<int>(s.kind), s.address);
  };
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  // One request per run of adjacent signals of one table and unit id, within the protocol's
  // limit. Gaps are not bridged: a device may refuse to read addresses it does not map.
  for (const std::size_t i : order) {
    const ProfileSignal& s = *slots_[i].signal;
    const std::size_t max = is_bit_kind(s.kind) ? kMaxReadBits : kMaxReadRegisters;
    Request* last = requests_.empty() ? nullptr : &requests_.back();
    const bool joins = last && last->unit_id == s.unit_id && last->kind == s.kind &&
                       s.address >= last->address &&
                       s.address <= last->address + last->count &&
                       static_cast<std::size_t>(s.last_address() - last->address + 1) <= max;
    if (!joins) {
      requests_.push_back({s.unit_id, s.kind, s.address, 0, words_});
      last = &requests_.back();
    }
    const auto end = std::max<std::size_t>(last->address + last->count, s.last_address() + 1u);
    const auto grown = static_cast<std::uint16_t>(end - last->address);
    words_ += grown - last->count;
    last->count = grown;
    slots_[i].request = requests_.size() - 1;
    slots_[i].offset = s.address - last->address;
  }
}

bool SignalIo::may_repeat(std::error_code ec, int repeats, double first_s) const {
  if (!ec || repeats >= policy_.max_retries || !retryable(ec, bus_.last_exception_code())) return false;
  return !clock_ || clock_->now_s() - first_s < policy_.budget_s;
}

template <class Request>
std::error_code SignalIo::with_retries(bool idempotent, Request&& request) {
  const double first_s = now_s();
  std::error_code ec = request();
  for (int i = 0; idempotent && may_repeat(ec, i, first_s); ++i) {
    ++repeats_;
    ec = request();
  }
  return ec;
}

std::error_code SignalIo::read(const ReadPlan& plan, std::span<double> values) {
  if (values.size() < plan.size()) return make_error_code(errc::invalid_argument);
  words_.resize(plan.words_);
  bits_.resize(plan.words_);
  for (const ReadPlan::Request& r : plan.requests_) {
    const auto ec = with_retries(true, [&] {
      if (is_bit_kind(r.kind))
        return bus_.read_bits(r.unit_id, r.kind, r.address, std::span(bits_).subspan(r.buffer_offset, r.count));
      return bus_.read_registers(r.unit_id, r.kind, r.address, std::span(words_).subspan(r.buffer_offset, r.count));
    });
    if (ec) return ec;
  }
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const ReadPlan::Slot& slot = plan.slots_[i];
    if (!slot.signal) {
      values[i] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    const ProfileSignal& s = *slot.signal;
    const std::size_t at = plan.requests_[slot.request].buffer_offset + slot.offset;
    double v = 0;
    if (is_bit_kind(s.kind)) {
      bool on = false;
      if (auto ec = decode_bit(bits_[at], on)) return ec;
      v = on ? 1.0 : 0.0;
    } else {
      if (auto ec = decode_registers(s.encoding, std::span(words_).subspan(at, address_width(s.encoding.type)), v))
        return ec;
    }
    if (auto ec = to_bench_code(profile_.kind, s, v, values[i])) return ec;
  }
  return {};
}

std::error_code SignalIo::write(std::string_view signal, double value) {
  const ProfileSignal* s = profile_.find(signal);
  if (!s || !s->writable() || !is_writable_kind(s->kind)) return make_error_code(errc::not_supported);
  double device_value = 0;
  if (auto ec = to_device_value(profile_.kind, *s, value, device_value)) return ec;
  const bool idempotent = s->role != SignalRole::window_start;
  if (s->kind == RegisterKind::coil) {
    if (device_value != 0 && device_value != 1) return make_error_code(errc::invalid_argument);
    const std::uint8_t bit = encode_bit(device_value != 0);
    return with_retries(idempotent, [&] { return bus_.write_bits(s->unit_id, s->address, std::span(&bit, 1)); });
  }
  std::uint16_t words[2];
  const std::size_t n = address_width(s->encoding.type);
  if (auto ec = encode_registers(s->encoding, device_value, std::span(words, n))) return ec;
  return with_retries(idempotent, [&] {
    return bus_.write_registers(s->unit_id, s->address, std::span<const std::uint16_t>(words, n));
  });
}

}  // namespace synbench::drivers
