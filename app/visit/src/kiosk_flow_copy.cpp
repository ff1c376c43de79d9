// The visitor's flow: the Copy key and what became of the copy (kiosk_flow.hpp, kiosk_effects.hpp CopyEffects).
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

void KioskFlow::copy_done(const std::string& line, double now_s) {
  guarded("a copy made", [&] {
    activity(now_s);
    if (line.empty())
      say(MessageId::copy_printed);
    else
      fx_.speech.say(line);
  });
}

void KioskFlow::copy_failed(double now_s) {
  guarded("a copy that failed", [&] {
    activity(now_s);
    say(MessageId::copy_failed);
  });
}

}  // namespace hk::app
