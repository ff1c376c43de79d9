#include "audio/messages.hpp"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <toml++/toml.h>

namespace hk::audio {
namespace {

#include "messages_en.inc"

constexpr std::size_t kMaxTextBytes = 1000;
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

}  // namespace

MessageCatalog MessageCatalog::parse(std::string_view text, const std::string& source) {
  const std::string where = "messages '" + source + "': ";
  toml::table t;
  try {
    t = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::string d(e.description());
    for (char& c : d) {
      if (c == '\n' || c == '\r') c = ' ';
    }
    throw MessageError(where + "not valid TOML: " + d + " (line " + std::to_string(e.source().begin.line) + ")");
  }
  MessageCatalog c;
  const auto voice = t["voice"].value<std::string>();
  if (!voice || voice->empty() || voice->size() > 64) throw MessageError(where + "voice must be an espeak-ng voice name (1 to 64 characters)");
  c.voice_ = *voice;
  c.language_ = t["language"].value_or(std::string(*voice));
  const toml::table* m = t["messages"].as_table();
  if (!m) throw MessageError(where + "has no [messages] table");
  for (const auto& [key, node] : *m) {
    bool known = false;
    for (std::string_view k : kMessageKeys) known = known || k == key.str();
    if (!known) throw MessageError(where + "messages." + std::string(key.str()) + " is not a message the kiosk has");
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
        if (!allowed.count(p)) throw MessageError(where + "messages." + key + " uses {" + p + "}, which the English text does not have");
      }
    }
    c.texts_[static_cast<std::size_t>(i)] = *v;
  }
  return c;
}

const MessageCatalog& MessageCatalog::english() {
  static const MessageCatalog en = parse(kMessagesEnToml, "en.toml (built in)");
  return en;
}

MessageCatalog MessageCatalog::load(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw MessageError("messages '" + path + "': cannot read the file (" + ec.message() + ")");
  if (size > kMaxFileBytes) {
    throw MessageError("messages '" + path + "': " + std::to_string(size) + " bytes is over the limit of " +
                       std::to_string(kMaxFileBytes) + " bytes");
  }
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  if (!f) throw MessageError("messages '" + path + "': cannot read the file");
  return parse(ss.str(), path);
}

std::string MessageCatalog::text(MessageId id, std::initializer_list<MessageArg> args) const {
  std::string s = raw(id);
  for (const MessageArg& a : args) {
    const std::string token = "{" + std::string(a.first) + "}";
    for (std::size_t i = s.find(token); i != std::string::npos; i = s.find(token, i + a.second.size())) {
      s.replace(i, token.size(), a.second);
    }
  }
  return s;
}

}  // namespace hk::audio
