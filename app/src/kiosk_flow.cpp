#include "kiosk_flow.hpp"

#include <algorithm>
#include <cmath>

namespace hk::app {

using audio::MessageId;

KioskFlow::KioskFlow(KioskEffects& effects, const audio::MessageCatalog& messages, const KioskFlowParams& params)
    : fx_(effects), msg_(messages), p_(params) {
  p_.warning_s = std::min(p_.warning_s, 0.5 * p_.timeout_s);  // a warning must leave time to answer it
}

void KioskFlow::say(MessageId id, std::initializer_list<audio::MessageArg> args) { fx_.say(msg_.text(id, args)); }

void KioskFlow::start_tutorial() {
  state_ = KioskState::Tutorial;
  shape_ = TutorialShape::Square;
  fx_.show_tutorial(shape_);
}

void KioskFlow::show(int index, const std::string& before) {
  const int n = fx_.picture_count();
  picture_ = ((index % n) + n) % n;  // wraps round both ways
  state_ = KioskState::Picture;
  const int shapes = fx_.show_picture(picture_);
  const std::string num = std::to_string(picture_ + 1), total = std::to_string(n);
  std::string text;
  if (shapes == 0) {
    text = msg_.text(MessageId::picture_empty, {{"picture", num}, {"pictures", total}});
  } else if (shapes == 1) {
    text = msg_.text(MessageId::picture_loaded_one, {{"picture", num}, {"pictures", total}});
  } else {
    text = msg_.text(MessageId::picture_loaded, {{"picture", num}, {"pictures", total}, {"shapes", std::to_string(shapes)}});
  }
  fx_.say(before.empty() ? text : before + " " + text);
}

void KioskFlow::wake(double now_s) {
  last_activity_s_ = now_s;
  warned_ = false;
  start_tutorial();
  fx_.say(msg_.raw(MessageId::welcome) + " " + msg_.raw(MessageId::tutorial_start));
}

void KioskFlow::handle_moved(double now_s) {
  if (state_ == KioskState::Attract) {
    wake(now_s);
    return;
  }
  last_activity_s_ = now_s;
  warned_ = false;
}

void KioskFlow::key(KioskKey k, double now_s) {
  if (state_ == KioskState::Attract) {
    wake(now_s);
    return;
  }
  last_activity_s_ = now_s;
  warned_ = false;
  switch (k) {
    case KioskKey::Help:
      say(MessageId::help);
      return;
    case KioskKey::Tutorial:
      start_tutorial();
      say(MessageId::tutorial_start);
      return;
    case KioskKey::VolumeUp:
      say(fx_.change_volume(+1) ? MessageId::volume_up : MessageId::volume_limit);
      return;
    case KioskKey::VolumeDown:
      say(fx_.change_volume(-1) ? MessageId::volume_down : MessageId::volume_limit);
      return;
    default:
      break;
  }
  if (state_ == KioskState::Tutorial) {
    switch (k) {
      case KioskKey::Next:
        if (shape_ == TutorialShape::Square) {
          shape_ = TutorialShape::Circle;
          fx_.show_tutorial(shape_);
          say(MessageId::tutorial_circle);
        } else if (shape_ == TutorialShape::Circle) {
          shape_ = TutorialShape::Triangle;
          fx_.show_tutorial(shape_);
          say(MessageId::tutorial_triangle);
        } else {
          show(0, msg_.raw(MessageId::tutorial_done));
        }
        return;
      case KioskKey::Previous:
        if (shape_ != TutorialShape::Square) shape_ = static_cast<TutorialShape>(static_cast<int>(shape_) - 1);
        fx_.show_tutorial(shape_);
        say(shape_ == TutorialShape::Square ? MessageId::tutorial_start : MessageId::tutorial_circle);
        return;
      case KioskKey::Describe:
        fx_.say(fx_.describe());
        return;
      default:
        say(MessageId::help);  // any other key still gets an answer
        return;
    }
  }
  switch (k) {  // Picture
    case KioskKey::Next:
      show(picture_ + 1);
      return;
    case KioskKey::Previous:
      show(picture_ - 1);
      return;
    case KioskKey::Describe:
      fx_.say(msg_.text(MessageId::describe, {{"description", fx_.describe()}}));
      return;
    case KioskKey::Finer:
      say(fx_.change_level(-1) ? MessageId::level_finer : MessageId::level_finest);
      return;
    case KioskKey::Coarser:
      say(fx_.change_level(+1) ? MessageId::level_coarser : MessageId::level_coarsest);
      return;
    default:
      say(MessageId::help);
      return;
  }
}

void KioskFlow::tick(double now_s) {
  if (state_ == KioskState::Attract) return;
  const double idle = now_s - last_activity_s_;
  if (idle >= p_.timeout_s) {
    fx_.new_session();  // first: it stops speech, and the goodbye must be heard
    say(MessageId::goodbye);
    state_ = KioskState::Attract;
    warned_ = false;
    return;
  }
  if (!warned_ && idle >= p_.timeout_s - p_.warning_s) {
    warned_ = true;
    say(MessageId::timeout_warning, {{"seconds", std::to_string(static_cast<int>(std::lround(p_.timeout_s - idle)))}});
  }
}

}  // namespace hk::app
