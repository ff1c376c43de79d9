// hk::decode_utf8 and hk::one_line, the one escaper for text echoed in messages (see text.hpp).
#include "hk/text.hpp"

#include <cctype>

#include <algorithm>

namespace hk {

Utf8Step decode_utf8(std::string_view s, std::size_t i) noexcept {
  const auto at = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b = at(i);
  if (b < 0x80) return {b, 1, true};
  std::size_t len = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // range of the second byte
  char32_t cp = 0;
  if (b >= 0xC2 && b <= 0xDF) {
    len = 2;
    cp = b & 0x1F;
  } else if (b >= 0xE0 && b <= 0xEF) {
    len = 3;
    cp = b & 0x0F;
    if (b == 0xE0) lo = 0xA0;  // overlong
    if (b == 0xED) hi = 0x9F;  // surrogates
  } else if (b >= 0xF0 && b <= 0xF4) {
    len = 4;
    cp = b & 0x07;
    if (b == 0xF0) lo = 0x90;  // overlong
    if (b == 0xF4) hi = 0x8F;  // above U+10FFFF
  } else {
    return {0, 1, false};  // starts no sequence
  }
  std::size_t k = 1;
  for (; k < len && i + k < s.size(); ++k) {
    const unsigned char c = at(i + k);
    if (k == 1 ? (c < lo || c > hi) : (c < 0x80 || c > 0xBF)) break;
    cp = (cp << 6) | (c & 0x3F);
  }
  if (k == len) return {cp, len, true};
  return {0, k, false};
}

std::string one_line(std::string_view s, std::size_t max_bytes) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string out;
  out.reserve(std::min(s.size(), max_bytes) + 8);
  std::size_t i = 0;
  while (i < s.size()) {
    const Utf8Step u = decode_utf8(s, i);
    const std::size_t n = u.well_formed ? u.length : 1;  // an ill-formed sequence is escaped byte by byte
    if (i + n > max_bytes) break;
    const char32_t cp = u.code_point;
    if (!u.well_formed || cp < 0x20 || (cp >= 0x7F && cp <= 0x9F)) {  // C0, DEL, C1
      for (std::size_t k = 0; k < n; ++k) {
        const auto b = static_cast<unsigned char>(s[i + k]);
        out += "\\x";
        out += kHex[b >> 4];
        out += kHex[b & 15];
      }
    } else {
      out.append(s.substr(i, n));
    }
    i += n;
  }
  if (i < s.size()) out += "...";
  return out;
}

// Appended piece by piece: GCC 12 warns (-Wrestrict, a false positive, GCC bug 105329) on "literal" + a temporary
// string in the package's hardened -O2 build.
std::string quoted(std::string_view s, std::size_t max_bytes, char quote) {
  std::string out(1, quote);
  out += one_line(s, max_bytes);
  out += quote;
  return out;
}

std::string first_words(const std::string& text, int n) {
  std::string out;
  int words = 0;
  std::size_t i = 0;
  while (i < text.size() && words < n) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    const std::size_t start = i;
    while (i < text.size() && !std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    if (i == start) break;
    if (!out.empty()) out += ' ';
    out.append(text, start, i - start);
    ++words;
  }
  return out;
}

std::string capitalised(std::string text) {
  if (text.empty()) return text;
  const auto c0 = static_cast<unsigned char>(text[0]);
  if (c0 >= 'a' && c0 <= 'z') {
    text[0] = static_cast<char>(c0 - 'a' + 'A');
  } else if (c0 == 0xC3 && text.size() > 1) {  // U+00C0..U+00FF: second byte 0x80..0xBF
    const auto c1 = static_cast<unsigned char>(text[1]);
    if (c1 >= 0xA0 && c1 <= 0xBE && c1 != 0xB7) text[1] = static_cast<char>(c1 - 0x20);  // à..þ but ÷
  }
  return text;
}

}  // namespace hk
