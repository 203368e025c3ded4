// Tests of the register codec: hand-computed words for every type, word order and byte order;
// scaling, rounding, limits, raw ranges and the decode-side rejection of implausible values.
#include "drivers/profile/register_codec.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "drivers/error.hpp"

namespace synbench::drivers {
namespace {

using Words = std::vector<std::uint16_t>;

RegisterEncoding enc(ValueType t, WordOrder wo = WordOrder::big, ByteOrder bo = ByteOrder::big) {
  RegisterEncoding e;
  e.type = t;
  e.word_order = wo;
  e.byte_order = bo;
  return e;
}

Words encoded(const RegisterEncoding& e, double v) {
  Words w(address_width(e.type), 0xDEAD);
  const std::error_code ec = encode_registers(e, v, w);
  EXPECT_FALSE(ec) << "encoding " << v << ": " << ec.message();
  return w;
}

struct Vector {
  std::string name;
  ValueType type;
  WordOrder word_order;
  ByteOrder byte_order;
  double value;
  Words words;
};

// Byte letters of a 32-bit value, most significant first: A B C D.
// big/big = AB CD, little-word/big-byte = CD AB, big-word/little-byte = BA DC, little/little = DC BA.
const std::vector<Vector> kVectors = {
    {"u16_big", ValueType::u16, WordOrder::big, ByteOrder::big, 0x1234, {0x1234}},
    {"u16_little", ValueType::u16, WordOrder::big, ByteOrder::little, 0x1234, {0x3412}},
    {"u16_word_order_ignored", ValueType::u16, WordOrder::little, ByteOrder::big, 0x1234, {0x1234}},
    {"u16_little_word_little_byte", ValueType::u16, WordOrder::little, ByteOrder::little, 0x1234, {0x3412}},
    {"u16_max", ValueType::u16, WordOrder::big, ByteOrder::big, 65535, {0xFFFF}},
    {"i16_big", ValueType::i16, WordOrder::big, ByteOrder::big, -12345, {0xCFC7}},
    {"i16_little", ValueType::i16, WordOrder::big, ByteOrder::little, -12345, {0xC7CF}},
    {"i16_little_word_big_byte", ValueType::i16, WordOrder::little, ByteOrder::big, -2, {0xFFFE}},
    {"i16_little_word_little_byte", ValueType::i16, WordOrder::little, ByteOrder::little, -2, {0xFEFF}},
    {"i16_min", ValueType::i16, WordOrder::big, ByteOrder::big, -32768, {0x8000}},
    {"u32_ABCD", ValueType::u32, WordOrder::big, ByteOrder::big, 0x12345678, {0x1234, 0x5678}},
    {"u32_CDAB", ValueType::u32, WordOrder::little, ByteOrder::big, 0x12345678, {0x5678, 0x1234}},
    {"u32_BADC", ValueType::u32, WordOrder::big, ByteOrder::little, 0x12345678, {0x3412, 0x7856}},
    {"u32_DCBA", ValueType::u32, WordOrder::little, ByteOrder::little, 0x12345678, {0x7856, 0x3412}},
    {"u32_max", ValueType::u32, WordOrder::big, ByteOrder::big, 4294967295.0, {0xFFFF, 0xFFFF}},
    {"i32_ABCD", ValueType::i32, WordOrder::big, ByteOrder::big, -123456789, {0xF8A4, 0x32EB}},
    {"i32_CDAB", ValueType::i32, WordOrder::little, ByteOrder::big, -123456789, {0x32EB, 0xF8A4}},
    {"i32_BADC", ValueType::i32, WordOrder::big, ByteOrder::little, -123456789, {0xA4F8, 0xEB32}},
    {"i32_DCBA", ValueType::i32, WordOrder::little, ByteOrder::little, -123456789, {0xEB32, 0xA4F8}},
    {"i32_min", ValueType::i32, WordOrder::big, ByteOrder::big, -2147483648.0, {0x8000, 0x0000}},
    {"f32_1p5_ABCD", ValueType::f32, WordOrder::big, ByteOrder::big, 1.5, {0x3FC0, 0x0000}},
    {"f32_1p5_CDAB", ValueType::f32, WordOrder::little, ByteOrder::big, 1.5, {0x0000, 0x3FC0}},
    {"f32_1p5_BADC", ValueType::f32, WordOrder::big, ByteOrder::little, 1.5, {0xC03F, 0x0000}},
    {"f32_1p5_DCBA", ValueType::f32, WordOrder::little, ByteOrder::little, 1.5, {0x0000, 0xC03F}},
    {"f32_minus_2p25", ValueType::f32, WordOrder::big, ByteOrder::big, -2.25, {0xC010, 0x0000}},
    {"f32_1500_ABCD", ValueType::f32, WordOrder::big, ByteOrder::big, 1500.0, {0x44BB, 0x8000}},
    // 123.456f = 0x42F6E979: four distinct bytes, so every permutation is visible.
    {"f32_123p456_ABCD", ValueType::f32, WordOrder::big, ByteOrder::big, 123.456, {0x42F6, 0xE979}},
    {"f32_123p456_CDAB", ValueType::f32, WordOrder::little, ByteOrder::big, 123.456, {0xE979, 0x42F6}},
    {"f32_123p456_BADC", ValueType::f32, WordOrder::big, ByteOrder::little, 123.456, {0xF642, 0x79E9}},
    {"f32_123p456_DCBA", ValueType::f32, WordOrder::little, ByteOrder::little, 123.456, {0x79E9, 0xF642}},
};

class CodecVector : public testing::TestWithParam<Vector> {};

TEST_P(CodecVector, EncodesToTheHandComputedWords) {
  const Vector& v = GetParam();
  EXPECT_EQ(encoded(enc(v.type, v.word_order, v.byte_order), v.value), v.words);
}

TEST_P(CodecVector, DecodesTheHandComputedWords) {
  const Vector& v = GetParam();
  double out = -1;
  ASSERT_FALSE(decode_registers(enc(v.type, v.word_order, v.byte_order), v.words, out));
  // f32 carries the value rounded to float; the integer types carry it exactly.
  const double expected = v.type == ValueType::f32 ? static_cast<double>(static_cast<float>(v.value)) : v.value;
  EXPECT_EQ(out, expected);
}

INSTANTIATE_TEST_SUITE_P(AllTypesAndOrders, CodecVector, testing::ValuesIn(kVectors),
                         [](const testing::TestParamInfo<Vector>& i) { return i.param.name; });

TEST(RegisterCodec, WidthOfEachType) {
  EXPECT_EQ(address_width(ValueType::boolean), 1u);
  EXPECT_EQ(address_width(ValueType::u16), 1u);
  EXPECT_EQ(address_width(ValueType::i16), 1u);
  EXPECT_EQ(address_width(ValueType::u32), 2u);
  EXPECT_EQ(address_width(ValueType::i32), 2u);
  EXPECT_EQ(address_width(ValueType::f32), 2u);
}

TEST(RegisterCodec, ScaleAndOffset) {
  // A temperature as u16 tenths of a degree above -50 C: raw = (21.3 + 50) / 0.1 = 713.
  RegisterEncoding e = enc(ValueType::u16);
  e.scale = 0.1;
  e.offset = -50;
  EXPECT_EQ(encoded(e, 21.3), (Words{713}));
  EXPECT_EQ(encoded(e, -50), (Words{0}));
  double out = 0;
  ASSERT_FALSE(decode_registers(e, Words{713}, out));
  EXPECT_NEAR(out, 21.3, 1e-12);
  ASSERT_FALSE(decode_registers(e, Words{2500}, out));
  EXPECT_NEAR(out, 200.0, 1e-12);
}

TEST(RegisterCodec, IntegerTypesRoundToNearestHalvesAwayFromZero) {
  RegisterEncoding e = enc(ValueType::i16);
  e.scale = 0.5;  // exact in binary, so 1.25 is exactly raw 2.5
  EXPECT_EQ(encoded(e, 1.25), (Words{3}));
  EXPECT_EQ(encoded(e, -1.25), (Words{0xFFFD}));  // -3
  EXPECT_EQ(encoded(e, 1.2), (Words{2}));         // 2.4 -> 2
  EXPECT_EQ(encoded(e, 1.3), (Words{3}));         // 2.6 -> 3
  e.scale = 0.01;
  EXPECT_EQ(encoded(e, 12.344), (Words{1234}));
  EXPECT_EQ(encoded(e, -12.346), (Words{0xFB2D}));  // -1235
}

TEST(RegisterCodec, NegativeScaleInvertsTheSign) {
  RegisterEncoding e = enc(ValueType::i16);
  e.scale = -1;
  e.min = -10;
  e.max = 10;
  EXPECT_EQ(encoded(e, 5), (Words{0xFFFB}));
  double out = 0;
  ASSERT_FALSE(decode_registers(e, Words{0xFFFB}, out));
  EXPECT_EQ(out, 5);
  EXPECT_EQ(decode_registers(e, Words{11}, out), errc::protocol);  // -11 is below min
}

TEST(RegisterCodec, ScaledRoundTripStaysWithinHalfAStep) {
  RegisterEncoding e = enc(ValueType::i16, WordOrder::big, ByteOrder::little);
  e.scale = 0.01;
  e.min = -180;
  e.max = 180;
  int checked = 0;
  for (double v = -180; v <= 180; v += 0.37, ++checked) {
    double out = 1e9;
    ASSERT_FALSE(decode_registers(e, encoded(e, v), out)) << v;
    EXPECT_NEAR(out, v, 0.005 + 1e-12) << v;
  }
  EXPECT_GT(checked, 900);

  RegisterEncoding f = enc(ValueType::f32, WordOrder::little, ByteOrder::little);
  f.scale = 1e-3;  // the device counts mA, the bench speaks A
  f.offset = 2;
  double out = 0;
  ASSERT_FALSE(decode_registers(f, encoded(f, 3.25), out));
  EXPECT_NEAR(out, 3.25, 1e-9);
  // (3.5 - 2) / 1e-3 = 1500.0f = 44 BB 80 00, sent D C B A.
  EXPECT_EQ(encoded(f, 3.5), (Words{0x0080, 0xBB44}));
}

TEST(RegisterCodec, EncodeRejectsValuesOutsideTheLimits) {
  RegisterEncoding e = enc(ValueType::i16);
  e.scale = 0.01;
  e.min = -180;
  e.max = 180;
  Words w{0x5555};
  EXPECT_FALSE(encode_registers(e, 180.0, w));
  EXPECT_FALSE(encode_registers(e, -180.0, w));
  w = {0x5555};
  EXPECT_EQ(encode_registers(e, 180.001, w), errc::invalid_argument);
  EXPECT_EQ(encode_registers(e, -180.001, w), errc::invalid_argument);
  EXPECT_EQ(w, (Words{0x5555})) << "a rejected value must leave the words untouched";
}

TEST(RegisterCodec, EncodeRejectsNanAndInfinity) {
  for (const ValueType t : {ValueType::u16, ValueType::i32, ValueType::f32}) {
    Words w(2);
    EXPECT_EQ(encode_registers(enc(t), std::nan(""), w), errc::invalid_argument);
    EXPECT_EQ(encode_registers(enc(t), std::numeric_limits<double>::infinity(), w), errc::invalid_argument);
    EXPECT_EQ(encode_registers(enc(t), -std::numeric_limits<double>::infinity(), w), errc::invalid_argument);
  }
}

TEST(RegisterCodec, EncodeRejectsRawValuesOutsideTheType) {
  Words w(2);
  EXPECT_FALSE(encode_registers(enc(ValueType::u16), 65535, w));
  EXPECT_EQ(encode_registers(enc(ValueType::u16), 65536, w), errc::invalid_argument);
  EXPECT_FALSE(encode_registers(enc(ValueType::u16), -0.4, w));  // rounds to 0
  EXPECT_EQ(encode_registers(enc(ValueType::u16), -0.5, w), errc::invalid_argument);  // rounds to -1
  EXPECT_FALSE(encode_registers(enc(ValueType::i16), 32767.4, w));
  EXPECT_EQ(encode_registers(enc(ValueType::i16), 32767.5, w), errc::invalid_argument);
  EXPECT_EQ(encode_registers(enc(ValueType::i16), -32769, w), errc::invalid_argument);
  EXPECT_EQ(encode_registers(enc(ValueType::u32), 4294967296.0, w), errc::invalid_argument);
  EXPECT_EQ(encode_registers(enc(ValueType::u32), -1, w), errc::invalid_argument);
  EXPECT_EQ(encode_registers(enc(ValueType::i32), 2147483648.0, w), errc::invalid_argument);
  EXPECT_EQ(encode_registers(enc(ValueType::i32), -2147483649.0, w), errc::invalid_argument);
  EXPECT_EQ(encode_registers(enc(ValueType::f32), 1e39, w), errc::invalid_argument);

  // Scaling applies first: u16 in tenths carries at most 6553.5.
  RegisterEncoding e = enc(ValueType::u16);
  e.scale = 0.1;
  EXPECT_EQ(encoded(e, 6553.5), (Words{0xFFFF}));
  EXPECT_EQ(encode_registers(e, 6553.6, w), errc::invalid_argument);
}

TEST(RegisterCodec, MisuseIsAnInvalidArgument) {
  Words one(1);
  EXPECT_EQ(encode_registers(enc(ValueType::f32), 1.0, one), errc::invalid_argument);  // needs 2 words
  double out = 0;
  EXPECT_EQ(decode_registers(enc(ValueType::u32), one, out), errc::invalid_argument);
  EXPECT_EQ(encode_registers(enc(ValueType::boolean), 1.0, one), errc::invalid_argument);
  RegisterEncoding inverted = enc(ValueType::u16);
  inverted.min = 10;
  inverted.max = 0;
  EXPECT_EQ(encode_registers(inverted, 5, one), errc::invalid_argument);
  EXPECT_EQ(decode_registers(inverted, Words{5}, out), errc::invalid_argument);
}

TEST(RegisterCodec, DecodeReportsValuesOutsideTheLimitsAsProtocolErrors) {
  RegisterEncoding state = enc(ValueType::u16);
  state.min = 0;
  state.max = 3;
  double out = -7;
  EXPECT_EQ(decode_registers(state, Words{4}, out), errc::protocol);
  EXPECT_EQ(out, -7) << "a rejected value must not reach the caller";
  ASSERT_FALSE(decode_registers(state, Words{3}, out));
  EXPECT_EQ(out, 3);

  RegisterEncoding fraction = enc(ValueType::f32);
  fraction.min = 0;
  fraction.max = 1;
  EXPECT_EQ(decode_registers(fraction, Words{0x3FC0, 0x0000}, out), errc::protocol);  // 1.5
  EXPECT_EQ(decode_registers(fraction, Words{0xC010, 0x0000}, out), errc::protocol);  // -2.25

  // One raw step past the limit is rejected, however fine the scale.
  RegisterEncoding udc = enc(ValueType::u16);
  udc.scale = 0.1;
  udc.min = 0;
  udc.max = 1000;
  ASSERT_FALSE(decode_registers(udc, Words{10000}, out));
  EXPECT_DOUBLE_EQ(out, 1000);
  EXPECT_EQ(decode_registers(udc, Words{10001}, out), errc::protocol);
}

TEST(RegisterCodec, DecodeRejectsNonFiniteFloats) {
  double out = -7;
  EXPECT_EQ(decode_registers(enc(ValueType::f32), Words{0x7FC0, 0x0000}, out), errc::protocol);  // NaN
  EXPECT_EQ(decode_registers(enc(ValueType::f32), Words{0x7F80, 0x0000}, out), errc::protocol);  // +inf
  EXPECT_EQ(decode_registers(enc(ValueType::f32), Words{0xFF80, 0x0000}, out), errc::protocol);  // -inf
  EXPECT_EQ(out, -7);
}

TEST(RegisterCodec, EveryValueWithinTheLimitsDecodesAfterFloatRounding) {
  // 0.3 is not a float; its nearest float lies above 0.3. It must still decode, clamped.
  RegisterEncoding e = enc(ValueType::f32);
  e.min = 0;
  e.max = 0.3;
  double out = 0;
  ASSERT_FALSE(decode_registers(e, encoded(e, 0.3), out));
  EXPECT_EQ(out, 0.3);
  EXPECT_EQ(decode_registers(e, Words{0x3E99, 0x999B}, out), errc::protocol);  // next float up
}

TEST(RegisterCodec, Bits) {
  EXPECT_EQ(encode_bit(true), 1);
  EXPECT_EQ(encode_bit(false), 0);
  bool on = false;
  ASSERT_FALSE(decode_bit(1, on));
  EXPECT_TRUE(on);
  ASSERT_FALSE(decode_bit(0, on));
  EXPECT_FALSE(on);
  on = true;
  EXPECT_EQ(decode_bit(2, on), errc::protocol);
  EXPECT_EQ(decode_bit(0xFF, on), errc::protocol);
  EXPECT_TRUE(on) << "a rejected bit must not reach the caller";
}

TEST(RegisterCodec, NamesRoundTrip) {
  for (const ValueType t : {ValueType::boolean, ValueType::u16, ValueType::i16, ValueType::u32, ValueType::i32,
                            ValueType::f32})
    EXPECT_EQ(parse_value_type(name(t)), t);
  EXPECT_EQ(parse_value_type("bool"), ValueType::boolean);
  EXPECT_EQ(parse_value_type("f64"), std::nullopt);
  EXPECT_EQ(parse_word_order("little"), WordOrder::little);
  EXPECT_EQ(parse_byte_order("big"), ByteOrder::big);
  EXPECT_EQ(parse_byte_order("middle"), std::nullopt);
}

}  // namespace
}  // namespace synbench::drivers
