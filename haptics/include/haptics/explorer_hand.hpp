#pragma once
/// @file explorer_hand.hpp
/// The visitor-like model hand of headless runs, `--hand explorer` (issue 14, item 4): a closed-loop
/// HandController that knows only what a visitor knows, what it feels (HandFeel) and its own memory of
/// where it has been, never the scene. A state machine of named phases:
///   Move  — sweeps the workspace in raster passes (a carrot running along the raster's corners at the
///           sweep speed, never more than `carrot_lead_m` ahead of the handle). Feeling a wall (|device
///           force| > contact_force_n) where its memory says it has not traced yet starts a Trace; where it
///           has traced (a wall already felt round), it pushes through (Pop) and carries on the sweep line.
///   Trace — follows the outline: presses gently against the wall (press_force_n along the felt force's
///           opposite, n̂) while moving along t̂ = sense·left_perp(n̂) at the trace speed (the turning sense
///           is fixed for the whole run). At an open end the felt force swings round the end and the trace
///           carries on along the other side. Ends back within `loop_close_m` of where it started after at
///           least `loop_min_m` travelled, after trace_max_s, when the wall is lost for lost_s, when it has
///           made no progress for stall_s (e.g. at the mechanical stops), or after `retrace_max_m` run
///           over walls traced before (by an earlier trace, or by this one more than loop_min_m of travel ago:
///           round an open end and back along its other side, which coverage does not need). Every place traced is remembered in a grid of cell_m cells.
///   Pop   — presses straight into the wall (along −n̂) with 1.1 · pop_force_n (HandCommand::max_force_n
///           above the usual max_force_n) for at most pop_hold_s + 0.15 s; the wall gave way when the
///           force pushing back falls under contact_force_n. A wall that does not give way (push-through
///           off, or pressing would carry the handle more than pop_travel_max_m) ends the sweep line.
/// Passes alternate between horizontal and vertical lines, every other pair offset by half the spacing,
/// so walls parallel to one pass's lines are met by the next. Inside a closed shape traced from outside
/// the sweep line pushes in, sweeps inside (tracing what it meets there) and pushes out again.
/// Grooves mode (`grooves`): the felt force points TOWARDS the curve and never blocks; a trace lets the
/// groove steer the hand (heading from the handle's velocity, a light pull along it) and walls traced before
/// are simply swept over.
/// Deterministic: the start corner, the first pass's orientation and the turning sense come from
/// std::mt19937_64(seed); nothing else is random, so the same feels give the same commands.

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "haptics/hand_controller.hpp"
#include "haptics/vec2.hpp"

namespace hk {

/// Parameters of the explorer hand. Units in names; the defaults are the kiosk's (config [hand],
/// [haptics], [workspace]).
struct ExplorerParams {
  double workspace_width_m = 0.14;      ///< usable rectangle, centred on the origin [m], > 0
  double workspace_height_m = 0.09;     ///< [m], > 0
  double sweep_spacing_m = 0.006;       ///< distance between raster lines [m], > 0 and ≤ the smaller side
  double sweep_speed_m_per_s = 0.08;    ///< carrot speed along the raster [m/s], > 0
  double trace_speed_m_per_s = 0.045;   ///< speed along an outline [m/s], > 0
  double contact_force_n = 0.5;         ///< a felt force above this is a wall (or a groove) [N], > 0
  double press_force_n = 1.0;           ///< how hard a trace presses against the wall [N], > 0, < pop_force_n
  double max_force_n = 2.0;             ///< the hand's usual strongest push ([hand] max_force_n) [N], > press_force_n
  double hand_stiffness_n_per_m = 200;  ///< the hand's own spring ([hand] stiffness_n_per_m) [N/m], > 0
  double pop_force_n = 3.0;             ///< [haptics] pop_force_n: a wall gives way above this [N]; 0 = never (no Pop)
  double pop_hold_s = 0.3;              ///< [haptics] pop_hold_s [s], > 0
  /// A traced wall that does not give way (push-through off, or three pushes failed): true = go round it back
  /// to the sweep line's far side (Bug2); false = end the sweep line there and take the next.
  bool bypass_walls = false;
  bool grooves = false;                 ///< [haptics] render = "grooves": the force points towards the curve
  std::uint64_t seed = 1;               ///< start corner, first pass orientation, turning sense
  double duration_s = 120.0;            ///< natural_duration_s [s], > 0
  double cell_m = 0.002;                ///< memory grid cell [m], > 0
  double carrot_lead_m = 0.008;         ///< the sweep's target runs at most this far ahead of the handle [m], > 0
  double loop_close_m = 0.003;          ///< a trace is round when back this close to its start [m], > 0
  double loop_min_m = 0.010;            ///< ... after travelling at least this [m], > loop_close_m
  double trace_max_s = 40.0;            ///< longest trace [s], > 0
  double lost_s = 0.4;                  ///< a trace that feels no wall this long ends [s], > 0
  double stall_s = 1.0;                 ///< a trace or move making less than 1 mm of progress in this ends [s], > 0
  double retrace_max_m = 0.02;          ///< a trace running this far over walls traced before ends [m], > 0
  double pop_travel_max_m = 0.008;      ///< a push that carried the handle this far without the wall giving way failed [m], > 0

  /// Throws std::invalid_argument (one line naming the field and its limit) when a value is out of range.
  void validate() const;
};

/// The phases of the explorer (see the file comment).
enum class ExplorerPhase : std::uint8_t { Move, Trace, Pop };

/// Counters of an explorer run, for tests and summaries.
struct ExplorerStats {
  long traces = 0;          ///< traces begun
  long traces_closed = 0;   ///< traces that came round to their start
  long traces_lost = 0;     ///< traces ended because no wall was felt for lost_s
  long traces_stalled = 0;  ///< traces ended for lack of progress (stall_s)
  long traces_timed_out = 0;///< traces ended after trace_max_s
  long traces_retraced = 0; ///< traces ended running over walls traced before (retrace_max_m)
  long pops = 0;            ///< push-throughs tried
  long pops_through = 0;    ///< push-throughs in which the wall gave way
  long bypasses = 0;        ///< walls gone round because they did not give way (traces of the Bug2 kind)
  long passes = 0;          ///< raster passes begun
  double traced_m = 0.0;    ///< handle travel while tracing [m]
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
  /// The first pass's start corner, 3 mm inside the workspace [m].
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
  HandCommand step_trace(const HandFeel& f, double dt);
  HandCommand step_pop(const HandFeel& f);
  // Phase entries.
  void enter_move(Vec2 handle);
  void enter_trace(const HandFeel& f, Vec2 n, bool bypass);
  bool walls_give_way() const noexcept;
  void enter_pop(const HandFeel& f, Vec2 n);
  // Raster planning: the waypoints of pass `stats_.passes`.
  void plan_pass();
  void next_waypoint();
  // Memory grid.
  int cell_index(Vec2 p) const noexcept;  // −1 outside
  void mark_traced(Vec2 p);
  bool traced_near(Vec2 p) const noexcept;  // the cell of p or one of its 8 neighbours traced
  int trace_id_at(Vec2 p) const noexcept;

  ExplorerParams p_;
  std::mt19937_64 rng_;
  int corner_ = 0;        // 0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left
  int orient0_ = 0;       // first pass: 0 horizontal lines, 1 vertical
  int sense_ = 1;
  Vec2 start_;
  ExplorerPhase phase_ = ExplorerPhase::Move;
  ExplorerStats stats_;
  double last_t_ = 0.0;
  bool started_ = false;
  Vec2 last_handle_;

  // Move.
  std::vector<Vec2> waypoints_;
  std::size_t wi_ = 0;
  Vec2 carrot_;
  double move_check_t_ = 0.0;
  double move_check_dist_ = 0.0;
  double ignore_until_t_ = 0.0;   // after a push-through, the release is not a new wall

  // Trace.
  int trace_id_ = 0;
  bool bypass_ = false;        // going round a wall that did not give way, back to the sweep line
  double bypass_goal_dist_ = 0.0;
  Vec2 bypass_from_;           // where the bypass met the wall: it ends back on the line from here to the waypoint
  Vec2 line_from_;             // where the current sweep line began
  Vec2 trace_start_;
  double trace_t0_ = 0.0;
  double travelled_ = 0.0;
  double retraced_ = 0.0;
  bool start_settled_ = false;
  double travelled_at_start_ = 0.0;
  Vec2 n_;                  // felt force direction (unit)
  double lost_since_ = -1.0;
  double lookahead_m_ = 0.001;
  Vec2 heading_;            // grooves: direction of travel
  double stall_t_ = 0.0;
  Vec2 stall_pos_;

  // Pop.
  Vec2 pop_n_;
  Vec2 pop_start_;
  double pop_t0_ = 0.0;

  // Memory: per cell the id of the trace that marked it (0 = never traced).
  int nx_ = 0, ny_ = 0;
  std::vector<int> traced_;
  std::vector<double> traced_at_m_;  // the trace's travel when the cell was first marked by it [m]
};

}  // namespace hk
