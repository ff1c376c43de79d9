#pragma once
/// @file panel_text.hpp
/// The operator panel's words in the staff's language ([operator] language): the English of the panel's source
/// (tr("…") in operator_panel.cpp, N_("…") and every settings field's help in config/src/fields.cpp) looked up in
/// the gettext domain haptic-kiosk-panel, compiled from app/kiosk/po/LANG.po into LOCALE/LANG/LC_MESSAGES/
/// haptic-kiosk-panel.mo (audio::MoCatalogue: Boost.Locale, no system locale). English needs no file: a language
/// without a panel catalogue, or one that cannot be read, is English with one log line.
///
/// The lines the operator session composes (the PIN prompt, the lockout, Apply's and Save's status, a refused
/// value) are printf templates marked tr("…") or trn("…", "…", n) in operator_session.cpp: msgfmt --check holds
/// each translation to the English template's conversions, so format() can hand them the same arguments.

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "audio/mo_catalogue.hpp"

namespace hk::app {

/// The gettext domain of the operator panel.
inline constexpr std::string_view kPanelDomain = "haptic-kiosk-panel";

/// The panel's words in one language. Copyable; copies share the compiled catalogue.
class PanelText {
 public:
  /// English: every word as written.
  PanelText() = default;
  /// The panel in `language` (a BCP 47 tag) from `locale_dir`; English ("en", or when that language has no
  /// panel catalogue or it cannot be read: then one warning in the log naming the language and the file).
  static PanelText load(const std::string& language, const std::filesystem::path& locale_dir);

  /// `english` in the panel's language; `english` itself where the catalogue has no translation of it. The
  /// pointer lives as long as this object (or the literal passed).
  const char* operator()(const char* english) const;
  /// The same for a text that is not NUL-terminated where it ends (a field's help).
  std::string operator()(std::string_view english) const;
  /// The plural entry `one` / `many` in the form for `n` (the catalogue's Plural-Forms; English: `one` for 1).
  const char* operator()(const char* one, const char* many, long n) const;
  /// The language asked for, as given to load() ("en" for the default).
  const std::string& asked() const { return asked_; }
  /// The language the words are in: the catalogue's, or "en".
  std::string language() const { return mo_ ? mo_->language() : std::string("en"); }

 private:
  std::string asked_ = "en";
  std::optional<audio::MoCatalogue> mo_;
};

/// `tmpl` (a printf template: a translated tr("…") whose conversions msgfmt --check matched to the English one's)
/// filled in with `args`.
template <typename... Args>
std::string format(const char* tmpl, Args... args) {
  const int n = std::snprintf(nullptr, 0, tmpl, args...);
  if (n <= 0) return {};
  std::string out(static_cast<std::size_t>(n) + 1, '\0');
  std::snprintf(out.data(), out.size(), tmpl, args...);
  out.pop_back();
  return out;
}

}  // namespace hk::app
