#pragma once
/// @file text.hpp
/// The one escaper for text from outside (file names, paths, TOML keys, device names, file contents)
/// that an error message or a log line echoes.
#include <cstddef>
#include <string>
#include <string_view>

namespace hk {

/// One step of UTF-8 decoding (see decode_utf8).
struct Utf8Step {
  char32_t code_point = 0;   ///< the scalar value decoded; 0 when ill-formed
  std::size_t length = 1;    ///< bytes consumed [1, 4]
  bool well_formed = false;  ///< a well-formed sequence (Unicode 15 table 3-7)
};

/// Decodes the UTF-8 sequence starting at s[i] (i < s.size()). Well-formed (Unicode table 3-7: no overlong
/// forms, no surrogates, nothing above U+10FFFF): its code point and length. Ill-formed: well_formed false
/// and `length` its maximal subpart (the longest prefix of a well-formed sequence, at least 1 byte), so
/// replacing each step by U+FFFD follows Unicode's "one U+FFFD per maximal subpart" practice (§3.9).
[[nodiscard]] Utf8Step decode_utf8(std::string_view s, std::size_t i) noexcept;

/// Default cut of one_line() [bytes of input].
inline constexpr std::size_t kOneLineMaxBytes = 512;

/// `s` made safe to echo on one line: every control character (C0 U+0000–U+001F, DEL and C1
/// U+0080–U+009F, byte by byte; a newline becomes "\x0A") and every byte that is not part of a well-formed UTF-8
/// sequence (binary junk, overlong forms, surrogates, code points above U+10FFFF) becomes "\xNN" (hex,
/// upper case), so the result is valid UTF-8 without control characters; well-formed UTF-8 (a path in
/// another script) is kept. At most `max_bytes` bytes of `s` are shown, never cutting a UTF-8 sequence;
/// "..." marks a cut. Never throws but std::bad_alloc.
[[nodiscard]] std::string one_line(std::string_view s, std::size_t max_bytes = kOneLineMaxBytes);

/// one_line(s) between two `quote` characters: the form messages use to name an input, e.g. "image '/media/a.png':
/// ..." (single quotes, the default), or a settings value as the file spells it ('"', config).
[[nodiscard]] std::string quoted(std::string_view s, std::size_t max_bytes = kOneLineMaxBytes, char quote = '\'');

/// The first `n` words of `text` (split at ASCII white space, joined by one space), for speech and names: what
/// a block of text begins with. The whole text when it has no more. Never throws but std::bad_alloc.
std::string first_words(const std::string& text, int n);

/// `text` with its first letter upper case, for a phrase that begins a sentence ("la flèche droite" → "La flèche
/// droite", "écoutez" → "Écoutez"): ASCII letters and the lower-case letters of Latin-1 (U+00E0 to U+00FE but
/// U+00F7, as UTF-8) are made upper case; any other first character is kept as it is.
std::string capitalised(std::string text);

}  // namespace hk
