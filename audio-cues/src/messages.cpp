#include "audio/messages.hpp"

#include <toml++/toml.h>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "hk/text.hpp"

namespace hk::audio {
namespace {

#include "messages_en.inc"

constexpr std::size_t kMaxTextBytes = 1000;
constexpr std::size_t kMaxKeyNameBytes = 100;
constexpr std::uintmax_t kMaxFileBytes = 256 * 1024;

std::set<std::string> placeholders(std::string_view s) {
  std::set<std::string> out;
  for (std::size_t i = s.find('{'); i != std::string_view::npos; i = s.find('{', i + 1)) {
    const std::size_t j = s.find('}', i);
    if (j == std::string_view::npos) break;
    out.emplace(s.substr(i + 1, j - i - 1));
  }
  return out;
}

/// True when text put at the end of `out` starts a sentence: `out` is empty or blank, or its last
/// character before the spaces ends one ('.', '!', '?').
bool starts_sentence(const std::string& out) {
  const std::size_t last = out.find_last_not_of(" \t\n");
  if (last == std::string::npos) return true;
  if (last + 1 == out.size()) return false;  // no space: in the middle of a word
  const char c = out[last];
  return c == '.' || c == '!' || c == '?';
}

using KeyMap = std::map<std::string, std::string, std::less<>>;

/// [key_places] (optional, any of the key names): where each key lies on the keypad, as a blind visitor finds it.
KeyMap key_places(const toml::table& t, const std::string& where, const KeyMap& key_names) {
  KeyMap out;
  const toml::node* node = t.get("key_places");
  if (!node) return out;
  const toml::table* kp = node->as_table();
  if (!kp) throw MessageError(where + "key_places must be a table");
  for (const auto& [key, value] : *kp) {
    const std::string name(key.str());
    const std::string shown = hk::one_line(name, 60);
    if (!key_names.count(name)) throw MessageError(where + "key_places." + shown + " is not a key name of [key_names]");
    const auto v = value.value<std::string>();
    if (!v) throw MessageError(where + "key_places." + shown + " is not a string");
    if (v->empty() || v->size() > MessageCatalog::kMaxKeyPlaceBytes) {
      throw MessageError(where + "key_places." + shown + " must be 1 to " +
                         std::to_string(MessageCatalog::kMaxKeyPlaceBytes) + " bytes");
    }
    out.emplace(name, *v);
  }
  return out;
}

}  // namespace

MessageCatalog MessageCatalog::parse(std::string_view text, const std::string& source) {
  const std::string where = "messages '" + hk::one_line(source) + "': ";
  toml::table t;
  try {
    t = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    const std::string d = hk::one_line(e.description(), 160);  // toml++ quotes the offending character as it is
    throw MessageError(where + "not valid TOML: " + d + " (line " + std::to_string(e.source().begin.line) + ")");
  }
  MessageCatalog c;
  const auto voice = t["voice"].value<std::string>();
  if (!voice || voice->empty() || voice->size() > 64)
    throw MessageError(where + "voice must be an espeak-ng voice name (1 to 64 characters)");
  c.voice_ = *voice;
  c.language_ = t["language"].value_or(std::string(*voice));
  const toml::table* m = t["messages"].as_table();
  if (!m) throw MessageError(where + "has no [messages] table");
  for (const auto& [key, node] : *m) {
    bool known = false;
    for (std::string_view k : kMessageKeys) known = known || k == key.str();
    if (!known)
      throw MessageError(where + "messages." + hk::one_line(key.str(), 60) + " is not a message the kiosk has");
  }
  // The English file is the reference for placeholders (it is parsed first, with itself as reference).
  const MessageCatalog* en = source == "en.toml (built in)" ? nullptr : &english();
  for (int i = 0; i < kMessageCount; ++i) {
    const std::string key(kMessageKeys[static_cast<std::size_t>(i)]);
    const auto v = (*m)[key].value<std::string>();
    if (!v) throw MessageError(where + "messages." + key + " is missing (or not a string)");
    if (v->empty() || v->size() > kMaxTextBytes) {
      throw MessageError(where + "messages." + key + " must be 1 to " + std::to_string(kMaxTextBytes) + " bytes");
    }
    if (en) {
      const auto allowed = placeholders(en->raw(static_cast<MessageId>(i)));
      for (const std::string& p : placeholders(*v)) {
        if (!allowed.count(p))
          throw MessageError(where + "messages." + key + " uses {" + hk::one_line(p, 60) +
                             "}, which the English text does not have");
      }
    }
    c.texts_[static_cast<std::size_t>(i)] = *v;
  }
  // [key_names]: English names every key a visitor may be given; a translation names exactly the same ones.
  const toml::table* kn = t["key_names"].as_table();
  if (!kn) throw MessageError(where + "has no [key_names] table");
  for (const auto& [key, node] : *kn) {
    const std::string name(key.str());
    const std::string shown = hk::one_line(name, 60);  // a quoted TOML key may hold any character
    if (en && !en->key_names_.count(name)) {
      throw MessageError(where + "key_names." + shown + " is not a key name the English catalogue has");
    }
    const auto v = node.value<std::string>();
    if (!v) throw MessageError(where + "key_names." + shown + " is not a string");
    if (v->empty() || v->size() > kMaxKeyNameBytes) {
      throw MessageError(where + "key_names." + shown + " must be 1 to " + std::to_string(kMaxKeyNameBytes) + " bytes");
    }
    c.key_names_.emplace(name, *v);
  }
  if (en) {
    for (const auto& [name, form] : en->key_names_) {
      if (!c.key_names_.count(name)) throw MessageError(where + "key_names." + name + " is missing (or not a string)");
    }
  } else if (c.key_names_.empty()) {
    throw MessageError(where + "[key_names] is empty");
  }
  c.key_places_ = key_places(t, where, c.key_names_);
  return c;
}

std::string MessageCatalog::key_place(std::string_view name) const {
  const auto it = key_places_.find(name);
  return it == key_places_.end() ? std::string() : it->second;
}

const MessageCatalog& MessageCatalog::english() {
  static const MessageCatalog en = parse(kMessagesEnToml, "en.toml (built in)");
  return en;
}

MessageCatalog MessageCatalog::load(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw MessageError("messages '" + hk::one_line(path) + "': cannot read the file (" + ec.message() + ")");
  if (size > kMaxFileBytes) {
    throw MessageError("messages '" + hk::one_line(path) + "': " + std::to_string(size) +
                       " bytes is over the limit of " + std::to_string(kMaxFileBytes) + " bytes");
  }
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  if (!f) throw MessageError("messages '" + hk::one_line(path) + "': cannot read the file");
  return parse(ss.str(), path);
}

std::string MessageCatalog::key_name(std::string_view name) const {
  const auto it = key_names_.find(name);
  return it == key_names_.end() ? std::string(name) : it->second;
}

std::string MessageCatalog::text(MessageId id, std::initializer_list<MessageArg> args,
                                 std::span<const KeyArg> keys) const {
  return expand(raw(id), args, keys);
}

std::string MessageCatalog::expand(std::string_view s, std::initializer_list<MessageArg> args,
                                   std::span<const KeyArg> keys) const {
  std::string out;
  out.reserve(s.size());
  std::size_t i = 0;
  while (i < s.size()) {
    std::size_t open = s.find('{', i);
    if (open == std::string::npos) break;
    const std::size_t close = s.find('}', open + 1);
    if (close == std::string::npos) break;
    open = s.rfind('{', close);  // the innermost: "{{seconds}}" keeps its outer braces
    const std::string_view name = s.substr(open + 1, close - open - 1);
    out.append(s.substr(i, open - i));
    const MessageArg* arg = nullptr;
    for (const MessageArg& a : args) {
      if (!arg && a.first == name) arg = &a;
    }
    const KeyArg* key = nullptr;
    for (const KeyArg& k : keys) {
      if (!key && k.first == name) key = &k;
    }
    if (arg) {
      out += arg->second;
    } else if (key) {
      std::string form = key_name(key->second);
      // Forms are written as they read after "Press"; a sentence starts with a capital (ASCII letters only).
      if (!form.empty() && starts_sentence(out) && form[0] >= 'a' && form[0] <= 'z')
        form[0] = static_cast<char>(form[0] - 'a' + 'A');
      out += form;
    } else {
      out.append(s.substr(open, close - open + 1));  // unknown: left as it is
    }
    i = close + 1;
  }
  out.append(s.substr(i));
  return out;
}

}  // namespace hk::audio
