#pragma once
/// @file language.hpp
/// Language tags as the settings and the catalogues name languages (BCP 47, RFC 5646, the subset the kiosk
/// takes): "en", "fr", "pt-BR", "sr-Latn".

#include <string>
#include <string_view>
#include <vector>

namespace hk {

/// Whether `tag` is a language tag the kiosk takes: a 2- or 3-letter lower-case language subtag, then
/// optional subtags of 1 to 8 ASCII letters or digits after '-'; 35 bytes at most.
bool is_language_tag(std::string_view tag);

/// The language subtag of `tag`: "fr" of "fr-CA", `tag` itself when it has no other subtag.
inline std::string_view language_subtag(std::string_view tag) { return tag.substr(0, tag.find('-')); }

/// The tags of a list the settings give as "en, fr, de" (comma-separated, spaces ignored), in order.
/// Returns an empty list, with `*problem` set to one line naming the entry at fault, when an entry is not a
/// language tag, one is given twice, or there are none or more than kMaxLanguages.
std::vector<std::string> language_list(std::string_view list, std::string* problem = nullptr);

/// Most languages one kiosk offers.
inline constexpr std::size_t kMaxLanguages = 16;

}  // namespace hk
