// The visitor-like model hand (`--hand explorer`, issue 14 item 4): sweep, trace, push through.
#include "haptics/explorer_hand.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hk {
namespace {

void require(bool ok, const char* field, const std::string& limit, double value) {
  if (!ok || !std::isfinite(value)) {
    throw std::invalid_argument(std::string("explorer hand: ") + field + " = " + std::to_string(value) + " is outside " + limit);
  }
}

constexpr double kMarginM = 0.003;        // raster lines stay this far inside the workspace edge [m]
constexpr double kWaypointReachM = 0.0015; // a waypoint is reached within this [m]
// Push with this times pop_force_n: over the wall's give-way force, but under the force a wall is clamped at
// (3.5 N against the 3 N default), so the handle stops a few mm in and the press is held, not lost.
constexpr double kPopFactor = 1.1;
constexpr double kPopExtraS = 0.15;        // push for pop_hold_s plus this
constexpr double kTurnRadiusM = 0.002;    // a trace that lost its wall turns towards it on this radius [m]
constexpr long kPopTriesBeforeGivingUp = 3;  // pushes that all failed before the hand stops pushing
constexpr double kBypassLineM = 0.0015;   // a bypass ends back within this of the sweep line [m]
constexpr double kBypassGainM = 0.003;    // ... at least this much closer to the waypoint than where it began [m]
constexpr double kReleaseIgnoreS = 0.06;   // after a push-through, forces are not walls for this long [s]

}  // namespace

void ExplorerParams::validate() const {
  require(workspace_width_m > 0 && workspace_width_m <= 1, "workspace_width_m", "(0, 1] m", workspace_width_m);
  require(workspace_height_m > 0 && workspace_height_m <= 1, "workspace_height_m", "(0, 1] m", workspace_height_m);
  require(sweep_spacing_m > 0 && sweep_spacing_m <= std::min(workspace_width_m, workspace_height_m), "sweep_spacing_m",
          "(0, the smaller workspace side] m", sweep_spacing_m);
  require(sweep_speed_m_per_s > 0 && sweep_speed_m_per_s <= 5, "sweep_speed_m_per_s", "(0, 5] m/s", sweep_speed_m_per_s);
  require(trace_speed_m_per_s > 0 && trace_speed_m_per_s <= 5, "trace_speed_m_per_s", "(0, 5] m/s", trace_speed_m_per_s);
  require(contact_force_n > 0 && contact_force_n <= 50, "contact_force_n", "(0, 50] N", contact_force_n);
  require(max_force_n > 0 && max_force_n <= 50, "max_force_n", "(0, 50] N", max_force_n);
  require(press_force_n > 0 && press_force_n < max_force_n, "press_force_n", "(0, max_force_n) N", press_force_n);
  require(pop_force_n == 0 || pop_force_n > press_force_n, "pop_force_n", "0 or (press_force_n, 20] N", pop_force_n);
  require(pop_force_n <= 20, "pop_force_n", "0 or (press_force_n, 20] N", pop_force_n);
  require(hand_stiffness_n_per_m > 0 && hand_stiffness_n_per_m <= 1e5, "hand_stiffness_n_per_m", "(0, 100000] N/m",
          hand_stiffness_n_per_m);
  require(pop_hold_s > 0 && pop_hold_s <= 10, "pop_hold_s", "(0, 10] s", pop_hold_s);
  require(duration_s > 0 && duration_s <= 86400, "duration_s", "(0, 86400] s", duration_s);
  require(cell_m >= 0.0002 && cell_m <= 0.05, "cell_m", "[0.0002, 0.05] m", cell_m);
  require(carrot_lead_m > 0 && carrot_lead_m <= 0.1, "carrot_lead_m", "(0, 0.1] m", carrot_lead_m);
  require(loop_close_m > 0 && loop_close_m <= 0.05, "loop_close_m", "(0, 0.05] m", loop_close_m);
  require(loop_min_m > loop_close_m && loop_min_m <= 1, "loop_min_m", "(loop_close_m, 1] m", loop_min_m);
  require(trace_max_s > 0 && trace_max_s <= 86400, "trace_max_s", "(0, 86400] s", trace_max_s);
  require(lost_s > 0 && lost_s <= 10, "lost_s", "(0, 10] s", lost_s);
  require(stall_s > 0 && stall_s <= 100, "stall_s", "(0, 100] s", stall_s);
  require(retrace_max_m > 0 && retrace_max_m <= 1, "retrace_max_m", "(0, 1] m", retrace_max_m);
  require(pop_travel_max_m > 0 && pop_travel_max_m <= 0.1, "pop_travel_max_m", "(0, 0.1] m", pop_travel_max_m);
}

ExplorerHand::ExplorerHand(const ExplorerParams& p) : p_(p), rng_(p.seed) {
  p_.validate();
  corner_ = static_cast<int>(rng_() % 4);
  orient0_ = static_cast<int>(rng_() % 2);
  sense_ = (rng_() % 2) == 0 ? 1 : -1;
  nx_ = static_cast<int>(std::ceil(p_.workspace_width_m / p_.cell_m)) + 2;
  ny_ = static_cast<int>(std::ceil(p_.workspace_height_m / p_.cell_m)) + 2;
  traced_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), 0);
  traced_at_m_.assign(traced_.size(), 0.0);
  plan_pass();
  start_ = waypoints_.front();
  line_from_ = start_;
  wi_ = 1;
  carrot_ = start_;
  last_handle_ = start_;
}

// ---- memory ----

int ExplorerHand::cell_index(Vec2 p) const noexcept {
  if (!is_finite(p)) return -1;
  const double fx = (p.x + p_.workspace_width_m / 2) / p_.cell_m + 1;
  const double fy = (p.y + p_.workspace_height_m / 2) / p_.cell_m + 1;
  if (fx < 0 || fy < 0 || fx >= nx_ || fy >= ny_) return -1;
  return static_cast<int>(fy) * nx_ + static_cast<int>(fx);
}

void ExplorerHand::mark_traced(Vec2 p) {
  const int i = cell_index(p);
  if (i < 0) return;
  const auto k = static_cast<std::size_t>(i);
  if (traced_[k] != trace_id_) traced_at_m_[k] = travelled_;
  traced_[k] = trace_id_;
}

int ExplorerHand::trace_id_at(Vec2 p) const noexcept {
  const int i = cell_index(p);
  return i >= 0 ? traced_[static_cast<std::size_t>(i)] : 0;
}

bool ExplorerHand::traced_at(Vec2 p_m) const noexcept { return trace_id_at(p_m) != 0; }

bool ExplorerHand::traced_near(Vec2 p) const noexcept {
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (traced_at(p + Vec2{dx * p_.cell_m, dy * p_.cell_m})) return true;
  return false;
}

// ---- raster planning ----

void ExplorerHand::plan_pass() {
  const long k = stats_.passes++;
  const bool vertical = ((orient0_ + k) % 2) == 1;
  const double offset = ((k / 2) % 2) == 1 ? p_.sweep_spacing_m / 2 : 0.0;
  const double hw = p_.workspace_width_m / 2 - kMarginM, hh = p_.workspace_height_m / 2 - kMarginM;
  // Along: the lines' direction; across: where the lines lie. In a pass's own frame (u along, v across).
  const double half_along = vertical ? hh : hw, half_across = vertical ? hw : hh;
  std::vector<double> across;
  for (double v = -half_across + offset; v <= half_across + 1e-12; v += p_.sweep_spacing_m) across.push_back(v);
  // The corner decides where the first line lies and which way it runs.
  const bool left = corner_ == 0 || corner_ == 3, top = corner_ == 0 || corner_ == 1;
  const bool across_from_high = vertical ? !left : top;
  bool along_positive = vertical ? !top : left;
  if (across_from_high) std::reverse(across.begin(), across.end());
  waypoints_.clear();
  for (double v : across) {
    const double u0 = along_positive ? -half_along : half_along;
    const Vec2 a = vertical ? Vec2{v, u0} : Vec2{u0, v};
    const Vec2 b = vertical ? Vec2{v, -u0} : Vec2{-u0, v};
    waypoints_.push_back(a);
    waypoints_.push_back(b);
    along_positive = !along_positive;
  }
  wi_ = 0;
}

bool ExplorerHand::walls_give_way() const noexcept {
  // Like a visitor, give up pushing after kPopTriesBeforeGivingUp pushes of which none went through.
  return p_.pop_force_n > 0 && !(stats_.pops >= kPopTriesBeforeGivingUp && stats_.pops_through == 0);
}

void ExplorerHand::next_waypoint() {
  line_from_ = wi_ < waypoints_.size() ? waypoints_[wi_] : last_handle_;
  ++wi_;
  if (wi_ >= waypoints_.size()) plan_pass();
  move_check_t_ = last_t_;
  move_check_dist_ = distance(last_handle_, waypoints_[wi_]);
}

// ---- phases ----

void ExplorerHand::enter_move(Vec2 handle) {
  phase_ = ExplorerPhase::Move;
  carrot_ = handle;
  move_check_t_ = last_t_;
  move_check_dist_ = distance(handle, waypoints_[wi_]);
}

void ExplorerHand::enter_trace(const HandFeel& f, Vec2 n, bool bypass) {
  phase_ = ExplorerPhase::Trace;
  bypass_ = bypass;
  if (bypass) {
    ++stats_.bypasses;
    bypass_goal_dist_ = distance(f.handle_m, waypoints_[wi_]);
    bypass_from_ = f.handle_m;
  } else {
    ++stats_.traces;
  }
  ++trace_id_;
  trace_start_ = f.handle_m;
  trace_t0_ = f.t_s;
  travelled_ = 0.0;
  retraced_ = 0.0;
  start_settled_ = false;
  travelled_at_start_ = 0.0;
  n_ = n;
  lost_since_ = -1.0;
  lookahead_m_ = p_.trace_speed_m_per_s * 6.0 / p_.hand_stiffness_n_per_m;
  heading_ = static_cast<double>(sense_) * left_perp(n);
  stall_t_ = f.t_s;
  stall_pos_ = f.handle_m;
}

void ExplorerHand::enter_pop(const HandFeel& f, Vec2 n) {
  phase_ = ExplorerPhase::Pop;
  ++stats_.pops;
  pop_n_ = n;
  pop_start_ = f.handle_m;
  pop_t0_ = f.t_s;
}

HandCommand ExplorerHand::command(const HandFeel& feel_in) {
  HandFeel f = feel_in;
  if (!is_finite(f.handle_m)) f.handle_m = last_handle_;
  if (!is_finite(f.device_force_n)) f.device_force_n = {};
  if (!is_finite(f.handle_velocity_m_per_s)) f.handle_velocity_m_per_s = {};
  const double dt = started_ ? std::clamp(f.t_s - last_t_, 0.0, 0.1) : 0.0;
  started_ = true;
  last_t_ = f.t_s;
  HandCommand c;
  switch (phase_) {
    case ExplorerPhase::Move: c = step_move(f, dt); break;
    case ExplorerPhase::Trace: c = step_trace(f, dt); break;
    case ExplorerPhase::Pop: c = step_pop(f); break;
  }
  last_handle_ = f.handle_m;
  return c;
}

HandCommand ExplorerHand::step_move(const HandFeel& f, double dt) {
  const double felt = length(f.device_force_n);
  if (felt > p_.contact_force_n && f.t_s >= ignore_until_t_) {
    const Vec2 n = (1.0 / felt) * f.device_force_n;
    if (!traced_near(f.handle_m)) {
      enter_trace(f, n, false);
      return step_trace(f, 0.0);
    }
    if (!p_.grooves) {
      if (walls_give_way()) {
        enter_pop(f, n);
        return step_pop(f);
      }
      if (p_.bypass_walls) {
        enter_trace(f, n, true);  // walls that never give way: go round this one to the sweep line's far side
        return step_trace(f, 0.0);
      }
      next_waypoint();  // walls that never give way: this sweep line ends here
      carrot_ = f.handle_m;
    }
  }
  // The carrot runs to the waypoint at the sweep speed, never far ahead of the handle.
  Vec2 goal = waypoints_[wi_];
  if (distance(f.handle_m, goal) < kWaypointReachM) {
    next_waypoint();
    goal = waypoints_[wi_];
  }
  const Vec2 to_goal = goal - carrot_;
  const double d = length(to_goal);
  const double step = p_.sweep_speed_m_per_s * dt;
  carrot_ = d <= step ? goal : carrot_ + (step / d) * to_goal;
  const Vec2 lead = carrot_ - f.handle_m;
  if (length(lead) > p_.carrot_lead_m) carrot_ = f.handle_m + (p_.carrot_lead_m / length(lead)) * lead;
  // No progress towards the waypoint for stall_s (the stops, a wall too soft to feel): skip it.
  if (f.t_s - move_check_t_ > p_.stall_s) {
    const double now = distance(f.handle_m, goal);
    if (now > move_check_dist_ - 0.001) {
      next_waypoint();
    } else {
      move_check_t_ = f.t_s;
      move_check_dist_ = now;
    }
  }
  return HandCommand{carrot_, p_.max_force_n};
}

HandCommand ExplorerHand::step_trace(const HandFeel& f, double dt) {
  const double felt = length(f.device_force_n);
  const bool touching = felt > 0.5 * p_.contact_force_n;
  if (touching) {
    n_ = normalized_or(0.5 * n_ + 0.5 * ((1.0 / felt) * f.device_force_n), n_);
    lost_since_ = -1.0;
  } else {
    if (lost_since_ < 0) lost_since_ = f.t_s;
    // The wall fell away (a convex corner, an open end): turn towards it, round a circle of kTurnRadiusM.
    const double turn = static_cast<double>(sense_) * std::max(p_.trace_speed_m_per_s, length(f.handle_velocity_m_per_s)) / kTurnRadiusM * dt;
    n_ = Vec2{n_.x * std::cos(turn) - n_.y * std::sin(turn), n_.x * std::sin(turn) + n_.y * std::cos(turn)};
  }
  const double moved = distance(f.handle_m, last_handle_);
  travelled_ += moved;
  stats_.traced_m += moved;
  // Running over walls felt before: an earlier trace's, or this trace's own from more than loop_min_m of travel
  // ago (round an open end and back along its other side, or round a loop again).
  const int i = cell_index(f.handle_m);
  const bool own_old = i >= 0 && traced_[static_cast<std::size_t>(i)] == trace_id_ &&
                       travelled_ - traced_at_m_[static_cast<std::size_t>(i)] > p_.loop_min_m;
  const bool other = i >= 0 && traced_[static_cast<std::size_t>(i)] != 0 && traced_[static_cast<std::size_t>(i)] != trace_id_;
  retraced_ = (own_old || other) ? retraced_ + moved : 0.0;
  if (touching) {
    mark_traced(f.handle_m);
    if (!p_.grooves) mark_traced(f.handle_m + 0.0015 * n_);
  }
  // The loop is judged from where the trace had settled (the first contact presses harder than a trace).
  if (!start_settled_ && travelled_ > 0.003) {
    start_settled_ = true;
    trace_start_ = f.handle_m;
    travelled_at_start_ = travelled_;
  }
  // When the trace ends.
  bool done = false;
  const long closed_before = stats_.traces_closed;
  if (start_settled_ && travelled_ - travelled_at_start_ > p_.loop_min_m && distance(f.handle_m, trace_start_) < p_.loop_close_m) {
    done = true;
    ++stats_.traces_closed;
  }
  if (!done && f.t_s - trace_t0_ > p_.trace_max_s) {
    done = true;
    ++stats_.traces_timed_out;
  }
  if (!done && lost_since_ >= 0 && f.t_s - lost_since_ > p_.lost_s) {
    done = true;
    ++stats_.traces_lost;
  }
  if (bypass_) {
    // Back on the sweep line, past the obstacle: carry on sweeping. Round to the start again: the waypoint is
    // out of reach (inside a closed shape), skip it.
    const Vec2 a = bypass_from_, b = waypoints_[wi_];
    const double off = std::abs(cross(normalized_or(b - a, Vec2{1, 0}), f.handle_m - a));
    if (!done && off < kBypassLineM && distance(f.handle_m, b) < bypass_goal_dist_ - kBypassGainM) {
      enter_move(f.handle_m);
      return HandCommand{f.handle_m, p_.max_force_n};
    }
    if (stats_.traces_closed > closed_before) {
      next_waypoint();
      enter_move(f.handle_m);
      return HandCommand{f.handle_m, p_.max_force_n};
    }
  }
  if (!done && !bypass_ && retraced_ > p_.retrace_max_m) {
    done = true;
    ++stats_.traces_retraced;
  }
  if (!done && f.t_s - stall_t_ > p_.stall_s) {
    if (distance(f.handle_m, stall_pos_) < 0.001) {
      done = true;
      ++stats_.traces_stalled;
    }
    stall_t_ = f.t_s;
    stall_pos_ = f.handle_m;
  }
  if (done) {
    enter_move(f.handle_m);
    return HandCommand{f.handle_m, p_.max_force_n};
  }
  const double k = p_.hand_stiffness_n_per_m;
  if (p_.grooves) {
    // The groove steers: keep going the way the handle goes, pulled lightly towards the curve.
    const Vec2 v = f.handle_velocity_m_per_s;
    if (length(v) > 0.3 * p_.trace_speed_m_per_s) heading_ = normalized_or(0.9 * heading_ + 0.1 * normalized_or(v, heading_), heading_);
    const Vec2 pull = touching ? (0.3 * p_.press_force_n / k) * n_ : Vec2{};
    return HandCommand{f.handle_m + lookahead_m_ * heading_ + pull, p_.max_force_n};
  }
  // Walls: press against the wall (−n̂), slide along t̂; the lookahead is trimmed to hold the trace speed.
  const Vec2 t = static_cast<double>(sense_) * left_perp(n_);
  const double v_along = dot(f.handle_velocity_m_per_s, t);
  lookahead_m_ = std::clamp(lookahead_m_ + 0.3 * (p_.trace_speed_m_per_s - v_along) * dt, 0.0005, 0.008);
  const double lead = lookahead_m_;
  return HandCommand{f.handle_m - (p_.press_force_n / k) * n_ + lead * t, p_.max_force_n};
}

HandCommand ExplorerHand::step_pop(const HandFeel& f) {
  const double push = kPopFactor * p_.pop_force_n;
  const double back = dot(f.device_force_n, pop_n_);
  const double since = f.t_s - pop_t0_;
  if (since > 0.0 && back < p_.contact_force_n) {  // the wall gave way
    ++stats_.pops_through;
    ignore_until_t_ = f.t_s + kReleaseIgnoreS;
    enter_move(f.handle_m);
    return HandCommand{f.handle_m, p_.max_force_n};
  }
  if (since > p_.pop_hold_s + kPopExtraS || dot(pop_start_ - f.handle_m, pop_n_) > p_.pop_travel_max_m) {
    // The wall did not give way: go round it to the far side of the sweep line, or end the sweep line here.
    if (p_.bypass_walls) {
      enter_trace(f, pop_n_, true);
      return step_trace(f, 0.0);
    }
    enter_move(f.handle_m);
    next_waypoint();
    return HandCommand{f.handle_m, p_.max_force_n};
  }
  return HandCommand{f.handle_m - (1.05 * push / p_.hand_stiffness_n_per_m) * pop_n_, push};
}

}  // namespace hk
