// hk::one_line, the one escaper for names echoed in messages: golden outputs worked out by hand from the
// byte values (RFC 3629 for what is well-formed UTF-8), and the properties every output must have.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "hk/error.hpp"
#include "hk/text.hpp"

namespace hk {
namespace {

using namespace std::string_literals;

TEST(OneLine, ControlBytesBecomeHexEscapes) {
  EXPECT_EQ(one_line("plain name.png"), "plain name.png");
  EXPECT_EQ(one_line("evil\nname\x1b[2J.png"), "evil\\x0Aname\\x1B[2J.png");
  EXPECT_EQ(one_line("a\r\tb\x7f"), "a\\x0D\\x09b\\x7F");
  EXPECT_EQ(one_line("nul\0byte"s), "nul\\x00byte");
}

TEST(OneLine, WellFormedUtf8IsKeptAndJunkEscaped) {
  EXPECT_EQ(one_line("Stra\xc3\x9f"
                     "e/\xe6\x97\xa5\xe6\x9c\xac.pdf"),
            "Stra\xc3\x9f"
            "e/\xe6\x97\xa5\xe6\x9c\xac.pdf");                      // ß, 日本
  EXPECT_EQ(one_line("\xf0\x9f\x90\x8e"), "\xf0\x9f\x90\x8e");      // U+1F40E, 4 bytes
  EXPECT_EQ(one_line("\xff\xfe"), "\\xFF\\xFE");                    // never UTF-8
  EXPECT_EQ(one_line("\xc0\xaf"), "\\xC0\\xAF");                    // overlong '/'
  EXPECT_EQ(one_line("\xed\xa0\x80"), "\\xED\\xA0\\x80");           // surrogate U+D800
  EXPECT_EQ(one_line("\xf4\x90\x80\x80"), "\\xF4\\x90\\x80\\x80");  // above U+10FFFF
  EXPECT_EQ(one_line("ab\xe6\x97"), "ab\\xE6\\x97");                // cut short
  EXPECT_EQ(one_line("\xc2\x9b"
                     "31m"),
            "\\xC2\\x9B"
            "31m");  // C1 CSI
}

TEST(DecodeUtf8, WellFormedSequencesAndMaximalSubparts) {
  // Code points worked out from the bits; maximal subparts as in Unicode 15 §3.9, table 3-8.
  const auto step = [](std::string_view s) { return decode_utf8(s, 0); };
  EXPECT_EQ(step("A").code_point, U'A');
  EXPECT_EQ(step("\xc3\x9f").code_point, U'\u00DF');
  EXPECT_EQ(step("\xe6\x97\xa5").code_point, U'\u65E5');
  EXPECT_EQ(step("\xf0\x9f\x90\x8e").code_point, U'\U0001F40E');
  EXPECT_EQ(step("\xf0\x9f\x90\x8e").length, 4u);
  for (std::string_view ill : {"\x80", "\xc0\xaf", "\xff"}) {
    EXPECT_FALSE(step(ill).well_formed) << ill;
    EXPECT_EQ(step(ill).length, 1u) << ill;  // starts no sequence
  }
  EXPECT_FALSE(step("\xe6\x97X").well_formed);
  EXPECT_EQ(step("\xe6\x97X").length, 2u);         // E6 97 is the longest well-formed prefix
  EXPECT_EQ(step("\xed\xa0\x80").length, 1u);      // a surrogate: ED A0 is no prefix
  EXPECT_EQ(step("\xf4\x90\x80\x80").length, 1u);  // above U+10FFFF
}

TEST(OneLine, CutsAtTheLimitOnASequenceBoundary) {
  EXPECT_EQ(one_line("abcdef", 4), "abcd...");
  EXPECT_EQ(one_line("abcd", 4), "abcd");
  EXPECT_EQ(one_line("ab\xc3\x9f", 3), "ab...");  // ß would straddle the limit: not cut in half
  EXPECT_EQ(one_line(std::string(1000, 'x')).size(), kOneLineMaxBytes + 3);
}

TEST(OneLine, AnyBytesGiveOneLineOfValidUtf8) {
  std::mt19937 rng(17);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int n = 0; n < 2000; ++n) {
    std::string in(static_cast<std::size_t>(n % 64), '\0');
    for (char& c : in) c = static_cast<char>(byte(rng));
    const std::string out = one_line(in);
    for (char c : out) {
      const auto u = static_cast<unsigned char>(c);
      ASSERT_FALSE(u < 0x20 || u == 0x7F) << "control byte in the output";
    }
    // Escaping again changes only the backslashes' meaning, never a byte: the output is a fixed point
    // (valid UTF-8 without control characters).
    ASSERT_EQ(one_line(out, out.size()), out);
  }
}

TEST(Error, IsARuntimeErrorWithTheOneLineMessage) {
  try {
    throw Error("image " + quoted("a\nb.png") + ": 3 x 0 px is empty");
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "image 'a\\x0Ab.png': 3 x 0 px is empty");
  }
}

}  // namespace
}  // namespace hk
