#pragma once
/// @file explorer_hand.hpp
/// The visitor-like model hand of headless runs, `--hand explorer`: a closed-loop
/// HandController that knows only what a visitor knows, what it feels (HandFeel: force, handle, and the
/// push-through earcon it hears) and its own memory of where it has been, never the scene. The memory is a grid
/// of cell_m cells: which cells a trace ran along (walls felt round) and which the handle has passed over in this
/// pass (seen). A state machine of named phases:
///   Move  — covers the workspace: a plan (Dijkstra over the memory grid) to the nearest unseen cell, then on
///           along the pass's lines while the cells ahead are unseen, a carrot running along it at the sweep speed
///           (never more than `carrot_lead_m` ahead of the handle). The handle's footprint is sweep_spacing_m across
///           the lines, so the plans make a boustrophedon sweep with lines sweep_spacing_m apart. Entering a remembered
///           wall costs the plan as much as 3 cm of travel (impassable where walls do not give way), so a region is
///           swept before the hand pushes into the next. When every reachable cell is seen, a new pass begins with
///           the lines turned 90°. Feeling a wall (|device force| > contact_force_n) where the memory holds none
///           starts a Trace; a remembered wall the plan crosses within 6 mm is pushed through (Pop); one the plan
///           runs beside is brushed along. The next plan is made from the goal when the handle is 4 mm from it,
///           so the hand does not stop at each goal. No progress for stall_s: the goal is given up as seen.
///   Trace — follows the outline: presses gently against the wall (press_force_n along the felt force's
///           opposite, n̂) while moving along t̂ = sense·left_perp(n̂) at the trace speed (the turning sense
///           is fixed for the whole run). At an open end the felt force swings round the end and the trace
///           carries on along the other side. Ends back within `loop_close_m` of where it started after at
///           least `loop_min_m` travelled, after trace_max_s, when the wall is lost for lost_s, when it has
///           made no progress for stall_s (e.g. at the mechanical stops), or after `retrace_max_m` travelled
///           without feeling a new wall (over walls traced before, by an earlier trace or by this one more than
///           loop_min_m of travel ago, or off the wall circling an end). Every place traced is remembered.
///   Pop   — presses into the wall (along the felt force's opposite, followed as it turns) with 1.1 · pop_force_n
///           (HandCommand::max_force_n above the usual max_force_n) for at most pop_hold_s + 0.15 s; the wall gave
///           way when the push-through earcon is heard or the force pushing back falls under contact_force_n. A wall
///           that does not give way (or pressing would carry the handle more than pop_travel_max_m) gives up the
///           plan's goal; after three pushes none of which went through, walls are taken never to give way.
/// Grooves mode (`grooves`): the felt force points TOWARDS the curve and never blocks; a trace lets the
/// groove steer the hand (heading from the handle's velocity, a light pull along it), and remembered grooves cost
/// the plans nothing.
/// Deterministic: the start corner, the first pass's orientation and the turning sense come from
/// std::mt19937_64(seed); nothing else is random (plans break ties by cell index), so the same feels give the same
/// commands.

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "haptics/hand_controller.hpp"
#include "hk/vec2.hpp"

namespace hk {

/// Parameters of the explorer hand. Units in names; the defaults are the kiosk's (config [hand],
/// [haptics], [workspace]).
struct ExplorerParams {
  double workspace_width_m = 0.14;   ///< usable rectangle, centred on the origin [m], > 0
  double workspace_height_m = 0.09;  ///< [m], > 0
  double sweep_spacing_m = 0.006;    ///< distance between sweep lines [m], > 0 and ≤ the smaller side
  double sweep_speed_m_per_s =
      0.12;  ///< carrot speed along the sweep [m/s], > 0 (the kiosk's: 1.5 x [hand] raster_speed_m_per_s)
  double trace_speed_m_per_s = 0.045;   ///< speed along an outline [m/s], > 0
  double contact_force_n = 0.5;         ///< a felt force above this is a wall (or a groove) [N], > 0
  double press_force_n = 1.0;           ///< how hard a trace presses against the wall [N], > 0, < pop_force_n
  double max_force_n = 2.0;             ///< the hand's usual strongest push ([hand] max_force_n) [N], > press_force_n
  double hand_stiffness_n_per_m = 200;  ///< the hand's own spring ([hand] stiffness_n_per_m) [N/m], > 0
  double pop_force_n = 3.0;             ///< [haptics] pop_force_n: a wall gives way above this [N]; 0 = never (no Pop)
  double pop_hold_s = 0.3;              ///< [haptics] pop_hold_s [s], > 0
  bool grooves = false;                 ///< [haptics] render = "grooves": the force points towards the curve
  std::uint64_t seed = 1;               ///< start corner, first pass orientation, turning sense
  double duration_s = 120.0;            ///< natural_duration_s [s], > 0
  double cell_m = 0.0015;               ///< memory grid cell [m], [0.0002, 0.05]
  double carrot_lead_m = 0.008;         ///< the sweep's target runs at most this far ahead of the handle [m], > 0
  double loop_close_m = 0.003;          ///< a trace is round when back this close to its start [m], > 0
  double loop_min_m = 0.010;            ///< ... after travelling at least this [m], > loop_close_m
  double trace_max_s = 40.0;            ///< longest trace [s], > 0
  double lost_s = 0.4;                  ///< a trace that feels no wall this long ends [s], > 0
  double stall_s = 1.0;                 ///< a trace or move making less than 1 mm of progress in this ends [s], > 0
  double retrace_max_m = 0.02;          ///< a trace running this far over walls traced before ends [m], > 0
  double pop_travel_max_m =
      0.008;  ///< a push that carried the handle this far without the wall giving way failed [m], > 0

  /// Throws hk::ArgumentError (one line naming the field and its limit) when a value is out of range.
  void validate() const;
};

/// The phases of the explorer (see the file comment).
enum class ExplorerPhase : std::uint8_t { Move, Trace, Pop };

/// Counters of an explorer run, for tests and summaries.
struct ExplorerStats {
  long traces = 0;            ///< traces begun
  long traces_closed = 0;     ///< traces that came round to their start
  long traces_lost = 0;       ///< traces ended because no wall was felt for lost_s
  long traces_stalled = 0;    ///< traces ended for lack of progress (stall_s)
  long traces_timed_out = 0;  ///< traces ended after trace_max_s
  long traces_retraced = 0;   ///< traces ended running over walls traced before (retrace_max_m)
  long pops = 0;              ///< push-throughs tried
  long pops_through = 0;      ///< push-throughs in which the wall gave way
  long passes = 0;            ///< coverage passes begun (each ends when every reachable cell is seen)
  long plans = 0;             ///< plans made (Dijkstra runs that found an unseen cell)
  double traced_m = 0.0;      ///< handle travel while tracing [m]
  double move_s = 0.0;        ///< time spent sweeping (Move) [s]
  double trace_s = 0.0;       ///< time spent tracing, bypasses included (Trace) [s]
  double pop_s = 0.0;         ///< time spent pushing through (Pop) [s]
};

/// The visitor-like model hand (`--hand explorer`). Not thread-safe; one per run.
class ExplorerHand final : public HandController {
 public:
  /// Validates `p` (ExplorerParams::validate) and plans the first pass from the seed.
  explicit ExplorerHand(const ExplorerParams& p);

  /// One tick: updates the memory and the phase from what is felt, returns the target and the force limit
  /// (max_force_n, or 1.1 · pop_force_n while pushing through). Non-finite feels are treated as no force
  /// and the last handle position.
  HandCommand command(const HandFeel& feel) override;
  /// The seed's start corner, 3 mm inside the workspace [m].
  Vec2 start_m() const override { return start_; }
  /// ExplorerParams::duration_s [s].
  double natural_duration_s() const override { return p_.duration_s; }

  /// The phase of the last command.
  ExplorerPhase phase() const noexcept { return phase_; }
  /// Counters so far.
  const ExplorerStats& stats() const noexcept { return stats_; }
  /// Whether the memory cell holding `p_m` [m] was traced (false outside the workspace grid).
  bool traced_at(Vec2 p_m) const noexcept;
  /// The turning sense of traces: +1 (t̂ = left_perp(n̂)) or −1.
  int turning_sense() const noexcept { return sense_; }

 private:
  // Phase steps, each returning the tick's command.
  HandCommand step_move(const HandFeel& f, double dt);
  // Move's stages: what a felt wall leads to, the plan, the carrot along it, the goal.
  enum class MoveOutcome : std::uint8_t { Carry, Traced, Pushed, Replanned };
  MoveOutcome meet_wall(const HandFeel& f);
  bool have_plan(const HandFeel& f);  // false: nothing reachable left (hold still)
  void advance_carrot(Vec2 handle, double dt);
  void check_goal(const HandFeel& f);
  HandCommand step_trace(const HandFeel& f, double dt);
  // Trace's stages: the wall's normal as felt, the travel noted, the end tests, the command along the wall.
  bool feel_trace_wall(const HandFeel& f, double dt);
  void note_trace_travel(const HandFeel& f, bool touching);
  bool trace_ends(const HandFeel& f);
  HandCommand trace_command(const HandFeel& f, double dt, bool touching);
  HandCommand step_pop(const HandFeel& f);
  // Phase entries.
  void enter_move(Vec2 handle);
  void enter_trace(const HandFeel& f, Vec2 n);
  bool walls_give_way() const noexcept;
  void enter_pop(const HandFeel& f, Vec2 n);
  // Coverage planning (see the .cpp): passes, the seen footprint, Dijkstra to the nearest unseen cell.
  void start_pass();
  void mark_seen(Vec2 p);
  void skip_small_loop();    // a closed trace enclosing little: its inside is not planned to
  bool plan(Vec2 handle);    // false: no unseen cell reachable
  bool replan(Vec2 handle);  // plan; failing that, a new pass and plan again
  bool passable(int from, int to) const noexcept;
  double step_cost(int from, int to, bool diagonal) const noexcept;
  bool plan_crosses_wall(Vec2 handle) const noexcept;
  // Memory grid.
  int cell_index(Vec2 p) const noexcept;  // −1 outside
  Vec2 cell_centre(int i) const noexcept;
  bool targetable(int i) const noexcept;  // inside the workspace less the margin
  void mark_traced(Vec2 p);
  void remember_wall(Vec2 handle, Vec2 n);  // a remembered wall felt where the memory had none: add it
  bool traced_near(Vec2 p) const noexcept;  // the cell of p or one of its 8 neighbours traced
  int trace_id_at(Vec2 p) const noexcept;

  ExplorerParams p_;
  std::mt19937_64 rng_;
  int corner_ = 0;   // 0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left
  int orient0_ = 0;  // first pass: 0 horizontal lines, 1 vertical
  int sense_ = 1;
  Vec2 start_;
  ExplorerPhase phase_ = ExplorerPhase::Move;
  ExplorerStats stats_;
  double last_t_ = 0.0;
  bool started_ = false;
  Vec2 last_handle_;

  // Move.
  int orient_ = 0;               // this pass: 0 horizontal lines, 1 vertical
  int half_strip_ = 2;           // the footprint reaches this many cells either side of the handle, across the lines
  int run_dir_ = 1;              // the way the last run along a line went (+1 / −1 along the axis)
  std::vector<Vec2> waypoints_;  // the plan: cell centres to the goal (the last) [m]
  std::size_t wi_ = 0;           // the waypoint the carrot runs to
  Vec2 carrot_;
  double move_check_t_ = 0.0;
  double move_check_dist_ = 0.0;
  double ignore_until_t_ = 0.0;  // after a push-through, the release is not a new wall
  bool patched_ = false;         // this plan met a wall the memory had missed, and the memory was patched
  double idle_until_t_ = 0.0;    // nothing reachable was left: plan again after this
  std::vector<double> cost_;     // Dijkstra scratch, per cell [m]
  std::vector<int> prev_;

  // Trace.
  int trace_id_ = 0;
  Vec2 trace_start_;
  double trace_t0_ = 0.0;
  double travelled_ = 0.0;
  double retraced_ = 0.0;
  bool start_settled_ = false;
  double travelled_at_start_ = 0.0;
  Vec2 start_heading_;  // t̂ where the trace settled
  Vec2 n_;              // felt force direction (unit)
  double lost_since_ = -1.0;
  double lookahead_m_ = 0.001;
  Vec2 heading_;  // grooves: direction of travel
  double stall_t_ = 0.0;
  Vec2 stall_pos_;

  // Pop.
  Vec2 pop_n_;
  Vec2 pop_start_;
  double pop_t0_ = 0.0;

  // Memory: per cell the id of the trace that marked it (0 = never traced), and whether seen in this pass.
  int nx_ = 0, ny_ = 0;
  std::vector<int> traced_;
  std::vector<double> traced_at_m_;  // the trace's travel when the cell was first marked by it [m]
  std::vector<std::uint8_t> seen_;
  std::vector<std::uint8_t> skip_;  // inside a small loop felt round: never planned to
  std::vector<Vec2> trace_path_;    // the handle's path along the current trace, every half cell [m]
};

}  // namespace hk
