// The guided tour's window-thread half (tour_desk.hpp).
#include "visit/tour_desk.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "runtime/runtime_params.hpp"
#include "visit/describe.hpp"

namespace hk::app {

TourDesk::TourDesk(ServoStep& step, DeviceHost& devices, Voice& voice, const audio::AudioSystem& audio,
                   const config::Settings& settings, Vec2 half_m, Vec2 cursor_m)
    : step_(step), devices_(devices), voice_(voice), audio_(audio), s_(settings), half_(half_m), cursor_in_(cursor_m) {}

void TourDesk::set_cursor(Vec2 m) {
  cursor_in_ = m;
  if (running_ && !quiet_ && length(m - cursor_ref_) > 0.003) {
    step_.cancel_tour();  // the visitor's hand takes over
    quiet_ = true;
    spdlog::info("tour: stopped by the hand");
  }
  const Vec2 c = m + cursor_offset_;
  const bool offset = cursor_offset_.x != 0.0 || cursor_offset_.y != 0.0;
  devices_.set_target(offset ? Vec2{std::clamp(c.x, -half_.x, half_.x), std::clamp(c.y, -half_.y, half_.y)} : m);
}

void TourDesk::stop_quietly() {
  asked_ = false;  // an announced tour does not start
  if (running_) {
    step_.cancel_tour();
    quiet_ = true;
  }
}

void TourDesk::key_pressed() {
  guide_stops_ = running();
  stop_quietly();
}

void TourDesk::guide() {
  const TourPicture picture = this->picture();
  const bool stops = guide_stops_;
  guide_stops_ = false;
  if (picture.scene && parts_offered_ < picture.parts.size()) return offer_part(picture);
  if (stops) {
    voice_.say(audio_.messages().text(audio::MessageId::tour_stopped));
    return;
  }
  if (!picture.scene) return;
  const TourParams tp = tour_params_from(s_);
  if (!plan_tour(*picture.scene, picture.id, step_.display().handle_m, touches_, tp)) {
    if (!picture.parts.empty()) return offer_part(picture);  // every shape touched: the named parts again
    bool any_shape = false;
    for (std::size_t c = 0; c < picture.scene->curve_count(); ++c)
      any_shape = any_shape || is_tour_shape(*picture.scene, c, tp);
    voice_.say(audio_.messages().text(any_shape ? audio::MessageId::tour_all_touched : audio::MessageId::tour_nothing));
    return;
  }
  ask(audio_.messages().text(audio::MessageId::tour_ask), picture.id, -1, {});
}

void TourDesk::offer_part(const TourPicture& picture) {
  const TourPicture::Part& part = picture.parts[parts_offered_++ % picture.parts.size()];
  ask(audio_.messages().text(audio::MessageId::tour_ask_part, {{"name", part.name}}), picture.id,
      static_cast<int>(part.curve), part.name);
}

void TourDesk::ask(const std::string& question, int scene_id, int part_curve, std::string part_name) {
  // Ask first: the pull starts once the visitor has heard what is coming (counted in servo ticks, so the
  // same in a headless run as at the kiosk).
  voice_.say_brief(question);
  asked_ = true;
  scene_ = scene_id;
  part_curve_ = part_curve;
  part_name_ = std::move(part_name);
  due_tick_ = step_.display().tick +
              static_cast<std::int64_t>(
                  std::ceil((audio_.speech_duration_s(question) + kAskMargin_s) * s_.haptics.servo_rate_hz));
}

void TourDesk::hand_over(const TourPicture& picture) {
  asked_ = false;
  if (!picture.scene || scene_ != picture.id) return;  // another picture came meanwhile
  const Vec2 handle_m = step_.display().handle_m;
  const TourParams tp = tour_params_from(s_);
  std::optional<TourPath> plan =
      part_curve_ >= 0 ? plan_tour_to(*picture.scene, picture.id, handle_m, static_cast<std::size_t>(part_curve_), tp)
                       : plan_tour(*picture.scene, picture.id, handle_m, touches_, tp);
  if (!plan) return;  // touched meanwhile: nothing left to lead to
  plan->id = ++seq_;
  running_ = plan->id;
  quiet_ = false;
  cursor_ref_ = cursor_in_;
  spdlog::info("tour {}: to shape {} ({:.1f} s)", plan->id, plan->curve, plan->duration_s());
  devices_.set_limp(true);
  step_.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
}

void TourDesk::poll() {
  const TourPicture picture = this->picture();
  const ServoDisplayState& d = step_.display();
  if (d.scene_id == touches_.scene_id() && d.curve >= 0) {
    touches_.touch(d.scene_id, d.curve);
    if (picture.scene && picture.id == d.scene_id) say_touched_name(picture, d.curve);
  }
  if (asked_ && d.tick >= due_tick_) hand_over(picture);
  if (!running_ || d.tour_id != running_ || !tour_ended(d.tour_phase)) return;
  if (d.tour_phase == TourPhase::Done) touches_.touch(scene_, d.tour_curve);
  running_ = 0;
  // The hand lets go where the tour left the handle (unless the visitor's own hand took over).
  if (devices_.limp()) {
    if (!quiet_ || length(cursor_in_ - cursor_ref_) <= 0.003) cursor_offset_ = d.handle_m - cursor_in_;
    set_cursor(cursor_in_);
    devices_.set_limp(false);
  }
  if (quiet_ || !picture.scene || scene_ != picture.id) return;
  report_end(picture, d);
}

void TourDesk::report_end(const TourPicture& picture, const ServoDisplayState& d) {
  const audio::MessageCatalog& m = audio_.messages();
  std::string text;
  if (d.tour_phase == TourPhase::Stopped) {
    text = m.text(audio::MessageId::tour_stopped) + " ";
  } else if (d.tour_phase == TourPhase::Stuck) {
    spdlog::warn("tour {}: stuck on shape {} (no progress), let go", d.tour_id, d.tour_curve);
    text = m.text(audio::MessageId::tour_stuck) + " ";
  } else if (d.tour_curve >= 0 && static_cast<std::size_t>(d.tour_curve) < picture.described) {
    // A named part is said as it was offered ("the right wing"), not as one of its shapes ("part of ...").
    const bool part = !part_name_.empty() && d.tour_curve == part_curve_;
    text = m.text(audio::MessageId::tour_traced,
                  {{"shape", std::to_string(d.tour_curve + 1)},
                   {"description", part ? part_name_ : picture.words(static_cast<std::size_t>(d.tour_curve))}}) +
           " ";
  }
  const int left = shapes_remaining(*picture.scene, touches_, tour_params_from(s_));
  if (left == 0)
    text += m.text(audio::MessageId::tour_all_touched);
  else
    text += m.text(audio::MessageId::tour_remaining, left);
  voice_.say(text);
}

void TourDesk::say_touched_name(const TourPicture& picture, int curve) {
  if (s_.kiosk.say_names_on_touch != "on" || !picture.name || running() || voice_.speaking()) return;
  if (static_cast<std::size_t>(curve) >= picture.described) return;
  std::string name = picture.name(static_cast<std::size_t>(curve));
  if (name.empty() || std::find(names_said_.begin(), names_said_.end(), name) != names_said_.end()) return;
  names_said_.push_back(name);
  voice_.say_brief(audio_.messages().text(audio::MessageId::touch_name, {{"name", sentence_case(name)}}));
}

void TourDesk::picture_changed(int id, int curves) {
  touches_.reset(id, curves);  // touches are kept per picture
  names_said_.clear();
  parts_offered_ = 0;
  stop_quietly();  // the servo stops a running tour at the swap anyway; nothing to say of it
}

void TourDesk::new_visitor(int id, int curves) {
  picture_changed(id, curves);
  cursor_offset_ = {};
}

}  // namespace hk::app
