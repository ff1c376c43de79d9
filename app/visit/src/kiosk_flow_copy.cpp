// The visitor's flow: the Copy key and what became of the copy (kiosk_flow.hpp, kiosk_effects.hpp CopyEffects).
#include <optional>

#include "visit/kiosk_flow.hpp"

namespace hk::app {

using audio::MessageId;

void KioskFlow::copy_key(double now_s) {
  CopyEffects* copies = fx_.copies;
  if (copies == nullptr || !copies->copies_offered()) {
    say(MessageId::copy_not_set_up);
    return;
  }
  if (v_.state != KioskState::Picture) {
    say(MessageId::copy_nothing);
    return;
  }
  if (copies->stick_missing()) {
    say(MessageId::copy_no_stick);
    return;
  }
  if (v_.copies_made >= p_.copy_per_visit) {
    fx_.speech.say(counted(MessageId::copy_visit_limit, p_.copy_per_visit));
    return;
  }
  if (copies->day_limit_reached()) {
    say(MessageId::copy_day_limit);
    return;
  }
  // The first press only asks: a copy is paper and a printer's time, not made by a key pressed by accident.
  if (v_.copy_asked_s < 0 || now_s - v_.copy_asked_s > kCopyConfirm_s) {
    v_.copy_asked_s = now_s;
    say(MessageId::copy_confirm);
    return;
  }
  v_.copy_asked_s = -1;
  if (!copies->start_copy()) {
    say(MessageId::copy_nothing);
    return;
  }
  ++v_.copies_made;
  say(MessageId::copy_making);
}

namespace {

/// The sentence for the stick's route (none when it was not asked).
std::optional<MessageId> saved_message(CopyReport::Route r) {
  using Route = CopyReport::Route;
  switch (r) {
    case Route::NotAsked:
      return std::nullopt;
    case Route::Done:
      return MessageId::copy_saved;
    case Route::NoStick:
      return MessageId::copy_no_stick;
    case Route::Full:
      return MessageId::copy_stick_full;
    case Route::WriteProtected:
      return MessageId::copy_stick_locked;
    case Route::Format:
      return MessageId::copy_stick_format;
    case Route::Failed:
      return MessageId::copy_stick_failed;
  }
  return MessageId::copy_stick_failed;
}

}  // namespace

void KioskFlow::copy_finished(const CopyReport& report, double now_s) {
  guarded("a copy finished", [&] {
    activity(now_s);
    std::string line;
    if (report.printed == CopyReport::Route::Done)
      line = report.printed_line.empty() ? text(MessageId::copy_printed) : report.printed_line;
    else if (report.printed != CopyReport::Route::NotAsked)
      line = text(MessageId::copy_failed);
    if (const std::optional<MessageId> saved = saved_message(report.saved)) {
      if (!line.empty()) line += " ";
      line += text(*saved, {{"folder", report.folder}});
    }
    if (report.nothing_made() && v_.copies_made > 0) --v_.copies_made;  // nothing to take home: not the visit's copy
    if (line.empty()) line = text(MessageId::copy_failed);
    fx_.speech.say(line);
  });
}

}  // namespace hk::app
