// Read planning, decoding and encoding of profile signals.
#include "drivers/profile_devices/signal_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <tuple>

#include "drivers/error.hpp"
#include "drivers/profile/number_format.hpp"
#include "drivers/profile/signal_codes.hpp"

namespace synbench::drivers {

ReadPlan::ReadPlan(const DeviceProfile& profile, std::initializer_list<std::string_view> names) {
  plan(profile, std::span<const std::string_view>(names.begin(), names.size()));
}

ReadPlan::ReadPlan(const DeviceProfile& profile, std::span<const std::string_view> names) {
  plan(profile, names);
}

std::size_t ReadPlan::index(std::string_view signal) const {
  return static_cast<std::size_t>(std::find(names_.begin(), names_.end(), signal) - names_.begin());
}

void ReadPlan::plan(const DeviceProfile& profile, std::span<const std::string_view> names) {
  slots_.resize(names.size());
  names_.assign(names.begin(), names.end());
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

namespace {

std::string hex_words(std::span<const std::uint16_t> words) {
  std::string out;
  char buf[8];
  for (const std::uint16_t w : words) {
    std::snprintf(buf, sizeof buf, "0x%04X", static_cast<unsigned>(w));
    out += (out.empty() ? "" : " ") + std::string(buf);
  }
  return out;
}

std::string place(const ProfileSignal& s) {
  std::string where = std::string(name(s.kind)) + " " + std::to_string(s.address);
  if (s.last_address() != s.address) where += ".." + std::to_string(s.last_address());
  if (s.masked()) where += " mask " + std::to_string(s.mask);
  return where + ", unit id " + std::to_string(s.unit_id);
}

std::string limits_of(const RegisterEncoding& e) {
  return "limits " + format_number(e.min) + ".." + format_number(e.max);
}

// A masked signal is a field of its word; any other spans address_width(type) words.
std::error_code decode_words(const RegisterEncoding& e, std::uint16_t mask, std::span<const std::uint16_t> words,
                             double& value) {
  return mask ? decode_field(e, mask, words[0], value) : decode_registers(e, words, value);
}

// Why words did not decode: decoded again without the limits (and through the same mask), so
// the message has the value the device sent, not just "out of range".
std::string why_not(const RegisterEncoding& e, std::uint16_t mask, std::span<const std::uint16_t> words) {
  RegisterEncoding open = e;
  open.min = -std::numeric_limits<double>::infinity();
  open.max = std::numeric_limits<double>::infinity();
  double v = 0;
  // The mask is already in the message's place (SignalIo::fail).
  const std::string encoding = " (" + std::string(name(e.type)) + ", scale " + format_number(e.scale) + ", offset " +
                               format_number(e.offset) + ")";
  if (decode_words(open, mask, words, v)) return "not a finite " + std::string(name(e.type)) + encoding;
  return format_number(v) + " is outside the profile's limits [" + format_number(e.min) + ", " +
         format_number(e.max) + "]" + encoding;
}

}  // namespace

std::string SignalIo::device() const { return std::string(name(profile_.kind)) + " '" + profile_.name + "'"; }

std::error_code SignalIo::fail(std::error_code ec, const ProfileSignal* s, std::string what) {
  last_error_ = device() + (s ? ": signal " + s->name + " (" + place(*s) + ")" : std::string()) + ": " + what;
  return ec;
}

std::error_code SignalIo::decode(const ProfileSignal& s, std::span<const std::uint16_t> all_words, std::size_t at,
                                 double& bench_value, double& device_value) {
  if (is_bit_kind(s.kind)) {
    bool on = false;
    if (auto ec = decode_bit(bits_[at], on))
      return fail(ec, &s, "raw " + std::to_string(bits_[at]) + ": a bit reads 0 or 1");
    device_value = on ? 1.0 : 0.0;
  } else {
    const auto words = all_words.subspan(at, address_width(s.encoding.type));
    RegisterEncoding e = s.encoding;
    // A fault code is never out of range: a code the profile has no label for is a fault too.
    if (is_fault_code(s)) {
      e.min = -std::numeric_limits<double>::infinity();
      e.max = std::numeric_limits<double>::infinity();
    }
    const auto ec = decode_words(e, s.mask, words, device_value);
    if (ec) return fail(ec, &s, "raw " + hex_words(words) + ": " + why_not(e, s.mask, words));
  }
  if (auto ec = to_bench_code(profile_.kind, s, device_value, bench_value)) {
    const std::size_t n = is_bit_kind(s.kind) ? 0 : address_width(s.encoding.type);
    return fail(ec, &s, (n ? "raw " + hex_words(all_words.subspan(at, n)) + ": " : "") +
                            "device code " + format_number(device_value) + " has no label and no \"otherwise\"");
  }
  return {};
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
    if (ec)
      return fail(ec, nullptr,
                  "reading " + std::string(name(r.kind)) + " " + std::to_string(r.address) + ".." +
                      std::to_string(r.address + r.count - 1) + ", unit id " + std::to_string(r.unit_id) + ": " +
                      bus_.last_error());
  }
  device_values_.assign(plan.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const ReadPlan::Slot& slot = plan.slots_[i];
    if (!slot.signal) {
      values[i] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    const std::size_t at = plan.requests_[slot.request].buffer_offset + slot.offset;
    if (auto ec = decode(*slot.signal, words_, at, values[i], device_values_[i])) return ec;
  }
  plan.device_values_ = device_values_;
  plan.last_words_ = words_;
  last_error_.clear();
  return {};
}

std::error_code SignalIo::read_array(const ReadPlan& plan, std::string_view signal, std::vector<double>& values) {
  const std::size_t i = plan.index(signal);
  if (!plan.present(i) || is_bit_kind(plan.slots_[i].signal->kind)) return make_error_code(errc::not_supported);
  const ProfileSignal& s = *plan.slots_[i].signal;
  const std::size_t at = plan.requests_[plan.slots_[i].request].buffer_offset + plan.slots_[i].offset;
  const std::size_t width = address_width(s.encoding.type);
  if (plan.last_words_.size() < at + width * s.values_count()) return make_error_code(errc::not_ready);
  values.assign(s.values_count(), 0.0);
  for (std::size_t k = 0; k < values.size(); ++k) {
    double device_value = 0;
    if (auto ec = decode(s, plan.last_words_, at + k * width, values[k], device_value)) {
      last_error_ += " (value " + std::to_string(k) + " of " + std::to_string(values.size()) + ")";
      return ec;
    }
  }
  return {};
}

std::optional<double> SignalIo::last_written(std::string_view signal) const {
  for (const auto& [n, v] : written_)
    if (n == signal) return v;
  return std::nullopt;
}

std::error_code SignalIo::write_masked(const ProfileSignal& s, double device_value, bool idempotent) {
  // Read-modify-write by this, the device's only owner: the register's other bits are the
  // device's own (or other signals'), kept as read.
  std::uint16_t word = 0;
  if (auto ec = with_retries(true, [&] { return bus_.read_registers(s.unit_id, s.kind, s.address, std::span(&word, 1)); }))
    return fail(ec, &s, "reading the register to change its bits: " + bus_.last_error());
  const std::uint16_t before = word;
  if (auto ec = encode_field(s.encoding, s.mask, device_value, word))
    return fail(ec, &s, format_number(device_value) + " does not fit its bits or " + limits_of(s.encoding));
  if (auto ec = with_retries(idempotent, [&] { return bus_.write_registers(s.unit_id, s.address, std::span<const std::uint16_t>(&word, 1)); }))
    return fail(ec, &s, "writing " + hex_words(std::span(&word, 1)) + " over " + hex_words(std::span(&before, 1)) + ": " +
                            bus_.last_error());
  return {};
}

std::error_code SignalIo::write(std::string_view signal, double value) { return write(signal, value, true); }

std::error_code SignalIo::write_once(std::string_view signal, double value) { return write(signal, value, false); }

std::error_code SignalIo::write(std::string_view signal, double value, bool repeat) {
  const ProfileSignal* s = profile_.find(signal);
  if (!s || !s->writable() || !is_writable_kind(s->kind)) return make_error_code(errc::not_supported);
  double device_value = 0;
  if (auto ec = to_device_value(profile_.kind, *s, value, device_value))
    return fail(ec, s, "the device has no code for bench code " + format_number(value));
  const bool idempotent = repeat && s->role != SignalRole::window_start;
  std::error_code ec;
  if (s->masked()) {
    ec = write_masked(*s, device_value, idempotent);
  } else if (s->kind == RegisterKind::coil) {
    if (device_value != 0 && device_value != 1)
      return fail(make_error_code(errc::invalid_argument), s, format_number(device_value) + " is not a bit");
    const std::uint8_t bit = encode_bit(device_value != 0);
    ec = with_retries(idempotent, [&] { return bus_.write_bits(s->unit_id, s->address, std::span(&bit, 1)); });
    if (ec) fail(ec, s, "writing " + std::to_string(bit) + ": " + bus_.last_error());
  } else {
    std::uint16_t words[2];
    const std::size_t n = address_width(s->encoding.type);
    if ((ec = encode_registers(s->encoding, device_value, std::span(words, n))))
      return fail(ec, s, format_number(device_value) + " is outside its " + limits_of(s->encoding) + " or type");
    ec = with_retries(idempotent, [&] {
      return bus_.write_registers(s->unit_id, s->address, std::span<const std::uint16_t>(words, n));
    });
    if (ec) fail(ec, s, "writing " + hex_words(std::span<const std::uint16_t>(words, n)) + ": " + bus_.last_error());
  }
  if (ec) return ec;
  last_error_.clear();
  const auto it = std::find_if(written_.begin(), written_.end(), [&](const auto& w) { return w.first == s->name; });
  if (it == written_.end())
    written_.emplace_back(s->name, value);
  else
    it->second = value;
  return {};
}

}  // namespace synbench::drivers
