#pragma once
/// @file mo_catalogue.hpp
/// One gettext domain's compiled catalogue (a GNU MO file) in one language, read with Boost.Locale's gnu_gettext
/// facet from the kiosk's own folder, needing no system locale. The visitor's messages (messages.hpp, domain
/// haptic-kiosk) and the operator panel's words (domain haptic-kiosk-panel) are both read with it.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "hk/error.hpp"

namespace hk::audio {

/// The largest catalogue file read [bytes].
inline constexpr std::uintmax_t kMaxCatalogueBytes = 1024 * 1024;

/// A catalogue file that cannot be used. what() is one line naming the file and, when one entry is at
/// fault, its key, e.g. "catalogue 'de' (/usr/share/haptic-kiosk/locale/de/LC_MESSAGES/haptic-kiosk.mo): help uses
/// {colour}, which the English text does not have".
class MessageError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// What is wrong with `mo` as a GNU MO file (the gettext manual, "The Format of GNU MO Files"), "" when nothing:
/// the magic number in either byte order, a revision of 0 or 1, a header entry (Boost.Locale reads entry 0 whatever
/// the count says), and every string table entry
/// and the hash table inside the file, each string NUL-terminated, each hash slot 0 or an entry's number + 1.
/// Boost.Locale 1.74 reads the offsets as they are, so a file is checked before it is handed over.
std::string mo_problem(const std::vector<char>& mo);

/// A compiled catalogue. Copies share the compiled file; lookups are safe from any thread once loaded.
class MoCatalogue {
 public:
  /// `locale_dir`/LANG/LC_MESSAGES/`domain`.mo, LANG the tag `language`, then its language subtag ("de-CH" falls
  /// back to "de").
  /// @throws MessageError (one line naming the language and the file) for a tag that is not BCP 47, no file, a
  ///         file over kMaxCatalogueBytes, or one that is not an MO file (mo_problem, or Boost.Locale refuses it).
  static MoCatalogue load(std::string_view domain, std::string_view language, const std::filesystem::path& locale_dir);
  /// The same from the bytes of an MO file (`source` names it in errors). @throws MessageError.
  static MoCatalogue from_bytes(std::string_view domain, std::string_view language, std::vector<char> mo_bytes,
                                const std::string& source);

  /// The translation of `id` in `context` (null: none); null when the catalogue has none. Boost.Locale may throw
  /// on a lookup in a damaged file (callers look every entry up once after loading).
  const char* get(const char* context, const char* id) const;
  /// The translation of plural entry `id` in the form for `count` (the catalogue's Plural-Forms); null when none.
  const char* get(const char* context, const char* id, int count) const;
  /// The catalogue's BCP 47 tag, as asked for.
  const std::string& language() const { return language_; }
  /// The file it was read from (or the name given to from_bytes).
  const std::string& source() const { return source_; }
  /// "catalogue 'fr' (FILE): ", the start of every MessageError about it.
  std::string where() const;

 private:
  struct Compiled;  // the MO's std::locale with its Boost.Locale message facet
  std::shared_ptr<const Compiled> compiled_;
  std::string language_, source_;
};

}  // namespace hk::audio
