// Fuzz harness: a message catalogue (translation) file (audio-cues/include/audio/messages.hpp).
//
// Entry point: hk::audio::MessageCatalog::parse (the in-memory half of load). toml++ is compiled into this
// harness (header-only), so the fuzzer sees the parser's coverage too. Properties:
//  - a refusal is a MessageError whose what() is one line "messages '<source>': ...", of bounded length;
//  - an accepted catalogue keeps the documented limits (voice 1..64 bytes, every text 1..1000 bytes and
//    using only the English text's placeholders, [key_names] exactly English's, each 1..100 bytes), and
//    text() expands every message, with and without arguments, without growing beyond what was put in.

#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>

#include "audio/messages.hpp"
#include "fuzz_common.hpp"

namespace {

std::set<std::string> placeholders(std::string_view s) {
  std::set<std::string> out;
  for (std::size_t i = s.find('{'); i != std::string_view::npos; i = s.find('{', i + 1)) {
    const std::size_t j = s.find('}', i);
    if (j == std::string_view::npos) break;
    out.emplace(s.substr(i + 1, j - i - 1));
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  (void)hk::audio::MessageCatalog::english();  // built once, outside the measured runs
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using hk::audio::MessageCatalog;
  using hk::audio::MessageId;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::string source = "stick/de.toml";
  try {
    const MessageCatalog c = MessageCatalog::parse(text, source);
    const MessageCatalog& en = MessageCatalog::english();
    FUZZ_CHECK(!c.voice().empty() && c.voice().size() <= 64, c.voice());
    FUZZ_CHECK(c.key_names().size() == en.key_names().size(), c.voice());
    for (const auto& [name, form] : c.key_names()) {
      FUZZ_CHECK(en.key_names().count(name) == 1, name);
      FUZZ_CHECK(!form.empty() && form.size() <= 100, form);
    }
    const std::string arg(20, 'x');
    for (int i = 0; i < hk::audio::kMessageCount; ++i) {
      const auto id = static_cast<MessageId>(i);
      const std::string& raw = c.raw(id);
      FUZZ_CHECK(!raw.empty() && raw.size() <= 1000, raw);
      const std::set<std::string> allowed = placeholders(en.raw(id));
      for (const std::string& p : placeholders(raw)) FUZZ_CHECK(allowed.count(p) == 1, p);
      FUZZ_CHECK(c.text(id) == raw, raw);  // nothing to put in: unchanged
      const hk::audio::KeyArg keys[] = {{"help_key", "F1"}, {"next_key", "UP"}};
      const std::string filled = c.text(id, {{"picture", arg}, {"title", arg}, {"seconds", arg}}, keys);
      std::size_t longest_key = 0;
      for (const auto& [name, form] : c.key_names()) longest_key = std::max(longest_key, form.size());
      // Each placeholder (at least 2 bytes of braces) is replaced by at most max(arg, key name) bytes.
      FUZZ_CHECK(filled.size() <= raw.size() * (1 + std::max(arg.size(), longest_key)), filled);
    }
  } catch (const hk::audio::MessageError& e) {
    const std::string what = e.what();
    FUZZ_CHECK(hk::fuzz::is_one_line(what), what);
    FUZZ_CHECK(what.starts_with("messages '" + source + "': "), what);
    FUZZ_CHECK(what.size() <= 1024, what);
  }
  return 0;
}
