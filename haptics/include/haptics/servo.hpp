#pragma once
/// @file servo.hpp
/// The servo tick (DESIGN.md "Data flow", "Real-time rules"): device sample → level policy (hand speed)
/// → collision query and contact solver at the level in use → force-step limit at level changes →
/// force guard → force command, plus haptic events.
///
/// Level changes: the level wanted (LevelPolicy in auto mode, else the fixed level) is
/// taken only at a tick where ContactSolver::level_change_is_safe says the proxy is on the same side of the
/// new level's polyline as of the old one; until then the old level stays (ServoOutput::level_wanted shows
/// the wait). After the change the old level remains a wall until the proxy leaves it, and any difference
/// between the force of the last tick and the new level's force fades out at max_force_step_n per tick.
///
/// Live gains: stiffness, damping, maximum force and friction may change while a hand
/// presses on a wall (SceneStep::set_gains). The solver uses the new gains at once; the difference between
/// the last tick's force and the new gains' force goes into the same fading residual as a level change, and
/// the guard's clamp walks to the new maximum force at max_force_step_n per tick, so no change of gains
/// (or of level, or both in one tick) moves the force by more than max_force_step_n per tick beyond what
/// the hand's own motion does. A difference of D [N] is gone after ceil(D / max_force_step_n) ticks,
/// counting the tick that takes the change.
/// Push-through is the contact solver's (ContactSolver::pop_through); the loop only keeps a press
/// from counting while its force ramps in (start-up, ServoInput::press_counts false while the caller fades).
/// The tick is `update(input, output) -> TickResult`: a function of (state, sample, scene), with no
/// allocation, lock, throw, I/O, logging or clock read. Its collision work is bounded by one number, the
/// box-test budget ServoParams::query_box_budget: one counter per tick (QueryBudget) shared by the
/// level-change check (ContactSolver::level_change_is_safe) and every collision query of the contact
/// solver; past it the proxy waits where the sweep is proven clear and a level change waits for a later
/// tick. Timing the tick is the caller's business. Status enums here; exceptions only at setup.
///
/// Grooves (ServoParams::render): the loop holds both solvers, sized at construction, and
/// steps the one in use: GrooveSolver (groove.hpp) in grooves mode, whose output fills the same
/// ContactOutput (proxy = closest point within the capture radius, state Edge inside it). Level changes are
/// then taken at once (no wall to cross), and the force-step limit at level and gains changes is the groove
/// solver's per-tick limit (k·|Δhandle| + jump_step_n, jump_step_n = max_force_step_n), not the residual.

#include <cstdint>

#include "haptics/contact.hpp"
#include "haptics/device.hpp"
#include "haptics/groove.hpp"
#include "haptics/level_policy.hpp"
#include "haptics/scene.hpp"

namespace hk {

/// Why a tick's force was zeroed or limited. `Ok` means the solver's force went out (maybe ramped).
enum class TickResult : std::uint8_t {
  Ok,
  DeviceNotOk,     ///< the device reported Lost/Fault/Closed: zero force
  NonFinite,       ///< the sample or the force was NaN/inf: zero force, state kept
  DeadlineMissed,  ///< the caller said this tick is late: zero force
};

/// The one gate every force passes (DESIGN.md "Real-time rules"): finite, clamped, ramped in at
/// start-up, zero on a missed deadline or a device that is not Ok.
struct ForceGuard {
  double max_force_n = 4.0;  ///< clamp on |F| [N]
  double ramp_s = 0.5;       ///< time for the clamp to grow linearly from 0 to max_force_n after start [s]

  /// Returns the force to send [N]. `since_start_s` is the time since the loop (or a new scene) started [s].
  /// Zero force when `status` is not Ok (why = DeviceNotOk), when `deadline_missed` (DeadlineMissed) or
  /// when `force_n` is NaN/inf (NonFinite), checked in that order; otherwise the force clamped in length
  /// to max_force_n · min(1, since_start_s / ramp_s), direction kept (why = Ok). `why` must not be null.
  Vec2 apply(Vec2 force_n, double since_start_s, DeviceStatus status, bool deadline_missed,
             TickResult* why) const noexcept;
};

/// Default box-test budget of a servo tick (ServoParams::query_box_budget; config key
/// [haptics] query_box_budget), sized so a tick's collision work stays near 200 µs, a fifth of the 1 ms
/// period. Measured on the 2-core development machine with a build running on the other core:
///   cmake --build build --target bench_anytime && build/bench/bench_anytime --out /tmp/anytime.json
/// which reports whole cold-query time divided by its box tests (sorting, segment tests and section
/// upkeep included): 42 ns per box test on horse, 46 ns on sudoku, 70 ns on a tiled 100k-segment scene
/// and ~100 ns on a tiled 1M-segment one. 200 µs / ~46 ns ≈ 4300 on the test pictures, hence 4000
/// (≈ 185 µs there; ≈ 400 µs in the worst case measured, the 1M-segment scene, still within the period).
/// A cold query needs 30–60 box tests to answer exactly at level 0, so the budget binds only in pathologies.
inline constexpr std::int32_t kDefaultQueryBoxBudget = 4000;

/// How curves are felt (config key [haptics] render): as walls the proxy cannot cross
/// (ContactSolver, the seed paper's god-object) or as engraved grooves that pull the hand in within a
/// capture radius and never block (GrooveSolver, groove.hpp).
enum class RenderMode : std::uint8_t {
  Walls,    ///< god-object walls (ContactSolver), the default
  Grooves,  ///< engraved lines (GrooveSolver)
};

/// The servo settings an operator may change while a visitor touches a wall. Units in
/// names. Values are assumed checked (config ranges): finite, max_force_step_n > 0, the rest ≥ 0.
struct ServoGains {
  double stiffness_n_per_m = 800.0;  ///< wall stiffness [N/m] (ContactParams::stiffness_n_per_m)
  double damping_n_s_per_m = 0.0;    ///< damping along the contact normal [N·s/m]
  double max_force_n = 4.0;          ///< force clamp of the solver and of the guard [N]
  double static_friction = 0.0;      ///< μ_s (ContactParams::static_friction)
  double dynamic_friction = 0.0;     ///< μ_d ≤ μ_s
  double max_force_step_n =
      0.05;  ///< the limit on force change per tick a gains change (or level change) may cause [N]
  std::int32_t query_box_budget =
      kDefaultQueryBoxBudget;   ///< box tests per tick (ServoParams::query_box_budget); 0 = no limit
  double pop_force_n = 0.0;     ///< push-through press [N], 0 = off (ContactParams::pop_force_n)
  double pop_hold_s = 0.3;      ///< how long the press must last [s]
  double pop_release_s = 0.02;  ///< the force fades over this after a push-through [s]
  bool operator==(const ServoGains&) const = default;
};

/// What the level policy chooses from when the level follows the hand's speed (`[haptics] level_mode`:
/// "auto" → Levels, "tolerance" → Tolerances, "cut" → Cuts; level ids in hk/constants.hpp).
enum class LevelSteps : std::uint8_t {
  /// The scene's levels: every curve at the same level.
  Levels,
  /// Tolerance steps: each curve renders at the coarsest of its own levels within the tolerance the hand's
  /// speed allows, under the same crossing checks at changes.
  Tolerances,
  /// Cut steps (kCutLevelBase + t): the walls are the tolerance cut at that tolerance, refined per segment
  /// rather than per curve (tolerance_cut.hpp), under the same crossing checks at changes. The step then
  /// computes the scene's cut masks (make_cut_walls) once, for both solvers; with the others, none.
  Cuts,
};

/// Parameters of the servo step.
struct ServoParams {
  double period_s = 0.001;  ///< servo period = 1 / servo rate [s]
  /// Resolution level at start, and always when !auto_level. With Tolerances or Cuts only where it starts:
  /// the coarsest step whose bound is within that level's.
  int level = 1;
  bool auto_level = false;                ///< the level follows the hand's speed (LevelPolicy), from `steps`
  LevelSteps steps = LevelSteps::Levels;  ///< what the policy chooses from (with auto_level)
  LevelPolicyParams policy;               ///< used when auto_level (its fixed_level is ignored: see `auto_level`)
  /// At a level change the force passes from the old level's to the new level's by at most this much per
  /// tick [N] (on top of what the hand's own motion changes), so a coarser or finer wall never kicks.
  double max_force_step_n = 0.05;
  /// Box tests one tick's level-change check and collision queries may do together [count]; 0 = no limit.
  /// Past it the proxy waits where the sweep is proven clear (anytime) and a level change waits. The
  /// scan of the boundary section is done even past it (QueryBudget), so a tick's box tests are at most
  /// this plus ContactOutput::query.section_box_tests.
  std::int32_t query_box_budget = kDefaultQueryBoxBudget;
  double velocity_cutoff_hz = 100;  ///< low-pass on the finite-difference handle velocity [Hz]
  ContactParams contact;
  ForceGuard guard;
  /// Walls (ContactSolver) or grooves (GrooveSolver). Fixed for the loop's life (a change of [haptics]
  /// render builds a new loop with the scene). In grooves mode a level change is always safe (no wall to
  /// cross), and the force-step limit at level and gains changes is the groove solver's own per-tick
  /// limit (groove.jump_step_n = max_force_step_n beyond what the hand's motion does), so the residual
  /// fade below is not added on top of it.
  RenderMode render = RenderMode::Walls;
  /// The groove field (grooves mode). apply_gains writes stiffness, max force and jump_step_n
  /// (= max_force_step_n) into it as into `contact`.
  GrooveParams groove;
};

/// The gains part of `p` (max_force_n from the solver's clamp, p.contact.max_force_n).
ServoGains gains_of(const ServoParams& p) noexcept;
/// Writes `g` into `p` (max_force_n into both the solver's and the guard's clamp; stiffness, max force and
/// max_force_step_n also into the groove params). Real-time safe.
void apply_gains(ServoParams& p, const ServoGains& g) noexcept;

/// Input of one tick.
struct ServoInput {
  DeviceSample sample;           ///< handle position [m] and status
  bool deadline_missed = false;  ///< the caller says this tick is late: the guard sends zero force
  /// False while the caller fades the force out (ServoStep's picture swap): a press then is not a
  /// deliberate push-through (ContactInput::press_counts). The loop also stops counting during its own ramp.
  bool press_counts = true;
};

/// Output of one tick.
struct ServoOutput {
  Vec2 force_n;  ///< force to write to the device [N] (after the guard)
  Vec2 handle_velocity_m_per_s;
  ContactOutput contact;  ///< proxy, state, constraints, events, query stats (budget_used: the whole tick's box tests)
  std::int32_t level =
      0;  ///< level id in use this tick (walls the proxy met): a level or a tolerance step (hk/constants.hpp)
  std::int32_t level_wanted = 0;  ///< level id asked for (policy or fixed); differs from `level` while a change waits
  bool level_changed = false;     ///< the level in use changed at the start of this tick
  TickResult result = TickResult::Ok;
};

/// The servo step for one scene: the guard, the level policy and the contact solver (walls or grooves) of one
/// scene, advanced by update() once a tick (ruckig-style: state in, force out). Construct at setup.
class SceneStep {
 public:
  /// `scene` must outlive the loop. Allocates (setup only).
  SceneStep(const Scene& scene, const ServoParams& params);
  /// Starts (or restarts) at the handle position: proxy placed there, force ramp from zero. Resets the
  /// solver in use (walls: ContactSolver, grooves: GrooveSolver), the walls' push-off charged to the tick's
  /// box-test budget (query_box_budget). Real-time safe: the servo calls it when it takes a picture and
  /// when a lost device comes back.
  void start(Vec2 handle_m) noexcept;
  /// Puts the proxy at the handle, free, its contact state forgotten (ContactSolver::reset at the level in
  /// use), without restarting the force ramp, the velocity filter or the level: called before update() on
  /// every tick the guided tour leads the handle through the air (app guided_tour.hpp), so the walls give
  /// no force then and are on again, on the handle's side, when it stops. Allocates nothing; walks the
  /// tree only within two skins of the handle, on the tick's box-test budget (query_box_budget).
  void relocate(Vec2 handle_m) noexcept { solver_.reset(handle_m, level_, params_.query_box_budget); }
  /// One servo tick: a function of (state, in, scene); no clock is read. A non-finite handle position
  /// gives zero force and NonFinite with the state kept. Real-time safe.
  TickResult update(const ServoInput& in, ServoOutput& out) noexcept;
  const ServoParams& params() const { return params_; }
  /// Fixes the level (automatic selection off). Takes effect at the next tick at which the proxy can move to
  /// it without crossing (see ContactSolver::level_change_is_safe). Real-time safe.
  void set_level(int level) noexcept {
    params_.level = level;
    params_.auto_level = false;
  }
  /// Turns automatic level selection from hand speed on or off (off: stays at the level in use). Real-time safe.
  void set_auto_level(bool on) noexcept;
  /// Real-time safe. New gains from the next update on. The solver uses them at once; the difference
  /// between the force the old gains gave at the last tick and what the new gains give fades at
  /// max_force_step_n per tick (the residual mechanism shared with level changes: the tick that takes the
  /// change already moves one step, so a difference of D [N] is gone after ceil(D / max_force_step_n)
  /// ticks); the guard's clamp (max force) moves towards the new value by at most max_force_step_n per
  /// tick, so lowering max force does not cut the force in one tick either. Gains equal to gains() change
  /// nothing. Before the first update after start() there is no force to keep: the gains simply apply.
  void set_gains(const ServoGains& g) noexcept;
  /// The gains in use (the targets: the force may still be fading towards them, see transition_active).
  /// Real-time safe.
  ServoGains gains() const noexcept { return gains_of(params_); }
  /// True while a gains or level change is still fading in (residual non-zero or the guard's clamp not
  /// yet at the new max force). False again from the tick on which the new gains' force law holds exactly.
  /// Real-time safe.
  bool transition_active() const noexcept;
  /// Level id in use (walls rendered): a level [0 = finest] or a tolerance step (hk/constants.hpp).
  int level() const noexcept { return level_; }
  std::int64_t ticks() const { return ticks_; }
  /// The contact solver (its proxy and boundary section), for display snapshots taken in the servo thread.
  /// In grooves mode it is not stepped: use section() for what the display shows.
  const ContactSolver& solver() const { return solver_; }
  /// The groove solver (stepped in grooves mode only).
  const GrooveSolver& groove() const { return groove_; }
  /// The boundary section of the solver in use (walls: the contact solver's; grooves: the groove solver's).
  const BoundarySection& section() const {
    return params_.render == RenderMode::Grooves ? groove_.section() : solver_.section();
  }

 private:
  ServoParams params_;
  // The cut masks and bounds (make_cut_walls), computed once and read by both solvers' sections; null unless
  // params_.steps == LevelSteps::Cuts. Declared before the solvers, which its initializer feeds.
  std::shared_ptr<const CutWalls> cuts_;
  ContactSolver solver_;
  GrooveSolver groove_;
  // The policy's ladder (levels, tolerance steps or cut steps): rung i is level id ladder_id_[i], with the scene's
  // error bound level_error_m_[i] [m] (non-decreasing); levels_ rungs. Declared before levels_ and policy_:
  // levels_'s initializer fills them, policy_'s reads them.
  int ladder_id_[LevelPolicy::kMaxLevels] = {};
  double level_error_m_[LevelPolicy::kMaxLevels] = {};
  double id_bound_m_[kLevelIds] =
      {};  // the scene's error bound at every level id [m] (to place an id not on the ladder)
  int levels_ = 1;
  // The rung for level id `id`: its own, or the coarsest whose bound is within the id's.
  int ladder_index(int id) const noexcept;
  LevelPolicy policy_;
  int level_ = 0;        // level in use
  Vec2 force_residual_;  // old level's (or gains') force minus the new one's, fading out at max_force_step_n per tick
                         // [N]
  double guard_max_force_n_ = 0.0;  // the guard's clamp in use, walking to params_.guard.max_force_n [N]
  bool gains_changed_ = false;  // set_gains since the last update: this tick's force difference goes to the residual
  Vec2 last_force_;             // force of the previous tick before the guard [N]
  Vec2 last_handle_;
  Vec2 velocity_;
  std::int64_t ticks_ = 0;
};

}  // namespace hk
