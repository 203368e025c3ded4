// Register codec: scaling, limits, raw-range checks, word and byte order.
#include "drivers/profile/register_codec.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

#include "drivers/error.hpp"

namespace synbench::drivers {
namespace {

constexpr std::array<std::string_view, 6> kTypeNames{"bool", "u16", "i16", "u32", "i32", "f32"};
constexpr std::array<std::string_view, 2> kOrderNames{"big", "little"};

struct RawRange {
  double lo, hi;
};

constexpr RawRange raw_range(ValueType t) {
  switch (t) {
    case ValueType::boolean: return {0, 1};
    case ValueType::u16: return {0, 65535};
    case ValueType::i16: return {-32768, 32767};
    case ValueType::u32: return {0, 4294967295.0};
    case ValueType::i32: return {-2147483648.0, 2147483647.0};
    case ValueType::f32:
      return {-static_cast<double>(std::numeric_limits<float>::max()),
              static_cast<double>(std::numeric_limits<float>::max())};
  }
  return {0, 0};
}

// The raw value an engineering value lands on, before the raw-range check. Integer types round
// here, f32 rounds to float here, so encode and the decode bounds below round identically.
double to_raw(const RegisterEncoding& e, double engineering) {
  const double raw = (engineering - e.offset) / e.scale;
  if (!std::isfinite(raw)) return raw;
  if (e.type == ValueType::f32) {
    // Converting a double beyond float's range is undefined; such a raw is out of range anyway.
    if (std::abs(raw) > raw_range(ValueType::f32).hi) return raw;
    return static_cast<double>(static_cast<float>(raw));
  }
  return std::round(raw);
}

std::uint16_t swap_bytes(std::uint16_t w) {
  return static_cast<std::uint16_t>((w >> 8) | (w << 8));
}

void put_words(const RegisterEncoding& e, std::uint32_t bits, std::span<std::uint16_t> out) {
  const auto order = [&](std::uint16_t w) { return e.byte_order == ByteOrder::big ? w : swap_bytes(w); };
  if (address_width(e.type) == 1) {
    out[0] = order(static_cast<std::uint16_t>(bits));
    return;
  }
  const auto hi = order(static_cast<std::uint16_t>(bits >> 16));
  const auto lo = order(static_cast<std::uint16_t>(bits & 0xFFFFu));
  out[0] = e.word_order == WordOrder::big ? hi : lo;
  out[1] = e.word_order == WordOrder::big ? lo : hi;
}

std::uint32_t get_bits(const RegisterEncoding& e, std::span<const std::uint16_t> words) {
  const auto order = [&](std::uint16_t w) { return e.byte_order == ByteOrder::big ? w : swap_bytes(w); };
  if (address_width(e.type) == 1) return order(words[0]);
  const std::uint32_t hi = order(e.word_order == WordOrder::big ? words[0] : words[1]);
  const std::uint32_t lo = order(e.word_order == WordOrder::big ? words[1] : words[0]);
  return (hi << 16) | lo;
}

}  // namespace

std::string_view name(ValueType t) { return kTypeNames[static_cast<std::size_t>(t)]; }
std::string_view name(WordOrder o) { return kOrderNames[static_cast<std::size_t>(o)]; }
std::string_view name(ByteOrder o) { return kOrderNames[static_cast<std::size_t>(o)]; }

std::optional<ValueType> parse_value_type(std::string_view s) {
  for (std::size_t i = 0; i < kTypeNames.size(); ++i)
    if (kTypeNames[i] == s) return static_cast<ValueType>(i);
  return std::nullopt;
}

std::optional<WordOrder> parse_word_order(std::string_view s) {
  if (s == "big") return WordOrder::big;
  if (s == "little") return WordOrder::little;
  return std::nullopt;
}

std::optional<ByteOrder> parse_byte_order(std::string_view s) {
  if (s == "big") return ByteOrder::big;
  if (s == "little") return ByteOrder::little;
  return std::nullopt;
}

std::error_code encode_registers(const RegisterEncoding& e, double value, std::span<std::uint16_t> out) {
  if (e.type == ValueType::boolean || out.size() < address_width(e.type) || !(e.min <= e.max))
    return errc::invalid_argument;
  if (!std::isfinite(value) || value < e.min || value > e.max) return errc::invalid_argument;
  const double raw = to_raw(e, value);
  const RawRange range = raw_range(e.type);
  if (!std::isfinite(raw) || raw < range.lo || raw > range.hi) return errc::invalid_argument;

  std::uint32_t bits = 0;
  switch (e.type) {
    case ValueType::u16:
    case ValueType::u32: bits = static_cast<std::uint32_t>(raw); break;
    // Two's complement: C++20 defines the signed-to-unsigned conversion as modular.
    case ValueType::i16:
    case ValueType::i32: bits = static_cast<std::uint32_t>(static_cast<std::int32_t>(raw)); break;
    case ValueType::f32: bits = std::bit_cast<std::uint32_t>(static_cast<float>(raw)); break;
    case ValueType::boolean: return errc::invalid_argument;
  }
  put_words(e, bits, out);
  return {};
}

std::error_code decode_registers(const RegisterEncoding& e, std::span<const std::uint16_t> words,
                                 double& value) {
  if (e.type == ValueType::boolean || words.size() < address_width(e.type) || !(e.min <= e.max))
    return errc::invalid_argument;
  const std::uint32_t bits = get_bits(e, words);

  double raw = 0;
  switch (e.type) {
    case ValueType::u16:
    case ValueType::u32: raw = static_cast<double>(bits); break;
    case ValueType::i16: raw = static_cast<std::int16_t>(bits); break;
    case ValueType::i32: raw = static_cast<std::int32_t>(bits); break;
    case ValueType::f32: raw = static_cast<double>(std::bit_cast<float>(bits)); break;
    case ValueType::boolean: return errc::invalid_argument;
  }
  if (!std::isfinite(raw)) return errc::protocol;

  // Bounds in raw space, rounded as encode rounds: a raw value passes exactly when some value
  // within [min, max] could have produced it, however coarse the scale.
  double lo = to_raw(e, e.min);
  double hi = to_raw(e, e.max);
  if (e.scale < 0) std::swap(lo, hi);
  if (raw < lo || raw > hi) return errc::protocol;

  const double engineering = raw * e.scale + e.offset;
  if (!std::isfinite(engineering)) return errc::protocol;
  // Quantization can put a raw bound up to half a step past its limit; the caller still gets
  // a value within [min, max].
  value = std::clamp(engineering, e.min, e.max);
  return {};
}

std::uint16_t field_max(std::uint16_t mask) {
  return mask == 0 ? std::uint16_t{0} : static_cast<std::uint16_t>(mask >> std::countr_zero(mask));
}

std::error_code decode_field(const RegisterEncoding& e, std::uint16_t mask, std::uint16_t word, double& value) {
  if (mask == 0 || e.type != ValueType::u16) return errc::invalid_argument;
  const std::uint16_t w = e.byte_order == ByteOrder::big ? word : swap_bytes(word);
  const auto field = static_cast<std::uint16_t>((w & mask) >> std::countr_zero(mask));
  // The field is decoded as a u16 of its own: the word's byte order is already undone.
  RegisterEncoding f = e;
  f.byte_order = ByteOrder::big;
  return decode_registers(f, std::span(&field, 1), value);
}

std::error_code encode_field(const RegisterEncoding& e, std::uint16_t mask, double value, std::uint16_t& word) {
  if (mask == 0 || e.type != ValueType::u16) return errc::invalid_argument;
  RegisterEncoding f = e;
  f.byte_order = ByteOrder::big;
  std::uint16_t field = 0;
  if (auto ec = encode_registers(f, value, std::span(&field, 1))) return ec;
  if (field > field_max(mask)) return errc::invalid_argument;
  const std::uint16_t w = e.byte_order == ByteOrder::big ? word : swap_bytes(word);
  const auto merged = static_cast<std::uint16_t>((w & ~mask) | ((field << std::countr_zero(mask)) & mask));
  word = e.byte_order == ByteOrder::big ? merged : swap_bytes(merged);
  return {};
}

std::error_code decode_bit(std::uint8_t raw, bool& on) {
  if (raw > 1) return errc::protocol;
  on = raw == 1;
  return {};
}

}  // namespace synbench::drivers
