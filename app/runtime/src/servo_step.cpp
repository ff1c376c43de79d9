#include "runtime/servo_step.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hk::app {

ServoStep::ServoStep(const CueTrackerParams& cue_params, audio::SpscRing<audio::CueEvent>* cues)
    : tracker_(cue_params), cues_(cues) {}

ServoStep::~ServoStep() {
  delete pending_.exchange(nullptr);
  delete current_;
  delete to_retire_;
  delete tour_pending_.exchange(nullptr);
  delete tour_;
  delete tour_to_retire_;
  collect_retired();
}

void ServoStep::publish(std::unique_ptr<SceneBundle> bundle) {
  delete pending_.exchange(bundle.release(), std::memory_order_acq_rel);
}

int ServoStep::collect_retired() {
  int n = 0;
  SceneBundle* b = nullptr;
  while (retired_.try_pop(b)) {
    delete b;
    ++n;
  }
  TourPath* t = nullptr;
  while (tour_retired_.try_pop(t)) delete t;
  return n;
}

void ServoStep::publish_tour(std::unique_ptr<TourPath> path) {
  delete tour_pending_.exchange(path.release(), std::memory_order_acq_rel);
}

void ServoStep::end_tour(TourPhase how) noexcept {
  tour_phase_ = how;
  guide_.abandon();
  if (tour_ && !tour_retired_.try_push(tour_)) tour_to_retire_ = tour_;  // step() takes no tour while this is set
  tour_ = nullptr;
}

// A new tour waits while a picture is being swapped in (it may be for the new one), then is taken for the
// picture in use or dropped (Stopped).
void ServoStep::take_tour(const DeviceSample& sample) noexcept {
  if (tour_ || tour_to_retire_ || !current_ || fading_) return;
  TourPath* next = tour_pending_.exchange(nullptr, std::memory_order_acq_rel);
  if (!next) return;
  tour_id_ = next->id;
  tour_curve_ = next->curve;
  tour_ = next;
  if (current_->id != next->scene_id || next->points.empty()) {
    end_tour(TourPhase::Stopped);  // for another picture: dropped
    return;
  }
  guide_.start(*next, sample.handle_m, current_->loop.params().period_s);
  tour_phase_ = TourPhase::Transit;
}

// Before the walls' step: a cancel or a picture changing ends the tour (its force fades out); a pending tour
// is taken; and where the guide suspends the walls the proxy goes with the handle (TourGuide::walls_suspended).
void ServoStep::tour_before_update(const DeviceSample& sample) noexcept {
  if (tour_to_retire_ && tour_retired_.try_push(tour_to_retire_)) tour_to_retire_ = nullptr;
  const bool cancel = tour_cancel_.exchange(false, std::memory_order_acq_rel);
  const bool picture_changing = fading_ || !current_ || (tour_ && current_->id != tour_->scene_id);
  if (tour_ && (cancel || picture_changing)) guide_.stop();
  take_tour(sample);
  if (tour_ && guide_.walls_suspended(out_.contact) && is_finite(sample.handle_m))
    current_->loop.relocate(sample.handle_m);
}

// After the walls' step: the guide force of the tick (TourGuide::update), the walls faded in the transit,
// the TourStart earcon where the outline begins, and the tour let go of once its force has faded out. A
// device not Ok or a sample not finite ends it at once (no force goes out anyway; it does not resume).
void ServoStep::tour_after_update(const DeviceSample& sample) noexcept {
  guide_force_ = {0.0, 0.0};
  if (!tour_) return;
  if (out_.result == TickResult::DeviceNotOk || out_.result == TickResult::NonFinite) {
    end_tour(TourPhase::Stopped);
    return;
  }
  TourInput in;
  in.handle_m = sample.handle_m;
  in.contact = &out_.contact;
  in.scene = current_->scene.get();
  in.walls_result = out_.result;
  in.period_s = current_->loop.params().period_s;
  TourOutput to;
  guide_.update(in, to);
  out_.force_n = to.walls_gain * out_.force_n;
  guide_force_ = to.guide_force_n;
  if (to.outline_began) {
    tour_phase_ = TourPhase::Outline;
    if (cues_) {
      audio::CueEvent c;
      c.tick = tick_;
      c.kind = audio::CueKind::TourStart;
      c.curve = tour_->curve;
      c.speed_m_per_s = static_cast<float>(tour_->params.speed_m_per_s);
      c.level = static_cast<std::int16_t>(out_.level);
      cues_->try_push(c);  // a full ring drops and counts
    }
  }
  if (to.ended != TourPhase::None) end_tour(to.ended);
}

void ServoStep::set_gains(const ServoGains& g) noexcept {
  GainsSlot& slot = gains_in_.back();
  slot.gains = g;
  slot.seq = ++gains_written_;
  gains_in_.publish();
}

// The phases of step, in order. Each reads and writes the core's own state; none allocates, locks or throws.

// New gains (set_gains): kept for every picture taken from now on, applied in apply_requests to the one in use.
void ServoStep::take_gains() noexcept {
  const GainsSlot& g = gains_in_.read();
  if (g.seq != gains_.seq) gains_ = g;
}

// A new picture waits while the old one's force fades out (a wall must not vanish under a pressing hand in
// one tick); then it is taken and started at the handle (proxy there, force ramped in from zero by the
// guard), and the old one is retired. The fade takes the share of the force ramp time that the force in use
// is of the clamp, so no step is larger than the ramp's (max_force_n · period / ramp_s): a hand in free
// space (no force) gets the new picture at the next tick, a hand pressing at the clamp waits the whole ramp.
// A bundle that found no room in the ring last time is handed back first.
void ServoStep::swap_scene(Vec2 handle_m) noexcept {
  if (to_retire_ && retired_.try_push(to_retire_)) to_retire_ = nullptr;
  if (!fading_ && current_ && pending_.load(std::memory_order_acquire) != nullptr) {
    const ServoParams& p = current_->loop.params();
    const double ramp_ticks = p.guard.ramp_s > 0.0 ? p.guard.ramp_s / p.period_s : 0.0;
    const double share = p.guard.max_force_n > 0.0 ? std::min(1.0, length(out_.force_n) / p.guard.max_force_n) : 1.0;
    fade_total_ = static_cast<long>(std::ceil(share * ramp_ticks));
    fade_step_n_ = ramp_ticks > 0.0 ? p.guard.max_force_n / ramp_ticks : 0.0;
    fade_left_ = fade_total_;
    fading_ = fade_total_ > 0;
  }
  if (fading_ && fade_left_ > 0) --fade_left_;
  if (to_retire_ || (fading_ && fade_left_ != 0)) return;
  SceneBundle* next = pending_.exchange(nullptr, std::memory_order_acq_rel);
  if (!next) return;
  fading_ = false;
  if (current_ && !retired_.try_push(current_)) to_retire_ = current_;
  current_ = next;
  if (gains_.seq != 0) current_->loop.set_gains(gains_.gains);  // before start: no fade, the ramp brings it in
  current_->loop.start(handle_m);
  tracker_.reset();
  tracker_.set_text_blocks(current_->text_blocks_m.data(), static_cast<int>(current_->text_blocks_m.size()));
}

// The owner's requests for the picture in use: a level (or levels from hand speed), the gains taken, and a
// device back after Lost/Fault/Closed, which starts the picture again at the handle (force ramped in).
void ServoStep::apply_requests(const DeviceSample& sample, bool device_returned) noexcept {
  const int want_level = requested_level_.exchange(-1, std::memory_order_relaxed);
  if (!current_) return;
  if (want_level == kAutoLevel) current_->loop.set_auto_level(true);
  if (want_level >= 0) current_->loop.set_level(want_level);
  if (gains_.seq != 0) current_->loop.set_gains(gains_.gains);  // no-op unless they changed
  if (device_returned && is_finite(sample.handle_m)) current_->loop.start(sample.handle_m);
}

// The walls' force: the servo loop's step on the picture in use (none: no force, the proxy at the handle),
// scaled down while the picture fades out before a swap.
TickResult ServoStep::render_walls(ServoInput& in) noexcept {
  TickResult r = TickResult::Ok;
  if (current_) {
    in.press_counts = !fading_;  // a hand sinking into a fading wall is not pushing through it
    r = current_->loop.update(in, out_);
  } else {
    out_ = ServoOutput{};
    out_.contact.proxy_m = in.sample.handle_m;
  }
  if (fading_ && fade_total_ > 0) {  // at most fade_left_ ramp steps of force left: down one step a tick
    const double cap_n = static_cast<double>(fade_left_) * fade_step_n_, f_n = length(out_.force_n);
    if (f_n > cap_n) out_.force_n = (cap_n / f_n) * out_.force_n;
  }
  return r;
}

// Walls plus the tour's guide force, never above the guard's clamp.
void ServoStep::add_guide_force() noexcept {
  if (guide_force_.x == 0.0 && guide_force_.y == 0.0) return;
  const double max_n = current_->loop.params().guard.max_force_n;
  Vec2 total = out_.force_n + guide_force_;
  const double len = length(total);
  if (len > max_n) total = (max_n / len) * total;
  out_.force_n = total;
}

// The tick's earcons (CueTracker) into the audio ring; a full ring drops and counts.
void ServoStep::emit_cues(Vec2 handle_m) noexcept {
  if (!current_) return;
  audio::CueEvent c[CueTracker::kMaxCuesPerTick];
  const int n = tracker_.update(tick_, out_, handle_m, out_.level, c);
  for (int i = 0; cues_ && i < n; ++i) cues_->try_push(c[i]);
}

// What the display thread shows, into the display slot's back buffer (published by the caller).
void ServoStep::write_display(const DeviceSample& sample) noexcept {
  ServoDisplayState& d = display_.back();
  d.tick = tick_;
  d.handle_m = sample.handle_m;
  d.proxy_m = out_.contact.proxy_m;
  d.force_n = out_.force_n;
  d.state = out_.contact.state;
  d.curve = out_.contact.state == ContactState::Free ? -1 : out_.contact.constraint[0].curve;
  d.level = current_ ? current_->loop.level() : 0;
  d.auto_level = current_ && current_->loop.params().auto_level;
  d.scene_id = current_ ? current_->id : -1;
  d.device_status = sample.status;
  d.penetration_m = out_.contact.state == ContactState::Free ? 0.0 : length(sample.handle_m - out_.contact.proxy_m);
  d.stiffness_n_per_m = current_ ? current_->loop.gains().stiffness_n_per_m : 0.0;
  d.gains_transition = current_ && current_->loop.transition_active();
  d.tour_phase = tour_phase_;
  d.tour_id = tour_id_;
  d.tour_curve = tour_curve_;
  d.guide_force_n = guide_force_;
  d.section_count = 0;
  if (current_) {
    const auto& sec = current_->loop.section().section();
    d.section_count = static_cast<std::int32_t>(sec.size());
    const std::size_t n = std::min<std::size_t>(sec.size(), ServoDisplayState::kMaxSection);
    std::copy_n(sec.data(), n, d.section);
  }
}

TickResult ServoStep::step(const DeviceSample& sample, bool deadline_missed, ServoCommand& cmd) noexcept {
  ServoInput in;
  in.sample = sample;
  in.deadline_missed = deadline_missed;
  const bool device_returned = sample.status == DeviceStatus::Ok && last_status_ != DeviceStatus::Ok;
  last_status_ = sample.status;

  take_gains();
  swap_scene(sample.handle_m);
  apply_requests(sample, device_returned);
  tour_before_update(sample);
  const TickResult r = render_walls(in);
  tour_after_update(sample);
  add_guide_force();
  cmd.force_n = out_.force_n;
  emit_cues(sample.handle_m);
  write_display(sample);
  ++tick_;
  return r;
}

}  // namespace hk::app
