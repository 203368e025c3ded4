// Register codec: one engineering value to and from the 16-bit words (or the single bit) that
// carry it over Modbus. Pure functions, no I/O, so every type, word order and byte order can be
// tested against hand-computed words before any transport exists.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string_view>
#include <system_error>

namespace synbench::drivers {

// boolean is the value of a coil or discrete input; the others live in holding/input registers.
enum class ValueType { boolean, u16, i16, u32, i32, f32 };

// Order of the two words of a 32-bit value: big = high word at the lower address.
enum class WordOrder { big, little };
// Order of the two bytes inside each word: big = high byte first (the Modbus standard).
enum class ByteOrder { big, little };

// Addresses one value occupies in its table: 1 for a bit or a 16-bit type, 2 for 32-bit types.
constexpr std::size_t address_width(ValueType t) {
  return (t == ValueType::u32 || t == ValueType::i32 || t == ValueType::f32) ? 2 : 1;
}

std::string_view name(ValueType t);
std::string_view name(WordOrder o);
std::string_view name(ByteOrder o);
std::optional<ValueType> parse_value_type(std::string_view s);
std::optional<WordOrder> parse_word_order(std::string_view s);
std::optional<ByteOrder> parse_byte_order(std::string_view s);

// How one engineering value maps to its raw register value: engineering = raw * scale + offset.
struct RegisterEncoding {
  ValueType type = ValueType::u16;
  WordOrder word_order = WordOrder::big;  // 32-bit types only
  ByteOrder byte_order = ByteOrder::big;
  double scale = 1.0;  // never zero (the profile rejects it)
  double offset = 0.0;
  double min = -std::numeric_limits<double>::infinity();  // engineering limits, inclusive
  double max = std::numeric_limits<double>::infinity();
};

// Writes address_width(e.type) words. errc::invalid_argument when the value is NaN or infinite,
// outside [min, max], or outside the raw type's range after scaling (integer types round to
// nearest, halves away from zero), when `out` is too small, the type is boolean or min > max.
std::error_code encode_registers(const RegisterEncoding& e, double value, std::span<std::uint16_t> out);

// Reads address_width(e.type) words into `value`, which is written only on success.
// errc::protocol when the raw value is NaN/infinite (f32) or lies outside the raw values that
// [min, max] encodes to: a stale or corrupt register must never pass as good data.
// errc::invalid_argument when `words` is too small, the type is boolean or min > max.
std::error_code decode_registers(const RegisterEncoding& e, std::span<const std::uint16_t> words,
                                 double& value);

// A field of one u16 register: the bits of `mask` (1..65535), read as (word & mask) >>
// trailing_zeros(mask), so several signals can share a control or status word. The encoding's
// type is u16 and its byte order applies to the whole word; scale, offset and limits to the field.
std::uint16_t field_max(std::uint16_t mask);
// errc::invalid_argument for a mask of 0 or a non-u16 encoding.
std::error_code decode_field(const RegisterEncoding& e, std::uint16_t mask, std::uint16_t word, double& value);
// Replaces the field's bits of `word` (other bits kept): errc::invalid_argument as
// encode_registers, and when the raw value does not fit in the mask's width.
std::error_code encode_field(const RegisterEncoding& e, std::uint16_t mask, double value, std::uint16_t& word);

// A coil or discrete input as libmodbus carries it: one byte, 0 or 1.
constexpr std::uint8_t encode_bit(bool on) { return on ? 1 : 0; }
// errc::protocol for any byte other than 0 or 1; `on` is written only on success.
std::error_code decode_bit(std::uint8_t raw, bool& on);

}  // namespace synbench::drivers
