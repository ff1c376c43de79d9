// The guided tour's force law (tour_guide.hpp): the spring, damper and press that lead the handle along a
// planned path, the pocket-following, and the tour's clock and ending.
#include "haptics/tour_guide.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hk {

TourPoint TourPath::at(double t_s, std::size_t& cursor) const noexcept {
  const std::size_t n = points.size();
  if (n == 1 || t_s <= points.front().t_s) return points.front();
  if (t_s >= points.back().t_s) {
    cursor = n - 1;
    return points.back();
  }
  if (cursor >= n - 1) cursor = 0;
  while (cursor + 1 < n - 1 && points[cursor + 1].t_s <= t_s) ++cursor;
  const TourPoint& a = points[cursor];
  const TourPoint& b = points[cursor + 1];
  const double span = b.t_s - a.t_s;
  const double f = span > 0.0 ? (t_s - a.t_s) / span : 1.0;
  return {t_s, lerp(a.target_m, b.target_m, f), lerp(a.press_n, b.press_n, f)};
}

void TourGuide::start(const TourPath& path, Vec2 handle_m, double period_s) noexcept {
  path_ = &path;
  phase_ = TourPhase::Transit;
  ending_ = TourPhase::None;
  t_s_ = 0.0;
  cursor_ = 0;
  ticks_ = 0;
  hold_ticks_ = 0;
  fade_ticks_ = std::max(1L, static_cast<long>(path.params.fade_s / period_s + 0.5));
  stall_ticks_ = std::max(1L, static_cast<long>(path.params.stall_s / period_s + 0.5));
  progress_tick_ = 0;
  rendered_ticks_ = 0;
  progress_t_s_ = 0.0;
  progress_error_m_ = std::numeric_limits<double>::infinity();
  overrun_ticks_ =
      std::max(stall_ticks_, static_cast<long>(path.params.overrun_factor * path.duration_s() / period_s + 0.5));
  fade_left_ = 0;
  prev_handle_ = handle_m;
  prev_target_ = path.points.front().target_m;
  velocity_ = hold_velocity_ = press_ = follow_dir_ = {0.0, 0.0};
  following_ = false;
  trap_ticks_ = 0;
}

void TourGuide::stop() noexcept {
  if (!path_ || ending_ != TourPhase::None) return;
  end(TourPhase::Stopped);
}

void TourGuide::end(TourPhase how) noexcept {
  ending_ = how;
  fade_left_ = fade_ticks_;
}

// No progress: in the last stall_s of ticks that rendered (a late tick moves no clock), the clock gained less
// than progress_min_s and the handle came no nearer its waiting target by progress_min_m (a handle led out of a
// pocket along the wall, the clock stopped, is progress); or the tour has run overrun_factor times its planned
// duration in ticks of any kind.
bool TourGuide::stalled(double error_m) noexcept {
  const TourParams& p = path_->params;
  if (t_s_ - progress_t_s_ >= p.progress_min_s || error_m <= progress_error_m_ - p.progress_min_m) {
    progress_t_s_ = t_s_;
    progress_error_m_ = error_m;
    progress_tick_ = rendered_ticks_;
  }
  return rendered_ticks_ - progress_tick_ >= stall_ticks_ || ticks_ >= overrun_ticks_;
}

bool TourGuide::on_toured_wall(const ContactOutput& c) const noexcept {
  return c.state != ContactState::Free && c.constraint[0].curve == path_->curve;
}

bool TourGuide::walls_suspended(const ContactOutput& last) const noexcept {
  if (!path_) return false;
  if (phase_ == TourPhase::Transit) return ticks_ >= fade_ticks_;
  if (phase_ != TourPhase::Outline || last.state == ContactState::Free) return false;
  const int n = last.state == ContactState::Vertex ? 2 : 1;
  for (int i = 0; i < n; ++i) {
    if (last.constraint[i].curve == path_->curve) return false;
  }
  return true;  // other shapes only, met one tick before at one tick's depth: let go of
}

// The handle's velocity through two low-passes of its own (the servo loop's 100 Hz one passes the encoder's
// steps: ~38 µm in one tick is 38 mm/s raw): kVelocityHz for the damping (velocity_), kHoldHz to tell a
// handle held still (hold_velocity_).
void TourGuide::track_handle(Vec2 h, double period_s) noexcept {
  const Vec2 raw_v = (1.0 / period_s) * (h - prev_handle_);
  prev_handle_ = h;
  const double a_v = 1.0 - std::exp(-2.0 * M_PI * kVelocityHz * period_s);
  const double a_h = 1.0 - std::exp(-2.0 * M_PI * kHoldHz * period_s);
  velocity_ = velocity_ + a_v * (raw_v - velocity_);
  hold_velocity_ = hold_velocity_ + a_h * (raw_v - hold_velocity_);
}

// The path's point at its clock, its press low-passed (kPressHz) so that contact beginning or ending and the
// polyline's vertices turn it smoothly. The press goes along the wall's inward normal where the handle touches
// the toured shape (so it never pushes along the wall the handle is on, into a corner), else along the path's.
TourPoint TourGuide::point_pressed(const TourInput& in) noexcept {
  TourPoint here = path_->at(t_s_, cursor_);
  const double press_len = length(here.press_n);
  const ContactOutput& c = *in.contact;
  if (press_len > 0.0 && on_toured_wall(c)) {
    Vec2 a, b;
    in.scene->segment(c.constraint[0], &a, &b);
    Vec2 n = left_perp(normalized_or(b - a, {1.0, 0.0}));
    if (dot(c.proxy_m - a, n) < 0.0) n = -n;  // outward: the proxy's side
    here.press_n = -press_len * n;
  }
  const double a_p = 1.0 - std::exp(-2.0 * M_PI * kPressHz * in.period_s);
  press_ = press_ + a_p * (here.press_n - press_);
  here.press_n = press_;
  return here;
}

// Caught in a pocket of its own shape? The press keeps the handle on the wall, so it follows the wall into
// every narrow pocket, slot or hook of the rendered polyline, which the planned track, offset from the curve
// at the planning level, passes outside; there the spring's pull points into the wall and the handle stops.
// On the toured shape's wall with the spring at its limit and the handle still for trap_s, the guide follows
// the wall (follow_force) until the handle is within rejoin_m of the target, which waits (the path's clock
// stops while the handle does not keep up). Outline only; a tour ending, or not in its outline, never follows.
void TourGuide::track_trap(const TourInput& in, Vec2 error_m, bool keeping_up) noexcept {
  const TourParams& p = path_->params;
  if (phase_ != TourPhase::Outline || ending_ != TourPhase::None) {
    following_ = false;
    trap_ticks_ = 0;
    return;
  }
  const bool on_shape = on_toured_wall(*in.contact);
  if (following_) {  // back to the spring near the target, or off the wall (round a tip: the spring leads on)
    if (length(error_m) < p.rejoin_m || !on_shape) following_ = false;
    return;
  }
  const bool still = length(hold_velocity_) < p.hold_speed_m_per_s;
  trap_ticks_ = on_shape && !keeping_up && still ? trap_ticks_ + 1 : 0;
  if (static_cast<double>(trap_ticks_) * in.period_s >= p.trap_s) {
    following_ = true;
    trap_ticks_ = 0;
  }
}

// The guide while following the wall: the press plus follow_force_n along the toured shape's wall the proxy is
// on, in the outline's direction (TourPath::direction along the segment's own end points, which every level
// orders alike); at a vertex the wall that leads away from the proxy (a zero-length wall keeps the last
// direction). Called only while following, so on the toured shape's wall. Never above max_force_n.
Vec2 TourGuide::follow_force(const TourInput& in, Vec2 press_n) noexcept {
  const TourParams& p = path_->params;
  const ContactOutput& c = *in.contact;
  const int walls = c.state == ContactState::Vertex ? 2 : (c.state == ContactState::Edge ? 1 : 0);
  double best_lead = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < walls; ++i) {
    if (c.constraint[i].curve != path_->curve) continue;
    Vec2 a, b;
    in.scene->segment(c.constraint[i], &a, &b);
    const Vec2 t = static_cast<double>(path_->direction) * normalized_or(b - a, follow_dir_);
    const double lead = dot(t, 0.5 * (a + b) - c.proxy_m);  // > 0: the wall goes on ahead of the proxy
    if (lead > best_lead) {
      best_lead = lead;
      follow_dir_ = t;
    }
  }
  Vec2 f = press_n + p.follow_force_n * follow_dir_;
  const double len = length(f);
  if (len > p.max_force_n) f = (p.max_force_n / len) * f;
  return f;
}

// The tour's progress on a tick that rendered: held still against it (the force at its limit, or the path's
// clock stopped because the handle does not keep up, while the handle barely moves) for hold_s stops it; the
// path's clock runs while the handle keeps up (within the spring's saturation distance); the outline begins
// (out.outline_began) and the path ends (Done) at their times. `keeping_up`: the spring's pull plus the press
// is below max_force_n; `guide_len_n` the guide force's length before the fades.
void TourGuide::advance(bool keeping_up, double guide_len_n, double period_s, TourOutput& out) noexcept {
  const TourParams& p = path_->params;
  const bool held = (guide_len_n >= 0.95 * p.max_force_n || !keeping_up || following_) &&
                    length(hold_velocity_) < p.hold_speed_m_per_s;
  hold_ticks_ = held ? hold_ticks_ + 1 : 0;
  if (static_cast<double>(hold_ticks_) * period_s >= p.hold_s) end(TourPhase::Stopped);
  if (ending_ == TourPhase::None && keeping_up) t_s_ += period_s;
  if (phase_ == TourPhase::Transit && t_s_ >= path_->outline_start_s) {
    phase_ = TourPhase::Outline;
    out.outline_began = true;
  }
  if (ending_ == TourPhase::None && t_s_ >= path_->duration_s()) end(TourPhase::Done);
}

void TourGuide::update(const TourInput& in, TourOutput& out) noexcept {
  out = TourOutput{};
  const TourParams& p = path_->params;
  const Vec2 h = in.handle_m;
  track_handle(h, in.period_s);
  const TourPoint here = point_pressed(in);
  const Vec2 target_v = (1.0 / in.period_s) * (here.target_m - prev_target_);
  prev_target_ = here.target_m;
  const Vec2 e = here.target_m - h;
  // A spring to the target, damping of the velocity relative to the target's (PD tracking) and the press
  // towards the wall.
  Vec2 f = p.stiffness_n_per_m * e + p.damping_n_s_per_m * (target_v - velocity_) + here.press_n;
  double f_len = length(f);
  if (f_len > p.max_force_n) f = (p.max_force_n / f_len) * f;
  // The handle keeps up while the spring's pull and the press stay under the limit (the clock runs).
  const bool keeping_up = length(p.stiffness_n_per_m * e + here.press_n) < p.max_force_n;
  track_trap(in, e, keeping_up);
  if (following_) {  // out of a pocket along its wall, then back to the spring
    f = follow_force(in, here.press_n);
    f_len = length(f);
  }
  double gain = std::min(1.0, static_cast<double>(ticks_ + 1) / static_cast<double>(fade_ticks_));  // fade in
  // The walls: faded out over the first fade_s of the transit, then off (walls_suspended); on from the outline.
  if (phase_ == TourPhase::Transit)
    out.walls_gain = std::max(0.0, 1.0 - static_cast<double>(ticks_ + 1) / static_cast<double>(fade_ticks_));
  if (ending_ == TourPhase::None && in.walls_result == TickResult::Ok) {
    advance(keeping_up, f_len, in.period_s, out);
    rendered_ticks_ += 1;
  }
  if (ending_ == TourPhase::None && stalled(length(e))) end(TourPhase::Stuck);
  if (ending_ != TourPhase::None) {  // fading out (Done or Stopped)
    --fade_left_;
    gain *= std::max(0.0, static_cast<double>(fade_left_) / static_cast<double>(fade_ticks_));
  }
  if (in.walls_result == TickResult::Ok) out.guide_force_n = gain * f;  // a late tick (DeadlineMissed) sends nothing
  ++ticks_;
  if (ending_ != TourPhase::None && fade_left_ <= 0) {
    out.ended = ending_;
    phase_ = ending_;
    path_ = nullptr;
  }
}

}  // namespace hk
