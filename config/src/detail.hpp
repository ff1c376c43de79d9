#pragma once
/// @file detail.hpp
/// Internal helpers shared by the config sources (not installed, not part of the API).

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include "hk/text.hpp"

#include "config/load.hpp"

namespace hk::config::detail {

/// One TOML table of the settings file, in file order.
struct TableInfo {
  std::string_view name;  ///< e.g. "haptics"
  std::string_view help;  ///< one-line description written above the table
};

/// The tables of the settings file, in file order; every FieldDescriptor::table is one of them.
std::span<const TableInfo> tables() noexcept;

/// Where a message comes from: a file (or named text) or an in-memory Settings.
struct Source {
  std::string name;  ///< path / source name, or "settings"
  bool is_file;      ///< true: messages start "config '<name>': ", false: "<name>: "
};

/// The one escaper (hk/text.hpp), for the names and values config messages echo.
using hk::one_line;

/// Shortest text that reads back to exactly `v`, plain decimal when that fits in 32 characters
/// ("800", "0.0005", "100000"), else with an exponent ("5e-324"); "nan", "inf", "-inf".
std::string format_real(double v);

/// `v` as TOML float text: format_real() with ".0" appended when it would read as an integer.
std::string format_toml_real(double v);

/// A TOML basic string literal for `s` (quoted, escaped).
std::string toml_string(std::string_view s);

/// The value of field `d` in `s` as TOML text, as to_toml writes it (800.0, "UP", 16384).
std::string toml_value(const FieldDescriptor& d, const Settings& s);

/// Writes all of `text` to `fd` (retrying short writes and EINTR); returns 0 or an errno value.
int write_all(int fd, std::string_view text);

/// The start of every temporary file name a save of `target` writes beside it, in `dir` (its folder, "." for
/// none): "<dir>/.<name>.tmp.", so one pattern finds what a crash left (the settings and the PIN's lockout state).
std::string temp_prefix(const std::string& dir, const std::string& target_name);

/// "table.key" of a descriptor.
std::string qualified(const FieldDescriptor& d);

/// What is allowed for `d`, e.g. "[10, 5000] N/m" or "one of \"simulated\"".
std::string allowed_text(const FieldDescriptor& d);

/// Why a real value is not allowed for `d` ("is out of range [..] unit", "is not a finite
/// number; ..."), or nullopt when it is allowed.
std::optional<std::string> real_problem(const FieldDescriptor& d, double v);
/// As real_problem() for an integer value.
std::optional<std::string> integer_problem(const FieldDescriptor& d, long long v);
/// As real_problem() for a text value.
std::optional<std::string> text_problem(const FieldDescriptor& d, std::string_view v);

/// Throws ConfigError with message "<prefix><body>[ (line N)]", key `key`.
[[noreturn]] void fail(const Source& src, const std::string& key, const std::string& body, std::size_t line = 0);

/// validate() with messages attributed to `src`.
void validate_as(const Settings& s, const Source& src);

}  // namespace hk::config::detail
