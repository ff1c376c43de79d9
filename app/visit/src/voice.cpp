// What the kiosk says (voice.hpp).
#include "visit/voice.hpp"
#include "hk/language.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <ctime>
#include <optional>

namespace hk::app {
namespace {

/// `text` with its line breaks (a reading's sentences are joined by them) as spaces: one line of the log.
std::string one_line(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

}  // namespace

void Voice::say(const std::string& text) {
  spdlog::info("say: {}", one_line(text));
  last_said_ = text;
  repeatable_ = text;
  ++kept_texts_;
  ++texts_said_;
  brief_last_ = false;
  audio_.say_text(text);
}

void Voice::say_brief(const std::string& text) {
  spdlog::info("say: {}", one_line(text));
  last_said_ = text;
  ++texts_said_;
  brief_last_ = true;
  audio_.say_text(text, false);
}

bool Voice::repeat() {
  if (repeatable_.empty()) return false;
  say(std::string(repeatable_));
  return true;
}

void Voice::say_in(const std::string& text, int from_piece, const std::string& language, int until_piece) {
  if (until_piece < 0)
    spdlog::info("say: {} (from piece {} in {})", one_line(text), from_piece, language);
  else
    spdlog::info("say: {} (pieces {} to {} in {})", one_line(text), from_piece, until_piece - 1, language);
  last_said_ = text;
  repeatable_ = text;
  ++kept_texts_;
  ++texts_said_;
  brief_last_ = false;
  audio_.say_text_in(text, true, static_cast<std::size_t>(std::max(0, from_piece)), language,
                     until_piece < 0 ? SIZE_MAX : static_cast<std::size_t>(until_piece));
}

std::string Voice::language_name_of(const std::string& tag) const {
  const auto& codes = audio_.languages();
  for (std::size_t i = 0; i < codes.size(); ++i)
    if (hk::language_subtag(codes[i]) == hk::language_subtag(tag))
      return audio_.catalogue(static_cast<int>(i)).language_name();
  return {};
}

void Voice::set_language(int index) {
  if (index == audio_.language() || !audio_.set_language(index)) return;
  spdlog::info("kiosk: language {}", audio_.languages()[static_cast<std::size_t>(index)]);
}

bool Voice::quiet_hours() const {
  const std::optional<config::QuietHours> hours = config::parse_quiet_hours(s_.kiosk.quiet_hours);
  if (!hours) return false;
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  if (localtime_r(&now, &local) == nullptr) return false;
  return config::in_quiet_hours(*hours, local.tm_hour * 60 + local.tm_min);
}

}  // namespace hk::app
