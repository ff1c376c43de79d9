#pragma once
/// @file text.hpp
/// The one escaper for text from outside (file names, paths, TOML keys, device names, file contents)
/// that an error message or a log line echoes.
#include <cstddef>
#include <string>
#include <string_view>

namespace hk {

/// Default cut of one_line() [bytes of input].
inline constexpr std::size_t kOneLineMaxBytes = 512;

/// `s` made safe to echo on one line: every control character (C0 U+0000–U+001F, DEL and C1
/// U+0080–U+009F, byte by byte; a newline becomes "\x0A") and every byte that is not part of a well-formed UTF-8
/// sequence (binary junk, overlong forms, surrogates, code points above U+10FFFF) becomes "\xNN" (hex,
/// upper case), so the result is valid UTF-8 without control characters; well-formed UTF-8 (a path in
/// another script) is kept. At most `max_bytes` bytes of `s` are shown, never cutting a UTF-8 sequence;
/// "..." marks a cut. Never throws but std::bad_alloc.
[[nodiscard]] std::string one_line(std::string_view s, std::size_t max_bytes = kOneLineMaxBytes);

/// one_line(s) in single quotes: the form messages use to name an input, e.g. "image '/media/a.png': ...".
[[nodiscard]] std::string quoted(std::string_view s, std::size_t max_bytes = kOneLineMaxBytes);

}  // namespace hk
