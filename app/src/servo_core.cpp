#include "servo_core.hpp"

#include <algorithm>
#include <limits>
#include <cmath>

namespace hk::app {

ServoCore::ServoCore(const CueTrackerParams& cue_params, audio::SpscRing<audio::CueEvent>* cues)
    : tracker_(cue_params), cues_(cues) {}

ServoCore::~ServoCore() {
  delete pending_.exchange(nullptr);
  delete current_;
  delete to_retire_;
  delete tour_pending_.exchange(nullptr);
  delete tour_;
  delete tour_to_retire_;
  collect_retired();
}

void ServoCore::publish(std::unique_ptr<SceneBundle> bundle) {
  delete pending_.exchange(bundle.release(), std::memory_order_acq_rel);
}

int ServoCore::collect_retired() {
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

void ServoCore::publish_tour(std::unique_ptr<TourPath> path) {
  delete tour_pending_.exchange(path.release(), std::memory_order_acq_rel);
}

void ServoCore::end_tour(TourPhase how) noexcept {
  tour_phase_ = how;
  tour_ending_ = TourPhase::None;
  if (tour_ && !tour_retired_.try_push(tour_)) tour_to_retire_ = tour_;  // step() takes no tour while this is set
  tour_ = nullptr;
}

void ServoCore::tour_before_update(const DeviceSample& sample) noexcept {
  if (tour_to_retire_ && tour_retired_.try_push(tour_to_retire_)) tour_to_retire_ = nullptr;
  const bool cancel = tour_cancel_.exchange(false, std::memory_order_acq_rel);
  const bool picture_changing = fading_ || !current_ || (tour_ && current_->id != tour_->scene_id);
  if (tour_ && tour_ending_ == TourPhase::None && (cancel || picture_changing)) {
    tour_ending_ = TourPhase::Stopped;
    tour_fade_left_ = tour_fade_ticks_;
  }
  // A new tour waits while a picture is being swapped in (it may be for the new one), then is taken for
  // the picture in use or dropped.
  if (!tour_ && !tour_to_retire_ && current_ && !fading_) {
    if (TourPath* next = tour_pending_.exchange(nullptr, std::memory_order_acq_rel)) {
      tour_id_ = next->id;
      tour_curve_ = next->curve;
      tour_ = next;
      if (current_->id != next->scene_id || next->points.empty()) {
        end_tour(TourPhase::Stopped);  // for another picture: dropped
      } else {
        const double period = current_->loop.params().period_s;
        tour_phase_ = TourPhase::Transit;
        tour_ending_ = TourPhase::None;
        tour_t_s_ = 0.0;
        tour_cursor_ = 0;
        tour_ticks_ = 0;
        tour_hold_ticks_ = 0;
        tour_fade_ticks_ = std::max(1L, static_cast<long>(next->params.fade_s / period + 0.5));
        tour_fade_left_ = 0;
        tour_prev_handle_ = sample.handle_m;
        tour_prev_target_ = next->points.front().target_m;
        tour_velocity_ = tour_hold_velocity_ = tour_press_ = tour_follow_dir_ = {0.0, 0.0};
        tour_following_ = false;
        tour_trap_ticks_ = 0;
      }
    }
  }
  // Walls suspended in the transit once they have faded out: the proxy goes with the handle. In the
  // outline only the toured shape is a wall: a contact (last tick) with other shapes only, met one tick
  // before at one tick's depth, is let go of, so a neighbouring outline never holds the handle back.
  bool other_walls_only = false;
  if (tour_ && tour_phase_ == TourPhase::Outline && out_.contact.state != ContactState::Free) {
    const int n = out_.contact.state == ContactState::Vertex ? 2 : 1;
    other_walls_only = true;
    for (int i = 0; i < n; ++i) other_walls_only = other_walls_only && out_.contact.constraint[i].curve != tour_->curve;
  }
  if (tour_ && ((tour_phase_ == TourPhase::Transit && tour_ticks_ >= tour_fade_ticks_) || other_walls_only) && is_finite(sample.handle_m))
    current_->loop.relocate(sample.handle_m);
}

// The handle's velocity through two low-passes of its own (the servo loop's 100 Hz one passes the encoder's
// steps: ~38 µm in one tick is 38 mm/s raw): kTourVelocityHz for the damping (tour_velocity_), kHoldVelocityHz
// to tell a handle held still (tour_hold_velocity_).
void ServoCore::track_tour_handle(Vec2 h, double period_s) noexcept {
  const Vec2 raw_v = (1.0 / period_s) * (h - tour_prev_handle_);
  tour_prev_handle_ = h;
  const double a_v = 1.0 - std::exp(-2.0 * M_PI * kTourVelocityHz * period_s);
  const double a_h = 1.0 - std::exp(-2.0 * M_PI * kHoldVelocityHz * period_s);
  tour_velocity_ = tour_velocity_ + a_v * (raw_v - tour_velocity_);
  tour_hold_velocity_ = tour_hold_velocity_ + a_h * (raw_v - tour_hold_velocity_);
}

// The path's point at its clock, its press low-passed (kPressHz) so that contact beginning or ending and the
// polyline's vertices turn it smoothly. The press goes along the wall's inward normal where the handle touches
// the toured shape (so it never pushes along the wall the handle is on, into a corner), else along the path's.
TourPoint ServoCore::tour_point_pressed(double period_s) noexcept {
  TourPoint here = tour_->at(tour_t_s_, tour_cursor_);
  const double press_len = length(here.press_n);
  if (press_len > 0.0 && out_.contact.state != ContactState::Free && out_.contact.constraint[0].curve == tour_->curve) {
    Vec2 a, b;
    current_->scene->segment(out_.contact.constraint[0], &a, &b);
    Vec2 n = left_perp(normalized_or(b - a, {1.0, 0.0}));
    if (dot(out_.contact.proxy_m - a, n) < 0.0) n = -n;  // outward: the proxy's side
    here.press_n = -press_len * n;
  }
  const double a_p = 1.0 - std::exp(-2.0 * M_PI * kPressHz * period_s);
  tour_press_ = tour_press_ + a_p * (here.press_n - tour_press_);
  here.press_n = tour_press_;
  return here;
}

// Caught in a pocket of its own shape? The press keeps the handle on the wall, so it follows the wall into
// every narrow pocket, slot or hook of the rendered polyline, which the planned track, offset from the curve
// at the planning level, passes outside; there the spring's pull points into the wall and the handle stops.
// On the toured shape's wall with the spring at its limit and the handle still for trap_s, the guide follows
// the wall (follow_force) until the handle is within rejoin_m of the target, which waits (the path's clock
// stops while the handle does not keep up). Outline only; a tour ending, or not in its outline, never follows.
void ServoCore::track_trap(Vec2 error_m, bool keeping_up, double period_s) noexcept {
  const TourParams& p = tour_->params;
  if (tour_phase_ != TourPhase::Outline || tour_ending_ != TourPhase::None) {
    tour_following_ = false;
    tour_trap_ticks_ = 0;
    return;
  }
  const bool on_shape = out_.contact.state != ContactState::Free && out_.contact.constraint[0].curve == tour_->curve;
  if (tour_following_) {  // back to the spring near the target, or off the wall (round a tip: the spring leads on)
    if (length(error_m) < p.rejoin_m || !on_shape) tour_following_ = false;
    return;
  }
  const bool still = length(tour_hold_velocity_) < p.hold_speed_m_per_s;
  tour_trap_ticks_ = on_shape && !keeping_up && still ? tour_trap_ticks_ + 1 : 0;
  if (static_cast<double>(tour_trap_ticks_) * period_s >= p.trap_s) {
    tour_following_ = true;
    tour_trap_ticks_ = 0;
  }
}

// The guide while following the wall: the press plus follow_force_n along the toured shape's wall the proxy is
// on, in the outline's direction (TourPath::direction along the segment's own end points, which every level
// orders alike); at a vertex the wall that leads away from the proxy (a zero-length wall keeps the last
// direction). Called only while following, so on the toured shape's wall. Never above max_force_n.
Vec2 ServoCore::follow_force(Vec2 press_n) noexcept {
  const TourParams& p = tour_->params;
  const ContactOutput& c = out_.contact;
  const int walls = c.state == ContactState::Vertex ? 2 : (c.state == ContactState::Edge ? 1 : 0);
  double best_lead = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < walls; ++i) {
    if (c.constraint[i].curve != tour_->curve) continue;
    Vec2 a, b;
    current_->scene->segment(c.constraint[i], &a, &b);
    const Vec2 t = static_cast<double>(tour_->direction) * normalized_or(b - a, tour_follow_dir_);
    const double lead = dot(t, 0.5 * (a + b) - c.proxy_m);  // > 0: the wall goes on ahead of the proxy
    if (lead > best_lead) {
      best_lead = lead;
      tour_follow_dir_ = t;
    }
  }
  Vec2 f = press_n + p.follow_force_n * tour_follow_dir_;
  const double len = length(f);
  if (len > p.max_force_n) f = (p.max_force_n / len) * f;
  return f;
}

// The tour's progress on a tick that rendered: held still against it (the force at its limit, or the path's
// clock stopped because the handle does not keep up, while the handle barely moves) for hold_s stops it; the
// path's clock runs while the handle keeps up (within the spring's saturation distance); the outline begins
// (the TourStart earcon) and the path ends (Done) at their times. `keeping_up`: the spring's pull plus the
// press is below max_force_n; `guide_len_n` the guide force's length before the fades.
void ServoCore::advance_tour(bool keeping_up, double guide_len_n, double period_s) noexcept {
  const TourParams& p = tour_->params;
  const bool held = (guide_len_n >= 0.95 * p.max_force_n || !keeping_up || tour_following_) && length(tour_hold_velocity_) < p.hold_speed_m_per_s;
  tour_hold_ticks_ = held ? tour_hold_ticks_ + 1 : 0;
  if (static_cast<double>(tour_hold_ticks_) * period_s >= p.hold_s) {
    tour_ending_ = TourPhase::Stopped;
    tour_fade_left_ = tour_fade_ticks_;
  }
  if (tour_ending_ == TourPhase::None && keeping_up) tour_t_s_ += period_s;
  if (tour_phase_ == TourPhase::Transit && tour_t_s_ >= tour_->outline_start_s) {
    tour_phase_ = TourPhase::Outline;
    if (cues_) {
      audio::CueEvent c;
      c.tick = tick_;
      c.kind = audio::CueKind::TourStart;
      c.curve = tour_->curve;
      c.speed_m_per_s = static_cast<float>(p.speed_m_per_s);
      c.level = static_cast<std::int16_t>(out_.level);
      cues_->try_push(c);  // a full ring drops and counts
    }
  }
  if (tour_ending_ == TourPhase::None && tour_t_s_ >= tour_->duration_s()) {
    tour_ending_ = TourPhase::Done;
    tour_fade_left_ = tour_fade_ticks_;
  }
}

void ServoCore::tour_after_update(const DeviceSample& sample) noexcept {
  guide_force_ = {0.0, 0.0};
  if (!tour_) return;
  if (out_.result == TickResult::DeviceNotOk || out_.result == TickResult::NonFinite) {
    end_tour(TourPhase::Stopped);  // no force goes out anyway; the tour does not resume on its own
    return;
  }
  const TourParams& p = tour_->params;
  const double period = current_->loop.params().period_s;
  const Vec2 h = sample.handle_m;
  track_tour_handle(h, period);
  const TourPoint here = tour_point_pressed(period);
  const Vec2 target_v = (1.0 / period) * (here.target_m - tour_prev_target_);
  tour_prev_target_ = here.target_m;
  const Vec2 e = here.target_m - h;
  // A spring to the target, damping of the velocity relative to the target's (PD tracking) and the press
  // towards the wall.
  Vec2 f = p.stiffness_n_per_m * e + p.damping_n_s_per_m * (target_v - tour_velocity_) + here.press_n;
  double f_len = length(f);
  if (f_len > p.max_force_n) f = (p.max_force_n / f_len) * f;
  // The handle keeps up while the spring's pull and the press stay under the limit (the clock runs).
  const bool keeping_up = length(p.stiffness_n_per_m * e + here.press_n) < p.max_force_n;
  track_trap(e, keeping_up, period);
  if (tour_following_) {  // out of a pocket along its wall, then back to the spring
    f = follow_force(here.press_n);
    f_len = length(f);
  }
  double gain = std::min(1.0, static_cast<double>(tour_ticks_ + 1) / static_cast<double>(tour_fade_ticks_));  // fade in
  // The walls: faded out over the first fade_s of the transit, then off (relocate); on from the outline.
  if (tour_phase_ == TourPhase::Transit)
    out_.force_n = std::max(0.0, 1.0 - static_cast<double>(tour_ticks_ + 1) / static_cast<double>(tour_fade_ticks_)) * out_.force_n;
  if (tour_ending_ == TourPhase::None && out_.result == TickResult::Ok) advance_tour(keeping_up, f_len, period);
  if (tour_ending_ != TourPhase::None) {  // fading out (Done or Stopped)
    --tour_fade_left_;
    gain *= std::max(0.0, static_cast<double>(tour_fade_left_) / static_cast<double>(tour_fade_ticks_));
  }
  if (out_.result == TickResult::Ok) guide_force_ = gain * f;  // a late tick (DeadlineMissed) sends nothing
  ++tour_ticks_;
  if (tour_ending_ != TourPhase::None && tour_fade_left_ <= 0) end_tour(tour_ending_);
}

void ServoCore::set_gains(const ServoGains& g) noexcept {
  GainsSlot& slot = gains_in_.back();
  slot.gains = g;
  slot.seq = ++gains_written_;
  gains_in_.publish();
}

// The phases of step, in order. Each reads and writes the core's own state; none allocates, locks or throws.

// New gains (set_gains): kept for every picture taken from now on, applied in apply_requests to the one in use.
void ServoCore::take_gains() noexcept {
  const GainsSlot& g = gains_in_.read();
  if (g.seq != gains_.seq) gains_ = g;
}

// A new picture waits while the old one's force fades out over the force ramp time (a wall must not vanish
// under a pressing hand in one tick); then it is taken and started at the handle (proxy there, force ramped
// in from zero by the guard), and the old one is retired. A bundle that found no room in the ring last
// time is handed back first.
void ServoCore::swap_scene(Vec2 handle_m) noexcept {
  if (to_retire_ && retired_.try_push(to_retire_)) to_retire_ = nullptr;
  if (!fading_ && current_ && pending_.load(std::memory_order_acquire) != nullptr) {
    const ServoParams& p = current_->loop.params();
    fade_total_ = p.guard.ramp_s > 0.0 ? static_cast<long>(p.guard.ramp_s / p.period_s + 0.5) : 0;
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
void ServoCore::apply_requests(const DeviceSample& sample, bool device_returned) noexcept {
  const int want_level = requested_level_.exchange(-1, std::memory_order_relaxed);
  if (!current_) return;
  if (want_level == kAutoLevel) current_->loop.set_auto_level(true);
  if (want_level >= 0) current_->loop.set_level(want_level);
  if (gains_.seq != 0) current_->loop.set_gains(gains_.gains);  // no-op unless they changed
  if (device_returned && is_finite(sample.handle_m)) current_->loop.start(sample.handle_m);
}

// The walls' force: the servo loop's step on the picture in use (none: no force, the proxy at the handle),
// scaled down while the picture fades out before a swap.
TickResult ServoCore::render_walls(ServoInput& in) noexcept {
  TickResult r = TickResult::Ok;
  if (current_) {
    in.press_counts = !fading_;  // a hand sinking into a fading wall is not pushing through it
    r = current_->loop.update(in, out_);
  } else {
    out_ = ServoOutput{};
    out_.contact.proxy_m = in.sample.handle_m;
  }
  if (fading_ && fade_total_ > 0) out_.force_n = (static_cast<double>(fade_left_) / static_cast<double>(fade_total_)) * out_.force_n;
  return r;
}

// Walls plus the tour's guide force, never above the guard's clamp.
void ServoCore::add_guide_force() noexcept {
  if (guide_force_.x == 0.0 && guide_force_.y == 0.0) return;
  const double max_n = current_->loop.params().guard.max_force_n;
  Vec2 total = out_.force_n + guide_force_;
  const double len = length(total);
  if (len > max_n) total = (max_n / len) * total;
  out_.force_n = total;
}

// The tick's earcons (CueTracker) into the audio ring; a full ring drops and counts.
void ServoCore::emit_cues(Vec2 handle_m) noexcept {
  if (!current_) return;
  audio::CueEvent c[CueTracker::kMaxCuesPerTick];
  const int n = tracker_.update(tick_, out_, handle_m, out_.level, c);
  for (int i = 0; cues_ && i < n; ++i) cues_->try_push(c[i]);
}

// What the display thread shows, into the display slot's back buffer (published by the caller).
void ServoCore::write_display(const DeviceSample& sample) noexcept {
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

TickResult ServoCore::step(const DeviceSample& sample, bool deadline_missed, ServoCommand& cmd) noexcept {
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
