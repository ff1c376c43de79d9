#include "audio/messages.hpp"

#include <boost/locale/gnu_gettext.hpp>
#include <boost/locale/message.hpp>

#include <fstream>
#include <iterator>
#include <set>

#include "hk/language.hpp"
#include "hk/text.hpp"

#ifndef HK_LOCALE_DIR
#define HK_LOCALE_DIR "locale"
#endif

namespace hk::audio {
namespace {

constexpr std::size_t kMaxTextBytes = 2000;

std::set<std::string, std::less<>> placeholders(std::string_view s) {
  std::set<std::string, std::less<>> out;
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

/// The name of a key entry without its family ("key_name.UP" → "UP").
std::string_view entry_name(std::string_view key) { return key.substr(key.find('.') + 1); }

/// `text` with runs of spaces made one and spaces before a comma or full stop dropped: a template whose
/// optional placeholder ({colour} unknown) was left empty.
std::string tidy_spaces(std::string text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    if (c == ' ' && (out.empty() || out.back() == ' ')) continue;
    if ((c == ',' || c == '.') && !out.empty() && out.back() == ' ') out.pop_back();
    out += c;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

}  // namespace

std::filesystem::path default_locale_dir() { return HK_LOCALE_DIR; }

std::string MessageCatalog::voice() const { return std::string(hk::language_subtag(language_)); }

std::string MessageCatalog::translate(const MessageSource& s, long count) const {
  const std::string ctx(s.key), one(s.one);
  if (mo_) {
    const int n = static_cast<int>(std::clamp<long>(count, 0, 1'000'000'000));
    const char* t = s.many.empty() ? mo_->get(ctx.c_str(), one.c_str()) : mo_->get(ctx.c_str(), one.c_str(), n);
    if (t && *t) return t;
  }  // build() looked every entry up once: a file Boost.Locale cannot read was refused there
  return std::string(s.many.empty() || count == 1 ? s.one : s.many);
}

MessageCatalog MessageCatalog::build(std::string_view language, std::optional<MoCatalogue> mo,
                                     const std::string& source) {
  MessageCatalog c;
  c.language_ = language;
  c.mo_ = std::move(mo);
  const std::string where = "catalogue '" + hk::one_line(std::string(language)) + "' (" + hk::one_line(source) + "): ";
  // Each entry is there, not empty, not too long, and uses only the placeholders of its English text.
  const auto check = [&](const MessageSource& s) {
    for (const long n : {1L, 0L, 2L, 5L}) {  // each plural form a visit can say, 0 shapes too
      if (s.many.empty() && n > 1) break;
      const std::string t = c.translate(s, n);
      if (c.mo_ && t == (n == 1 || s.many.empty() ? s.one : s.many)) {
        const char* found = c.mo_->get(std::string(s.key).c_str(), std::string(s.one).c_str());
        if (!found) throw MessageError(where + std::string(s.key) + " is missing");
      }
      if (t.size() > kMaxTextBytes)
        throw MessageError(where + std::string(s.key) + " is " + std::to_string(t.size()) +
                           " bytes, over the limit of " + std::to_string(kMaxTextBytes));
      const auto allowed = placeholders(s.one), allowed_many = placeholders(s.many);
      for (const std::string& p : placeholders(t))
        if (!allowed.count(p) && !allowed_many.count(p))
          throw MessageError(where + std::string(s.key) + " uses {" + hk::one_line(p, 60) +
                             "}, which the English text does not have");
    }
  };
  for (const MessageSource& s : kMessageSources) check(s);
  for (const MessageSource& s : kWordSources) check(s);
  for (const MessageSource& s : kKeyNameSources) check(s);
  for (const MessageSource& s : kKeyPlaceSources) check(s);
  for (std::size_t i = 0; i < kMessageSources.size(); ++i) c.texts_[i] = c.translate(kMessageSources[i], 1);
  for (std::size_t i = 0; i < kWordSources.size(); ++i) c.words_[i] = c.translate(kWordSources[i], 1);
  for (const MessageSource& s : kKeyNameSources) c.key_names_.emplace(entry_name(s.key), c.translate(s, 1));
  for (const MessageSource& s : kKeyPlaceSources) c.key_places_.emplace(entry_name(s.key), c.translate(s, 1));
  return c;
}

const MessageCatalog& MessageCatalog::english() {
  static const MessageCatalog en = build("en", std::nullopt, "built in");
  return en;
}

MessageCatalog MessageCatalog::from_mo(std::string_view language, std::vector<char> mo_bytes,
                                       const std::string& source) {
  return checked(MoCatalogue::from_bytes(kMessageDomain, language, std::move(mo_bytes), source));
}

MessageCatalog MessageCatalog::load(std::string_view language, const std::filesystem::path& locale_dir) {
  if (language == "en") return english();
  return checked(MoCatalogue::load(kMessageDomain, language, locale_dir));
}

MessageCatalog MessageCatalog::checked(MoCatalogue mo) {
  const std::string where = mo.where();
  const std::string language = mo.language(), source = mo.source();
  try {  // Boost.Locale reads parts of the file on the first lookups, which build() makes
    return build(language, std::move(mo), source);
  } catch (const MessageError&) {
    throw;
  } catch (const std::exception& e) {
    throw MessageError(where + "not a gettext MO file (" + hk::one_line(e.what(), 120) + ")");
  }
}

std::string MessageCatalog::key_name(std::string_view name) const {
  const auto it = key_names_.find(name);
  return it == key_names_.end() ? std::string(name) : it->second;
}

std::string MessageCatalog::key_place(std::string_view name) const {
  const auto it = key_places_.find(name);
  return it == key_places_.end() ? std::string() : it->second;
}

std::string MessageCatalog::raw(MessageId id, long count) const {
  const MessageSource& s = kMessageSources[static_cast<std::size_t>(id)];
  return s.many.empty() ? raw(id) : translate(s, count);
}

std::string MessageCatalog::text(MessageId id, std::initializer_list<MessageArg> args,
                                 std::span<const KeyArg> keys) const {
  return expand(raw(id), args, keys);
}

std::string MessageCatalog::text(MessageId id, long count, std::initializer_list<MessageArg> args,
                                 std::span<const KeyArg> keys) const {
  std::vector<MessageArg> all(args);
  all.emplace_back("count", std::to_string(count));  // after the caller's: a caller's own {count} wins
  return expand_all(raw(id, count), all, keys);
}

std::string MessageCatalog::word(std::string_view key, long count, std::initializer_list<MessageArg> args) const {
  for (std::size_t i = 0; i < kWordSources.size(); ++i) {
    const MessageSource& s = kWordSources[i];
    if (s.key != key) continue;
    std::vector<MessageArg> all(args);
    all.emplace_back("count", std::to_string(count));
    return tidy_spaces(expand_all(s.many.empty() || count == 1 ? words_[i] : translate(s, count), all, {}));
  }
  return {};
}

std::string MessageCatalog::expand(std::string_view s, std::initializer_list<MessageArg> args,
                                   std::span<const KeyArg> keys) const {
  return expand_all(s, std::span<const MessageArg>(args.begin(), args.size()), keys);
}

std::string MessageCatalog::expand_all(std::string_view s, std::span<const MessageArg> args,
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
      // Forms are written as they read after "Press"; a sentence starts with a capital.
      if (starts_sentence(out)) form = hk::capitalised(form);
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
