// Request decoding, table lookup, encoding and exception replies of the register server.
#include "emulator/modbus/register_server.hpp"

#include <algorithm>
#include <cmath>

#include "drivers/error.hpp"
#include "drivers/profile/register_codec.hpp"
#include "drivers/profile/signal_codes.hpp"
#include "emulator/modbus/modbus_pdu.hpp"
#include "emulator/modbus/served_codes.hpp"

namespace synbench::emulator {

using drivers::RegisterKind;
using namespace modbus;

namespace {

std::uint8_t exception_for(std::error_code ec) {
  if (ec == synbench::errc::invalid_argument || ec == synbench::errc::not_supported) return kIllegalDataValue;
  if (ec == synbench::errc::busy) return kServerDeviceBusy;
  return kServerDeviceFailure;
}

std::size_t width(const drivers::ProfileSignal& s) { return drivers::address_width(s.encoding.type); }

}  // namespace

RegisterServer::RegisterServer(std::vector<drivers::DeviceProfile> profiles, SignalProvider& provider)
    : profiles_(std::move(profiles)), provider_(provider) {
  for (const drivers::DeviceProfile& p : profiles_)
    for (const drivers::ProfileSignal& s : p.signals) {
      if (!s.count) {
        tables_[{s.unit_id, s.kind}].push_back(Entry{&s, p.kind, false, std::nullopt, served_codes(p, s).by_code});
        continue;
      }
      for (std::size_t k = 0; k < s.count; ++k) {
        drivers::ProfileSignal& e = elements_.emplace_back(s);
        e.count = 0;
        e.address = static_cast<std::uint16_t>(s.address + k * width(s));
        tables_[{s.unit_id, s.kind}].push_back(
            Entry{&e, p.kind, false, std::nullopt, served_codes(p, s).by_code, static_cast<int>(k)});
      }
    }
  for (auto& [key, t] : tables_)
    std::sort(t.begin(), t.end(), [](const Entry& a, const Entry& b) { return a.signal->address < b.signal->address; });
}

bool RegisterServer::serves(std::uint8_t unit_id) const {
  for (const auto& [key, t] : tables_)
    if (key.first == unit_id) return true;
  return false;
}

RegisterServer::Table* RegisterServer::table(std::uint8_t unit_id, RegisterKind kind) {
  const auto it = tables_.find({unit_id, kind});
  return it == tables_.end() ? nullptr : &it->second;
}

std::error_code RegisterServer::stick(std::uint8_t unit_id, std::string_view signal) {
  for (auto& [key, t] : tables_)
    for (Entry& e : t)
      if (key.first == unit_id && e.signal->name == signal) {
        e.stuck = true;
        return {};
      }
  return make_error_code(synbench::errc::not_supported);
}

void RegisterServer::unstick_all() {
  for (auto& [key, t] : tables_)
    for (Entry& e : t) {
      e.stuck = false;
      e.stuck_words.reset();
    }
}

std::array<std::uint16_t, 2> RegisterServer::raw(Entry& e) {
  if (e.stuck && e.stuck_words) return *e.stuck_words;
  const drivers::ProfileSignal& s = *e.signal;
  std::array<std::uint16_t, 2> w{0, 0};
  // Write-only signals (a level fault reset, window start) read as zero: the device clears
  // them as it acts. A pulse reset's register holds what was written; the heartbeat reads back.
  const bool self_clearing =
      (s.role == drivers::SignalRole::fault_reset && s.reset.mode == drivers::FaultResetMode::Mode::level) ||
      s.role == drivers::SignalRole::window_start;
  double v = self_clearing        ? 0.0
             : e.element >= 0 ? provider_.read_element(e.device, s, static_cast<std::size_t>(e.element))
                              : provider_.read_signal(e.device, s);
  double device_value = 0;
  if (!e.served.empty()) {
    // An enumerated signal: the code's own number, its `otherwise`, or a drive state's fallback
    // (served_codes.hpp); 0 only for a code the map cannot show and the twin never takes.
    const bool index = v >= 0 && v == std::floor(v) && v < static_cast<double>(e.served.size());
    device_value = index ? e.served[static_cast<std::size_t>(v)].value_or(0.0) : 0.0;
  } else if (drivers::to_device_value(e.device, s, v, device_value)) {
    // A fault the profile has no code for is served as the bench's own number, never as "none":
    // the bench then reads it as unknown (or the profile's otherwise).
    device_value = drivers::is_fault_code(s) ? v : 0;
  }
  if (drivers::is_bit_kind(s.kind)) {
    w[0] = device_value != 0 ? 1 : 0;
  } else if (s.masked()) {
    if (!std::isfinite(device_value)) device_value = 0;
    drivers::RegisterEncoding clamp = s.encoding;
    // A field saturates at its bits, as a wider register at its type.
    const double lo = clamp.offset, hi = drivers::field_max(s.mask) * clamp.scale + clamp.offset;
    device_value = std::clamp(device_value, std::max(clamp.min, std::min(lo, hi)), std::min(clamp.max, std::max(lo, hi)));
    if (drivers::encode_field(s.encoding, s.mask, device_value, w[0])) w[0] = 0;
  } else {
    // A real device saturates what it cannot represent; so does the twin.
    if (!std::isfinite(device_value)) device_value = 0;
    device_value = std::clamp(device_value, s.encoding.min, s.encoding.max);
    if (drivers::encode_registers(s.encoding, device_value, std::span(w.data(), width(s)))) w = {0, 0};
  }
  if (e.stuck) e.stuck_words = w;
  return w;
}

std::uint8_t RegisterServer::read(std::uint8_t unit_id, RegisterKind kind, std::uint16_t address,
                                  std::uint16_t count, std::span<std::uint8_t> data) {
  const bool bits = drivers::is_bit_kind(kind);
  if (count == 0 || count > (bits ? 2000 : 125)) return kIllegalDataValue;
  Table* t = table(unit_id, kind);
  if (!t || t->empty()) return kIllegalDataAddress;
  const std::uint32_t end = std::uint32_t{address} + count;  // one past the last
  // Addresses past the last mapped one do not exist; gaps inside the map read as zero.
  if (end - 1 > t->back().signal->last_address()) return kIllegalDataAddress;
  const std::size_t bytes = bits ? (count + 7u) / 8u : 2u * count;
  std::fill(data.begin(), data.begin() + static_cast<std::ptrdiff_t>(bytes), 0);
  for (Entry& e : *t) {
    const drivers::ProfileSignal& s = *e.signal;
    if (s.last_address() < address || s.address >= end) continue;
    if (!s.readable() && s.role != drivers::SignalRole::heartbeat) continue;
    const auto w = raw(e);
    for (std::size_t i = 0; i < width(s); ++i) {
      const std::uint32_t a = s.address + static_cast<std::uint32_t>(i);
      if (a < address || a >= end) continue;
      const std::size_t k = a - address;
      if (bits) {
        if (w[0]) data[k / 8] = static_cast<std::uint8_t>(data[k / 8] | (1u << (k % 8)));
      } else {
        // OR: masked signals of one register each contribute their bits.
        put16(&data[2 * k], static_cast<std::uint16_t>(get16(&data[2 * k]) | w[i]));
      }
    }
  }
  return 0;
}

std::uint8_t RegisterServer::write_bits(std::uint8_t unit_id, std::uint16_t address,
                                        std::span<const std::uint8_t> bits) {
  Table* t = table(unit_id, RegisterKind::coil);
  if (!t) return kIllegalDataAddress;
  std::vector<Entry*> targets;
  for (std::size_t i = 0; i < bits.size(); ++i) {
    const auto it = std::find_if(t->begin(), t->end(), [&](const Entry& e) {
      return e.signal->address == address + i;
    });
    if (it == t->end() || !it->signal->writable()) return kIllegalDataAddress;
    targets.push_back(&*it);
  }
  for (std::size_t i = 0; i < bits.size(); ++i)
    if (auto ec = provider_.write_signal(targets[i]->device, *targets[i]->signal, bits[i] ? 1.0 : 0.0))
      return exception_for(ec);
  if (!targets.empty()) provider_.accepted_write(targets.front()->device);
  return 0;
}

std::uint8_t RegisterServer::split_masked(std::vector<Entry*>& at, std::uint16_t word,
                                          std::vector<std::pair<Entry*, double>>& writes) {
  // Like a device acting on its control word: a signal whose bits did not change is not written
  // again (a rewritten enable bit is no new enable; an edge-triggered reset needs an edge).
  std::uint16_t current = 0;
  for (Entry* e : at) current = static_cast<std::uint16_t>(current | raw(*e)[0]);
  for (Entry* e : at) {
    const drivers::ProfileSignal& s = *e->signal;
    if (!s.writable()) continue;  // the device's own bits: a write does not change them
    // The field's bits as they travel (the encoding may swap the word's bytes).
    const auto wire_mask = s.encoding.byte_order == drivers::ByteOrder::big
                               ? s.mask
                               : static_cast<std::uint16_t>((s.mask >> 8) | (s.mask << 8));
    if (((word ^ current) & wire_mask) == 0) continue;
    double device_value = 0, code = 0;
    if (drivers::decode_field(s.encoding, s.mask, word, device_value)) return kIllegalDataValue;
    if (drivers::to_bench_code(e->device, s, device_value, code)) return kIllegalDataValue;
    writes.emplace_back(e, code);
  }
  return 0;
}

std::uint8_t RegisterServer::write_words(std::uint8_t unit_id, std::uint16_t address,
                                         std::span<const std::uint16_t> words) {
  Table* t = table(unit_id, RegisterKind::holding);
  if (!t) return kIllegalDataAddress;
  // The request must cover whole writable signals, with nothing left over; check all of them
  // before applying any, so a refused value leaves the device unchanged.
  std::vector<std::pair<Entry*, double>> writes;
  std::vector<Entry*> masked;
  std::optional<drivers::DeviceKind> device;
  std::size_t i = 0;
  while (i < words.size()) {
    const auto it = std::find_if(t->begin(), t->end(), [&](const Entry& e) {
      return e.signal->address == address + i;
    });
    if (it == t->end()) return kIllegalDataAddress;
    device = it->device;
    if (it->signal->masked()) {
      // A shared register: its signals are the entries at this address, all masked (the
      // profile refuses a mix); at least one of them must be writable.
      masked.clear();
      for (auto m = it; m != t->end() && m->signal->address == address + i; ++m) masked.push_back(&*m);
      if (std::none_of(masked.begin(), masked.end(), [](const Entry* e) { return e->signal->writable(); }))
        return kIllegalDataAddress;
      if (const auto ex = split_masked(masked, words[i], writes)) return ex;
      ++i;
      continue;
    }
    if (!it->signal->writable()) return kIllegalDataAddress;
    const drivers::ProfileSignal& s = *it->signal;
    if (i + width(s) > words.size()) return kIllegalDataAddress;
    double device_value = 0, code = 0;
    if (drivers::decode_registers(s.encoding, words.subspan(i, width(s)), device_value)) return kIllegalDataValue;
    if (drivers::to_bench_code(it->device, s, device_value, code)) return kIllegalDataValue;
    writes.emplace_back(&*it, code);
    i += width(s);
  }
  for (auto& [e, v] : writes)
    if (auto ec = provider_.write_signal(e->device, *e->signal, v)) return exception_for(ec);
  if (device) provider_.accepted_write(*device);
  return 0;
}

std::size_t RegisterServer::handle(std::uint8_t unit_id, std::span<const std::uint8_t> req,
                                   std::span<std::uint8_t> reply) {
  if (req.empty()) return 0;
  const std::uint8_t fn = req[0];
  const bool broadcast = unit_id == 0;
  auto answer = [&](std::uint8_t exception, std::size_t length) -> std::size_t {
    if (broadcast) return 0;
    return exception ? exception_reply(fn, exception, reply) : length;
  };
  switch (fn) {
    case kReadCoils:
    case kReadDiscreteInputs:
    case kReadHoldingRegisters:
    case kReadInputRegisters: {
      if (broadcast) return 0;  // a broadcast read has no one to answer
      if (req.size() != 5) return answer(kIllegalDataValue, 0);
      const RegisterKind kind = fn == kReadCoils             ? RegisterKind::coil
                                : fn == kReadDiscreteInputs  ? RegisterKind::discrete_input
                                : fn == kReadHoldingRegisters ? RegisterKind::holding
                                                              : RegisterKind::input;
      const std::uint16_t address = get16(&req[1]), count = get16(&req[3]);
      const std::uint8_t ex = read(unit_id, kind, address, count, reply.subspan(2));
      const std::size_t bytes = drivers::is_bit_kind(kind) ? (count + 7u) / 8u : 2u * count;
      reply[0] = fn;
      reply[1] = static_cast<std::uint8_t>(bytes);
      return answer(ex, 2 + bytes);
    }
    case kWriteSingleCoil: {
      if (req.size() != 5) return answer(kIllegalDataValue, 0);
      const std::uint16_t value = get16(&req[3]);
      if (value != 0xFF00 && value != 0x0000) return answer(kIllegalDataValue, 0);
      const std::uint8_t bit = value == 0xFF00;
      std::uint8_t ex = 0;
      if (broadcast) {
        for (const auto& p : profiles_) write_bits(p.unit_id, get16(&req[1]), std::span(&bit, 1));
      } else {
        ex = write_bits(unit_id, get16(&req[1]), std::span(&bit, 1));
      }
      std::copy(req.begin(), req.end(), reply.begin());
      return answer(ex, 5);
    }
    case kWriteSingleRegister: {
      if (req.size() != 5) return answer(kIllegalDataValue, 0);
      const std::uint16_t word = get16(&req[3]);
      std::uint8_t ex = 0;
      if (broadcast) {
        for (const auto& p : profiles_) write_words(p.unit_id, get16(&req[1]), std::span(&word, 1));
      } else {
        ex = write_words(unit_id, get16(&req[1]), std::span(&word, 1));
      }
      std::copy(req.begin(), req.end(), reply.begin());
      return answer(ex, 5);
    }
    case kWriteMultipleCoils:
    case kWriteMultipleRegisters: {
      if (req.size() < 6) return answer(kIllegalDataValue, 0);
      const std::uint16_t address = get16(&req[1]), count = get16(&req[3]);
      const std::size_t bytes = req[5];
      const bool coils = fn == kWriteMultipleCoils;
      const std::size_t max = coils ? 1968 : 123;
      if (count == 0 || count > max || bytes != (coils ? (count + 7u) / 8u : 2u * count) ||
          req.size() != 6 + bytes)
        return answer(kIllegalDataValue, 0);
      std::uint8_t ex = 0;
      if (coils) {
        std::vector<std::uint8_t> bits(count);
        for (std::size_t i = 0; i < count; ++i) bits[i] = (req[6 + i / 8] >> (i % 8)) & 1;
        if (broadcast) {
          for (const auto& p : profiles_) write_bits(p.unit_id, address, bits);
        } else {
          ex = write_bits(unit_id, address, bits);
        }
      } else {
        std::vector<std::uint16_t> words(count);
        for (std::size_t i = 0; i < count; ++i) words[i] = get16(&req[6 + 2 * i]);
        if (broadcast) {
          for (const auto& p : profiles_) write_words(p.unit_id, address, words);
        } else {
          ex = write_words(unit_id, address, words);
        }
      }
      reply[0] = fn;
      put16(&reply[1], address);
      put16(&reply[3], count);
      return answer(ex, 5);
    }
    default:
      return answer(kIllegalFunction, 0);
  }
}

}  // namespace synbench::emulator
