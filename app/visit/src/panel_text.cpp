// The operator panel's words in the staff's language (panel_text.hpp).
#include "visit/panel_text.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace hk::app {

PanelText PanelText::load(const std::string& language, const std::filesystem::path& locale_dir) {
  PanelText t;
  t.asked_ = language;
  if (language.empty() || language == "en" || language.rfind("en-", 0) == 0) return t;
  try {
    t.mo_ = audio::MoCatalogue::load(kPanelDomain, language, locale_dir);
    (void)t.mo_->get(nullptr, "Apply");  // Boost.Locale reads parts of a file on its first lookup
  } catch (const std::exception& e) {
    spdlog::warn("operator panel: {}; the panel is in English", e.what());
    t.mo_.reset();
  }
  return t;
}

const char* PanelText::operator()(const char* english) const {
  if (!mo_) return english;
  try {
    const char* t = mo_->get(nullptr, english);
    return t && *t ? t : english;
  } catch (const std::exception&) {  // a damaged file: its words stay English
    return english;
  }
}

const char* PanelText::operator()(const char* one, const char* many, long n) const {
  const char* english = n == 1 ? one : many;
  if (!mo_) return english;
  try {
    const char* t = mo_->get(nullptr, one, static_cast<int>(std::clamp(n, -1000000L, 1000000L)));
    return t && *t ? t : english;
  } catch (const std::exception&) {
    return english;
  }
}

std::string PanelText::operator()(std::string_view english) const { return (*this)(std::string(english).c_str()); }

}  // namespace hk::app
