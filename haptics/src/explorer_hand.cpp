// The visitor-like model hand (`--hand explorer`): sweep, trace, push through.
#include "haptics/explorer_hand.hpp"
#include "hk/error.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

namespace hk {
namespace {

void require(bool ok, const char* field, const std::string& limit, double value) {
  if (!ok || !std::isfinite(value)) {
    throw hk::ArgumentError(std::string("explorer hand: ") + field + " = " + std::to_string(value) + " is outside " +
                            limit);
  }
}

constexpr double kMarginM = 0.003;          // the sweep keeps this far inside the workspace edge [m]
constexpr double kWaypointReachM = 0.0015;  // a plan's end is reached within this [m]
constexpr double kPlanAheadM = 0.004;       // the next plan is made from the goal when the handle is this near it [m]
// Push with this times pop_force_n: over the wall's give-way force, but under the force a wall is clamped at
// (3.5 N against the 3 N default), so the handle stops a few mm in and the press is held, not lost.
constexpr double kPopFactor = 1.1;
constexpr double kPopExtraS = 0.15;          // push for pop_hold_s plus this
constexpr double kTurnRadiusM = 0.002;       // a trace that lost its wall turns towards it on this radius [m]
constexpr long kPopTriesBeforeGivingUp = 3;  // pushes that all failed before the hand stops pushing
constexpr double kReleaseIgnoreS = 0.06;     // after a push-through, forces are not walls for this long [s]
constexpr double kWallCostM = 0.03;     // planning: entering a remembered wall costs this much travel (~ a push) [m]
constexpr double kCrossAheadM = 0.006;  // a remembered wall felt is pushed through if the plan crosses it this near [m]
constexpr int kRunMaxCells = 10;  // a plan runs on along its line at most this many cells (1.5 cm at the default cell)
constexpr double kGrooveReachM =
    0.003;  // a groove is felt this far from its curve ([haptics] groove_capture_radius_m) [m]
constexpr double kSmallLoopM2 =
    1e-4;  // a loop felt round enclosing less than this (1 cm²): its inside is not planned to [m²]
constexpr double kBlockingCos = 0.7;  // a wall whose force turns the way back by more than ~135° stands across it // a
                                      // plan runs on along its line at most this many cells

}  // namespace

void ExplorerParams::validate() const {
  require(workspace_width_m > 0 && workspace_width_m <= 1, "workspace_width_m", "(0, 1] m", workspace_width_m);
  require(workspace_height_m > 0 && workspace_height_m <= 1, "workspace_height_m", "(0, 1] m", workspace_height_m);
  require(sweep_spacing_m > 0 && sweep_spacing_m <= std::min(workspace_width_m, workspace_height_m), "sweep_spacing_m",
          "(0, the smaller workspace side] m", sweep_spacing_m);
  require(sweep_speed_m_per_s > 0 && sweep_speed_m_per_s <= 5, "sweep_speed_m_per_s", "(0, 5] m/s",
          sweep_speed_m_per_s);
  require(trace_speed_m_per_s > 0 && trace_speed_m_per_s <= 5, "trace_speed_m_per_s", "(0, 5] m/s",
          trace_speed_m_per_s);
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
  seen_.assign(traced_.size(), 0);
  skip_.assign(traced_.size(), 0);
  // The footprint of a sweep line: sweep_spacing_m across, so the next line lies one spacing over.
  half_strip_ = std::max(0, static_cast<int>(std::lround(p_.sweep_spacing_m / p_.cell_m)) - 1);
  // The start: the seed's corner, kMarginM inside the workspace; the first run heads away from it.
  const bool left = corner_ == 0 || corner_ == 3, top = corner_ == 0 || corner_ == 1;
  start_ = {(left ? -1 : 1) * (p_.workspace_width_m / 2 - kMarginM),
            (top ? 1 : -1) * (p_.workspace_height_m / 2 - kMarginM)};
  run_dir_ = orient0_ == 0 ? (left ? 1 : -1) : (top ? 1 : -1);
  start_pass();
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
  // Walls are felt only on contact: the 8 neighbours. A groove pulls from its capture radius (3 mm by default).
  const int r = p_.grooves ? std::max(1, static_cast<int>(std::ceil(kGrooveReachM / p_.cell_m))) : 1;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      if (traced_at(p + Vec2{dx * p_.cell_m, dy * p_.cell_m})) return true;
  return false;
}

// ---- coverage planning ----
//
// The hand's memory is a grid of cell_m cells over the workspace. A cell is *seen* in this pass once the handle
// has run across it: the footprint of the handle is a strip one cell long along the pass's lines and
// sweep_spacing_m across them, so the nearest unseen cells lie along the current line first, then on the next line
// one spacing over: a boustrophedon (lawn-mower) sweep that plans itself (Choset 2000, "Coverage of known spaces:
// the boustrophedon cellular decomposition", Autonomous Robots 9(3)). Remembered walls (traced cells) cost
// kWallCostM of travel to enter (a push-through) or are impassable where walls do not give way, so the sweep
// covers the region it is in before it pushes into the next one.

Vec2 ExplorerHand::cell_centre(int i) const noexcept {
  const int ix = i % nx_, iy = i / nx_;
  return {(ix - 1 + 0.5) * p_.cell_m - p_.workspace_width_m / 2,
          (iy - 1 + 0.5) * p_.cell_m - p_.workspace_height_m / 2};
}

bool ExplorerHand::targetable(int i) const noexcept {
  const Vec2 c = cell_centre(i);
  return std::abs(c.x) <= p_.workspace_width_m / 2 - kMarginM && std::abs(c.y) <= p_.workspace_height_m / 2 - kMarginM;
}

void ExplorerHand::start_pass() {
  const long k = stats_.passes++;
  orient_ = static_cast<int>((orient0_ + k) % 2);
  for (std::size_t i = 0; i < seen_.size(); ++i) seen_[i] = targetable(static_cast<int>(i)) && skip_[i] == 0 ? 0 : 1;
}

void ExplorerHand::mark_seen(Vec2 p) {
  const int i = cell_index(p);
  if (i < 0) return;
  const int ix = i % nx_, iy = i / nx_;
  for (int d = -half_strip_; d <= half_strip_; ++d) {
    const int jx = orient_ == 0 ? ix : ix + d, jy = orient_ == 0 ? iy + d : iy;
    if (jx >= 0 && jy >= 0 && jx < nx_ && jy < ny_) seen_[static_cast<std::size_t>(jy * nx_ + jx)] = 1;
  }
}

void ExplorerHand::skip_small_loop() {
  // A loop felt round that encloses less than kSmallLoopM2: what is inside it is known well enough from its outline;
  // its inside is never planned to (shoelace area; cells by the crossing-number test on their centres).
  const std::size_t n = trace_path_.size();
  if (n < 3) return;
  double area = 0.0;
  Vec2 lo = trace_path_[0], hi = trace_path_[0];
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2 a = trace_path_[k], b = trace_path_[(k + 1) % n];
    area += 0.5 * cross(a, b);
    lo = {std::min(lo.x, a.x), std::min(lo.y, a.y)};
    hi = {std::max(hi.x, a.x), std::max(hi.y, a.y)};
  }
  if (std::abs(area) >= kSmallLoopM2) return;
  for (double y = lo.y; y <= hi.y + p_.cell_m; y += p_.cell_m)
    for (double x = lo.x; x <= hi.x + p_.cell_m; x += p_.cell_m) {
      const int i = cell_index({x, y});
      if (i < 0) continue;
      const Vec2 c = cell_centre(i);
      bool inside = false;
      for (std::size_t k = 0, j = n - 1; k < n; j = k++) {
        const Vec2 a = trace_path_[k], b = trace_path_[j];
        if ((a.y > c.y) != (b.y > c.y) && c.x < (b.x - a.x) * (c.y - a.y) / (b.y - a.y) + a.x) inside = !inside;
      }
      if (inside) skip_[static_cast<std::size_t>(i)] = seen_[static_cast<std::size_t>(i)] = 1;
    }
}

bool ExplorerHand::passable(int from, int to) const noexcept {
  // Walls that never give way cannot be planned through (grooves never block).
  if (p_.grooves || walls_give_way()) return true;
  return traced_[static_cast<std::size_t>(to)] == 0 || traced_[static_cast<std::size_t>(from)] != 0;
}

double ExplorerHand::step_cost(int from, int to, bool diagonal) const noexcept {
  double c = (diagonal ? std::sqrt(2.0) : 1.0) * p_.cell_m;
  if (!p_.grooves && traced_[static_cast<std::size_t>(to)] != 0 && traced_[static_cast<std::size_t>(from)] == 0)
    c += kWallCostM;
  return c;
}

bool ExplorerHand::plan(Vec2 handle) {
  // Dijkstra from the handle's cell to the cheapest unseen cell (ties to the lower index: deterministic).
  waypoints_.clear();
  wi_ = 0;
  if (!is_finite(handle)) return false;
  // From the grid's cell nearest the handle (a handle pushed past the workspace's edge plans from its border).
  const double hx = p_.workspace_width_m / 2 + p_.cell_m / 2, hy = p_.workspace_height_m / 2 + p_.cell_m / 2;
  const int src = cell_index({std::clamp(handle.x, -hx, hx), std::clamp(handle.y, -hy, hy)});
  if (src < 0) return false;
  const std::size_t n = seen_.size();
  cost_.assign(n, std::numeric_limits<double>::infinity());
  prev_.assign(n, -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  cost_[static_cast<std::size_t>(src)] = 0.0;
  open.push({0.0, src});
  int target = -1;
  while (!open.empty()) {
    const auto [c, i] = open.top();
    open.pop();
    if (c > cost_[static_cast<std::size_t>(i)]) continue;
    if (seen_[static_cast<std::size_t>(i)] == 0) {
      target = i;
      break;
    }
    const int ix = i % nx_, iy = i / nx_;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0) continue;
        const int jx = ix + dx, jy = iy + dy;
        if (jx < 0 || jy < 0 || jx >= nx_ || jy >= ny_) continue;
        const int j = jy * nx_ + jx;
        const bool diagonal = dx != 0 && dy != 0;
        // No cutting a corner between two cells of a remembered wall.
        if (diagonal && !p_.grooves &&
            (traced_[static_cast<std::size_t>(iy * nx_ + jx)] != 0 ||
             traced_[static_cast<std::size_t>(jy * nx_ + ix)] != 0))
          continue;
        if (!passable(i, j)) continue;
        const double cj = c + step_cost(i, j, diagonal);
        if (cj < cost_[static_cast<std::size_t>(j)]) {
          cost_[static_cast<std::size_t>(j)] = cj;
          prev_[static_cast<std::size_t>(j)] = i;
          open.push({cj, j});
        }
      }
  }
  if (target < 0) return false;
  for (int i = target; i >= 0 && i != src; i = prev_[static_cast<std::size_t>(i)]) waypoints_.push_back(cell_centre(i));
  std::reverse(waypoints_.begin(), waypoints_.end());
  // Then run on along the line through the target while the cells ahead are unseen and free, the way the last
  // run went if it can (a lawn-mower turns back at the end of a line).
  const int tx = target % nx_, ty = target / nx_;
  auto run_length = [&](int dir) {
    int len = 0;
    for (int s = 1; s <= kRunMaxCells; ++s) {
      const int jx = orient_ == 0 ? tx + dir * s : tx, jy = orient_ == 0 ? ty : ty + dir * s;
      if (jx < 0 || jy < 0 || jx >= nx_ || jy >= ny_) break;
      const auto j = static_cast<std::size_t>(jy * nx_ + jx);
      if (seen_[j] != 0 || (traced_[j] != 0 && !p_.grooves)) break;
      len = s;
    }
    return len;
  };
  const int ahead = run_length(run_dir_), back = run_length(-run_dir_);
  if (back > ahead) run_dir_ = -run_dir_;
  const int len = std::max(ahead, back);
  if (len > 0) {
    const int jx = orient_ == 0 ? tx + run_dir_ * len : tx, jy = orient_ == 0 ? ty : ty + run_dir_ * len;
    waypoints_.push_back(cell_centre(jy * nx_ + jx));
  }
  // The handle's own cell unseen and nothing to run on to: the plan is that cell's centre (a plan is never
  // empty; its last waypoint is the goal).
  if (waypoints_.empty()) waypoints_.push_back(cell_centre(target));
  ++stats_.plans;
  return true;
}

bool ExplorerHand::replan(Vec2 handle) {
  if (plan(handle)) return true;
  start_pass();  // everything reachable seen: the next pass, along the other lines
  return plan(handle);
}

bool ExplorerHand::plan_crosses_wall(Vec2 handle) const noexcept {
  // Whether the planned way, within kCrossAheadM of the handle, runs over a remembered wall.
  Vec2 a = handle;
  double left = kCrossAheadM;
  for (std::size_t k = wi_; k < waypoints_.size() && left > 0; ++k) {
    const Vec2 b = waypoints_[k];
    const double len = distance(a, b);
    for (double u = 0.0; u < std::min(len, left); u += 0.5 * p_.cell_m)
      if (trace_id_at(a + (u / len) * (b - a)) != 0) return true;
    left -= len;
    a = b;
  }
  return false;
}

// ---- phases ----

bool ExplorerHand::walls_give_way() const noexcept {
  // Like a visitor, give up pushing after kPopTriesBeforeGivingUp pushes of which none went through.
  return p_.pop_force_n > 0 && !(stats_.pops >= kPopTriesBeforeGivingUp && stats_.pops_through == 0);
}

void ExplorerHand::remember_wall(Vec2 handle, Vec2 n) {
  // Under the nearest remembered wall's id: the handle's cell and the cell at the wall's face (n̂ points off it).
  int id = 0;
  for (int dy = -1; dy <= 1 && id == 0; ++dy)
    for (int dx = -1; dx <= 1 && id == 0; ++dx) id = trace_id_at(handle + Vec2{dx * p_.cell_m, dy * p_.cell_m});
  for (const Vec2 q : {handle, handle + 0.001 * n}) {
    const int i = cell_index(q);
    if (i >= 0 && traced_[static_cast<std::size_t>(i)] == 0) traced_[static_cast<std::size_t>(i)] = id;
  }
}

void ExplorerHand::enter_move(Vec2 handle) {
  phase_ = ExplorerPhase::Move;
  carrot_ = handle;
  waypoints_.clear();  // plan afresh from here: what was felt changed the memory
  wi_ = 0;
}

void ExplorerHand::enter_trace(const HandFeel& f, Vec2 n) {
  phase_ = ExplorerPhase::Trace;
  ++stats_.traces;
  ++trace_id_;
  trace_path_.clear();
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
  (phase_ == ExplorerPhase::Move    ? stats_.move_s
   : phase_ == ExplorerPhase::Trace ? stats_.trace_s
                                    : stats_.pop_s) += dt;
  mark_seen(f.handle_m);
  HandCommand c;
  switch (phase_) {
    case ExplorerPhase::Move:
      c = step_move(f, dt);
      break;
    case ExplorerPhase::Trace:
      c = step_trace(f, dt);
      break;
    case ExplorerPhase::Pop:
      c = step_pop(f);
      break;
  }
  last_handle_ = f.handle_m;
  return c;
}

// Move, phase by phase: a wall met (trace it, push through it, or patch the memory), the plan (made afresh
// when done), the carrot along it, the goal reached or given up.
HandCommand ExplorerHand::step_move(const HandFeel& f, double dt) {
  if (const MoveOutcome o = meet_wall(f); o != MoveOutcome::Carry) {
    if (o == MoveOutcome::Traced) return step_trace(f, 0.0);
    if (o == MoveOutcome::Pushed) return step_pop(f);
    return HandCommand{f.handle_m, p_.max_force_n};  // Replanned: stand still this tick
  }
  if (!have_plan(f)) {
    carrot_ = f.handle_m;
    return HandCommand{f.handle_m, p_.max_force_n};
  }
  advance_carrot(f.handle_m, dt);
  check_goal(f);
  return HandCommand{carrot_, p_.max_force_n};
}

ExplorerHand::MoveOutcome ExplorerHand::meet_wall(const HandFeel& f) {
  const double felt = length(f.device_force_n);
  if (felt <= p_.contact_force_n || f.t_s < ignore_until_t_) return MoveOutcome::Carry;
  const Vec2 n = (1.0 / felt) * f.device_force_n;
  if (!traced_near(f.handle_m)) {
    enter_trace(f, n);
    return MoveOutcome::Traced;
  }
  if (p_.grooves) return MoveOutcome::Carry;  // remembered grooves are crossed
  // A wall felt round before: push through it where the plan crosses it or where it stands square across the
  // way; where the plan only runs beside it, brush along it.
  const Vec2 way = carrot_ - f.handle_m;
  const bool across = length(way) > 1e-4 && dot(n, (1.0 / length(way)) * way) < -kBlockingCos;
  const bool crosses = plan_crosses_wall(f.handle_m);
  if (across && !crosses && !patched_) {
    // The memory held this wall short of where it stands: remember it here, and plan again (round it, or
    // through it if going round costs more).
    remember_wall(f.handle_m, n);
    patched_ = true;
    enter_move(f.handle_m);
    return MoveOutcome::Replanned;
  }
  if (walls_give_way() && (across || crosses)) {
    enter_pop(f, n);
    return MoveOutcome::Pushed;
  }
  return MoveOutcome::Carry;
}

bool ExplorerHand::have_plan(const HandFeel& f) {
  if (wi_ < waypoints_.size()) return true;
  if (f.t_s < idle_until_t_) return false;
  if (!replan(f.handle_m)) {
    idle_until_t_ = f.t_s + 0.5;  // nothing left to reach: hold still, look again later
    return false;
  }
  move_check_t_ = f.t_s;
  move_check_dist_ = distance(f.handle_m, waypoints_.back());
  patched_ = false;
  return true;
}

void ExplorerHand::advance_carrot(Vec2 handle, double dt) {
  // The carrot runs through the waypoints at the sweep speed, never far ahead of the handle.
  double step = p_.sweep_speed_m_per_s * dt;
  while (wi_ < waypoints_.size()) {
    const Vec2 to = waypoints_[wi_] - carrot_;
    const double d = length(to);
    if (d > step) {
      carrot_ = carrot_ + (step / d) * to;
      break;
    }
    carrot_ = waypoints_[wi_];
    step -= d;
    if (wi_ + 1 == waypoints_.size()) break;  // the last one is left when the handle reaches it
    ++wi_;
  }
  const Vec2 lead = carrot_ - handle;
  if (length(lead) > p_.carrot_lead_m) carrot_ = handle + (p_.carrot_lead_m / length(lead)) * lead;
}

void ExplorerHand::check_goal(const HandFeel& f) {
  const Vec2 goal = waypoints_.back();
  if (wi_ + 1 >= waypoints_.size() && distance(carrot_, goal) < 1e-9 && distance(f.handle_m, goal) < kPlanAheadM) {
    // Nearly there: what lies between the handle and the goal will be seen; plan on from the goal, so the hand
    // does not stop at every goal.
    const double d = distance(f.handle_m, goal);
    for (double u = 0.0; u <= d; u += 0.5 * p_.cell_m)
      mark_seen(f.handle_m + (u / std::max(d, 1e-12)) * (goal - f.handle_m));
    mark_seen(goal);
    if (replan(goal)) {
      waypoints_.insert(waypoints_.begin(), goal);
      wi_ = 0;
      move_check_t_ = f.t_s;
      move_check_dist_ = distance(f.handle_m, waypoints_.back());
      patched_ = false;
      return;
    }
    wi_ = waypoints_.size();
    return;
  }
  if (wi_ + 1 >= waypoints_.size() && distance(f.handle_m, goal) < kWaypointReachM) {
    if (const int g = cell_index(goal); g >= 0) seen_[static_cast<std::size_t>(g)] = 1;
    wi_ = waypoints_.size();  // done: plan again next tick
  } else if (f.t_s - move_check_t_ > p_.stall_s) {
    // No progress towards the goal for stall_s (a wall too soft to feel, a stop): give it up as seen.
    const double now = distance(f.handle_m, goal);
    if (now > move_check_dist_ - 0.001) {
      if (const int g = cell_index(goal); g >= 0) seen_[static_cast<std::size_t>(g)] = 1;
      wi_ = waypoints_.size();
    }
    move_check_t_ = f.t_s;
    move_check_dist_ = now;
  }
}

// One tick of a trace: the wall felt, the travel noted, then the trace ends (back to moving) or goes on along the wall.
HandCommand ExplorerHand::step_trace(const HandFeel& f, double dt) {
  const bool touching = feel_trace_wall(f, dt);
  note_trace_travel(f, touching);
  if (trace_ends(f)) {
    enter_move(f.handle_m);
    return HandCommand{f.handle_m, p_.max_force_n};
  }
  return trace_command(f, dt, touching);
}

// The wall's normal n_ as the trace feels it: while the force says the hand touches, smoothed towards the force's
// direction; when the wall falls away (a convex corner, an open end), turned towards it round a circle of
// kTurnRadiusM, and the time it was lost noted. Returns whether the hand touches.
bool ExplorerHand::feel_trace_wall(const HandFeel& f, double dt) {
  const double felt = length(f.device_force_n);
  const bool touching = felt > 0.5 * p_.contact_force_n;
  if (touching) {
    n_ = normalized_or(0.5 * n_ + 0.5 * ((1.0 / felt) * f.device_force_n), n_);
    lost_since_ = -1.0;
  } else {
    if (lost_since_ < 0) lost_since_ = f.t_s;
    const double turn = static_cast<double>(sense_) *
                        std::max(p_.trace_speed_m_per_s, length(f.handle_velocity_m_per_s)) / kTurnRadiusM * dt;
    n_ = Vec2{n_.x * std::cos(turn) - n_.y * std::sin(turn), n_.x * std::sin(turn) + n_.y * std::cos(turn)};
  }
  return touching;
}

// The trace's bookkeeping of where the hand went: distance travelled, travel over walls felt before (retraced_),
// the path, the cells traced, and once the trace has settled its start (the loop is judged from there).
void ExplorerHand::note_trace_travel(const HandFeel& f, bool touching) {
  const double moved = distance(f.handle_m, last_handle_);
  travelled_ += moved;
  stats_.traced_m += moved;
  // Running over walls felt before: an earlier trace's, or this trace's own from more than loop_min_m of travel
  // ago (round an open end and back along its other side, or round a loop again).
  const int i = cell_index(f.handle_m);
  const bool own_old = i >= 0 && traced_[static_cast<std::size_t>(i)] == trace_id_ &&
                       travelled_ - traced_at_m_[static_cast<std::size_t>(i)] > p_.loop_min_m;
  const bool other =
      i >= 0 && traced_[static_cast<std::size_t>(i)] != 0 && traced_[static_cast<std::size_t>(i)] != trace_id_;
  // Travel since a new wall was last felt: over old walls, or off any wall (circling at an end that keeps
  // brushing the wall it left), it grows.
  retraced_ = (touching && !own_old && !other) ? 0.0 : retraced_ + moved;
  if (trace_path_.empty() || distance(trace_path_.back(), f.handle_m) > 0.5 * p_.cell_m)
    trace_path_.push_back(f.handle_m);
  if (touching) {
    mark_traced(f.handle_m);
    if (!p_.grooves) mark_traced(f.handle_m + 0.0015 * n_);
  }
  // The loop is judged from where the trace had settled (the first contact presses harder than a trace).
  if (!start_settled_ && travelled_ > 0.003) {
    start_settled_ = true;
    trace_start_ = f.handle_m;
    start_heading_ = static_cast<double>(sense_) * left_perp(n_);
    travelled_at_start_ = travelled_;
  }
}

// Whether the trace ends this tick, each end counted in stats_: round (back at the start going the same way, not
// passing it on the far side of a thin stroke), timed out, lost the wall, retracing old walls, or stalled.
bool ExplorerHand::trace_ends(const HandFeel& f) {
  if (start_settled_ && travelled_ - travelled_at_start_ > p_.loop_min_m &&
      distance(f.handle_m, trace_start_) < p_.loop_close_m &&
      dot(static_cast<double>(sense_) * left_perp(n_), start_heading_) > 0.5) {
    ++stats_.traces_closed;
    skip_small_loop();
    return true;
  }
  if (f.t_s - trace_t0_ > p_.trace_max_s) {
    ++stats_.traces_timed_out;
    return true;
  }
  if (lost_since_ >= 0 && f.t_s - lost_since_ > p_.lost_s) {
    ++stats_.traces_lost;
    return true;
  }
  if (retraced_ > p_.retrace_max_m) {
    ++stats_.traces_retraced;
    return true;
  }
  bool stalled = false;
  if (f.t_s - stall_t_ > p_.stall_s) {
    if (distance(f.handle_m, stall_pos_) < 0.001) {
      stalled = true;
      ++stats_.traces_stalled;
    }
    stall_t_ = f.t_s;
    stall_pos_ = f.handle_m;
  }
  return stalled;
}

// The command of a trace going on: with grooves, on along the handle's way, pulled lightly towards the curve; with
// walls, pressed against the wall (−n̂) and sliding along t̂, the lookahead trimmed to hold the trace speed.
HandCommand ExplorerHand::trace_command(const HandFeel& f, double dt, bool touching) {
  const double k = p_.hand_stiffness_n_per_m;
  if (p_.grooves) {
    // The groove steers: keep going the way the handle goes, pulled lightly towards the curve.
    const Vec2 v = f.handle_velocity_m_per_s;
    if (length(v) > 0.3 * p_.trace_speed_m_per_s)
      heading_ = normalized_or(0.9 * heading_ + 0.1 * normalized_or(v, heading_), heading_);
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
  // Press along the wall's normal as felt now: pressed off it, the proxy slides and the press never holds.
  const double felt = length(f.device_force_n);
  if (felt > p_.contact_force_n) pop_n_ = normalized_or(0.8 * pop_n_ + 0.2 * ((1.0 / felt) * f.device_force_n), pop_n_);
  if (since > 0.0 && (f.heard_pop || back < p_.contact_force_n)) {  // the wall gave way (heard, or felt)
    ++stats_.pops_through;
    ignore_until_t_ = f.t_s + kReleaseIgnoreS;
    enter_move(f.handle_m);
    return HandCommand{f.handle_m, p_.max_force_n};
  }
  if (since > p_.pop_hold_s + kPopExtraS || dot(pop_start_ - f.handle_m, pop_n_) > p_.pop_travel_max_m) {
    // The wall did not give way: what lay beyond it is given up for this pass; plan afresh.
    if (!waypoints_.empty())
      if (const int g = cell_index(waypoints_.back()); g >= 0) seen_[static_cast<std::size_t>(g)] = 1;
    enter_move(f.handle_m);
    return HandCommand{f.handle_m, p_.max_force_n};
  }
  return HandCommand{f.handle_m - (1.05 * push / p_.hand_stiffness_n_per_m) * pop_n_, push};
}

}  // namespace hk
