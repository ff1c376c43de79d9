// Fuzz harness: a compiled message catalogue (an MO file, audio-cues/include/audio/messages.hpp).
//
// Entry point: hk::audio::MessageCatalog::from_mo (the in-memory half of load), which hands the bytes to
// Boost.Locale's gettext reader and checks every entry against the English source. Properties:
//  - a refusal is a MessageError whose what() is one line "catalogue 'fr' (stick/fr.mo): ...", of bounded length;
//  - an accepted catalogue keeps the documented limits (every message, word, key name and key place at most 2000
//    bytes, using only its English text's placeholders), and text() expands every message, plain and counted
//    for 0, 1, 2 and 5, without growing beyond what was put in.

#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <vector>

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
  const std::string source = "stick/fr.mo";
  try {
    const MessageCatalog c = MessageCatalog::from_mo("fr", std::vector<char>(data, data + size), source);
    const std::string arg(20, 'x');
    const hk::audio::KeyArg keys[] = {{"help_key", "F1"}, {"next_key", "UP"}};
    std::size_t longest_key = 0;
    for (const auto& [name, form] : c.key_names()) longest_key = std::max(longest_key, form.size());
    for (int i = 0; i < hk::audio::kMessageCount; ++i) {
      const auto id = static_cast<MessageId>(i);
      const auto& source_text = hk::audio::kMessageSources[static_cast<std::size_t>(i)];
      std::set<std::string> allowed = placeholders(source_text.one);
      for (const std::string& p : placeholders(source_text.many)) allowed.insert(p);
      for (const long n : {0L, 1L, 2L, 5L}) {
        const std::string raw = c.raw(id, n);
        FUZZ_CHECK(raw.size() <= 2000, raw);
        for (const std::string& p : placeholders(raw)) FUZZ_CHECK(allowed.count(p) == 1, p);
        const std::string filled = c.text(id, n, {{"picture", arg}, {"title", arg}}, keys);
        // Each placeholder (at least 2 bytes of braces) is replaced by at most max(arg, key name, count) bytes.
        FUZZ_CHECK(filled.size() <= raw.size() * (1 + std::max(arg.size(), longest_key)), filled);
      }
    }
    for (const auto& w : hk::audio::kWordSources) FUZZ_CHECK(c.word(w.key, 2).size() <= 2000 * 3, w.key);
  } catch (const hk::audio::MessageError& e) {
    const std::string what = e.what();
    FUZZ_CHECK(hk::fuzz::is_one_line(what), what);
    FUZZ_CHECK(what.starts_with("catalogue 'fr' (" + source + "): "), what);
    FUZZ_CHECK(what.size() <= 1024, what);
  }
  return 0;
}
