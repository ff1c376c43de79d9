// Fuzz harness: the settings file (config/load.hpp), as an operator or a stick might hand it over.
//
// Entry point: hk::config::parse_settings (the in-memory half of load_settings: TOML parse, every key
// checked against its descriptor, validate). toml++ is compiled into this harness (header-only), so the
// fuzzer sees the parser's coverage too. Properties:
//  - a refusal is a ConfigError whose what() is one line "config '<source>': ...", at most a few hundred
//    bytes, and whose key() is empty, "[table]" or "table.key" of a real field;
//  - accepted settings pass validate() and survive to_toml -> parse_settings unchanged.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "config/load.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::string source = "stick/kiosk.toml";
  hk::config::Settings s;
  try {
    s = hk::config::parse_settings(text, source);
  } catch (const hk::config::ConfigError& e) {
    const std::string what = e.what();
    FUZZ_CHECK(hk::fuzz::is_one_line(what), what);
    FUZZ_CHECK(what.starts_with("config '" + source + "': "), what);
    FUZZ_CHECK(what.size() <= 1024, what);
    FUZZ_CHECK(e.source() == source, what);
    const std::string& key = e.key();
    FUZZ_CHECK(hk::fuzz::is_one_line(key), key);
    // Empty (not about one key), "[table]", "table.key", or a bare key outside any table.
    FUZZ_CHECK(key.empty() || (key.front() == '[' && key.back() == ']') || key.find('.') != std::string::npos ||
                   what.find("outside any table") != std::string::npos,
               key);
    return 0;
  }
  try {
    hk::config::validate(s);
  } catch (const hk::config::ConfigError& e) {
    FUZZ_CHECK(false, std::string("accepted settings fail validate(): ") + e.what());
  }
  const std::string again = hk::config::to_toml(s);
  try {
    FUZZ_CHECK(hk::config::parse_settings(again, "round trip") == s, again);
  } catch (const hk::config::ConfigError& e) {
    FUZZ_CHECK(false, std::string("to_toml of accepted settings does not load: ") + e.what());
  }
  return 0;
}
