// Percent-decoding of request targets: the escapes, '+' by context, and what is malformed.
#include "server/http/url_text.hpp"

#include <gtest/gtest.h>

namespace synbench::http {
namespace {

TEST(PercentDecode, DecodesEscapesOfEitherCase) {
  EXPECT_EQ(percent_decode("a%20b%2Fc%2fd", Plus::literal), "a b/c/d");
  EXPECT_EQ(percent_decode("%C3%A9", Plus::literal), "\xC3\xA9");
  EXPECT_EQ(percent_decode("", Plus::space), "");
}

TEST(PercentDecode, PlusIsASpaceOnlyInQueries) {
  EXPECT_EQ(percent_decode("a+b%2B", Plus::space), "a b+");
  EXPECT_EQ(percent_decode("a+b%2B", Plus::literal), "a+b+");
}

TEST(PercentDecode, KeepsBytesThatAreNotText) {
  const auto nul = percent_decode("a%00b", Plus::literal);
  ASSERT_TRUE(nul);
  EXPECT_EQ(nul->size(), 3u);
  EXPECT_EQ((*nul)[1], '\0');
  EXPECT_EQ(percent_decode("%ff", Plus::literal), "\xff");
}

TEST(PercentDecode, RefusesMalformedEscapes) {
  for (const char* bad : {"%", "%4", "a%", "%4g", "%g4", "%%41", "ok%2"})
    EXPECT_FALSE(percent_decode(bad, Plus::space)) << bad;
}

TEST(AsciiLower, FoldsAsciiOnly) {
  EXPECT_EQ(ascii_lower("Bearer LOCALHOST:8080"), "bearer localhost:8080");
  EXPECT_EQ(ascii_lower("\xC3\x89"), "\xC3\x89");  // É is left alone: hosts and schemes are ASCII
}

}  // namespace
}  // namespace synbench::http
