#pragma once
/// @file tour_guide.hpp
/// The guided tour's force law, a pure servo-rate step: TourGuide::update(input) -> guide force. A planned
/// TourPath (timed targets of the handle: transit through the air to a shape, onto it, round its outline,
/// off it; planned off the servo thread by app/guided_tour.hpp) is followed by a force-limited spring:
///
///   F_g = k_g·(target − handle) + b_g·(target velocity − handle velocity) + press,  |F_g| ≤ max_force_n
///
/// the handle's velocity low-passed at 30 Hz (encoder steps are noise to a damper); press: the path's force
/// onto the wall, turned along the inward normal of the toured shape's wall segment the proxy is on when the
/// handle touches it, low-passed at 10 Hz so it turns smoothly. The force fades in and out over fade_s.
/// During the transit the walls fade out over fade_s and are then suspended (walls_suspended: the caller
/// puts the proxy at the handle); from the outline on only the toured shape is a wall (a contact with other
/// shapes only is let go of the next tick). The path's clock runs only while |spring + press| stays below
/// max_force_n, so a held handle is not left behind by a target running away. Caught in a pocket of the
/// shape (on its wall, the spring at its limit, the handle still for trap_s) the guide follows the wall
/// (follow_force_n along it, plus the press) until the handle is within rejoin_m of the target. The tour ends
/// (force faded out over fade_s) at the path's end (Done), when the hand holds still against it (guide force
/// at ≥ 95 % of its limit, or the clock stopped, while the handle, its velocity low-passed at 5 Hz, moves
/// slower than hold_speed_m_per_s, for hold_s), or at stop() (Stopped). Whatever the handle does, a tour
/// always ends: one that makes no progress (its clock gains less than progress_min_s, and the handle comes no
/// nearer its target by progress_min_m, in stall_s of ticks), or that has run
/// overrun_factor times its planned duration, ends Stuck (a handle pinned in a tip, jittering too much to
/// count as held, would otherwise keep it going for good).
///
/// The spring and damper follow a minimum-jerk target (Flash & Hogan 1985, "The coordination of arm
/// movements", J. Neurosci. 5(7)); tuning in TourParams. Real-time: update, stop and walls_suspended
/// allocate nothing and cannot throw.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "haptics/contact.hpp"
#include "haptics/scene.hpp"
#include "haptics/servo.hpp"
#include "hk/vec2.hpp"

namespace hk {

/// One timed target of a tour: where the spring pulls the handle at time t_s after the tour was taken,
/// and the force that presses it against the wall there.
struct TourPoint {
  double t_s = 0.0;  ///< time since the tour started [s], increasing along the path
  Vec2 target_m;     ///< target of the guide spring [m], workspace frame
  Vec2 press_n;      ///< force towards the wall [N] where the handle touches no wall (zero in the transit)
};

/// Tuning of the guided tour. Units in names. Defaults: the shipped settings ([haptics] tour_max_force_n,
/// tour_speed_m_per_s) and the constants chosen here.
struct TourParams {
  double max_force_n = 1.2;     ///< |guide force| never exceeds this [N] ([haptics] tour_max_force_n)
  double speed_m_per_s = 0.03;  ///< speed along the outline [m/s] ([haptics] tour_speed_m_per_s)
  /// Guide spring [N/m]. 300 N/m with the 0.08 kg handle and 2 + 5 N·s/m of damping is a second-order
  /// follower with ω ≈ 61 rad/s and ζ ≈ 0.7 (no overshoot worth feeling); it lags ~0.7 mm at 3 cm/s and
  /// saturates at max_force_n after 4 mm of error.
  double stiffness_n_per_m = 300.0;
  double damping_n_s_per_m = 5.0;  ///< guide damping on the handle's velocity relative to the target's [N·s/m]
  double offset_m = 0.0015;        ///< start and end points lie this far off the curve on the handle's side [m]
  double track_offset_m = 0.001;   ///< the outline's targets lie this far off the curve on the handle's side [m]
  double press_force_n = 0.6;      ///< force pressing the handle onto the wall along the outline [N]
  double press_ramp_m = 0.002;  ///< the press grows in over this much of the outline's start and fades over its end [m]
  double sample_m = 0.0005;     ///< spacing of the outline's targets [m]
  double transit_sample_s = 0.005;  ///< spacing of the transit's targets [s]
  double min_transit_s = 0.2;       ///< the shortest transit [s] (a start right by the shape still eases in)
  double fade_s = 0.05;  ///< the guide force fades in and out over this [s]; walls fade out over it at the start
  double hold_speed_m_per_s = 0.005;  ///< "holding still": the handle slower than this...
  double hold_s = 0.5;                ///< ...with the guide force at its limit for this long stops the tour [s]
  double min_shape_length_m = 0.006;  ///< curves shorter than this (level 0) are specks, not toured [m]
  double plan_error_m = 0.0005;       ///< plan on the coarsest level whose error is below this [m]
  /// Caught in a pocket of the shape: the handle on the toured shape's wall, the spring at its limit and the
  /// handle not moving for trap_s, the guide pushes it along that wall in the outline's direction with
  /// follow_force_n (plus the press) until it is within rejoin_m of the waiting target or off the wall.
  double trap_s = 0.15;         ///< [s]
  double follow_force_n = 0.5;  ///< [N]; above the break-away friction of the press (μ_s 0.4 × 0.6 N)
  double rejoin_m = 0.002;      ///< [m]; above the track's offset from the wall plus the press's depth
  /// A tour that makes no progress ends Stuck: in the last stall_s of ticks its clock gained less than
  /// progress_min_s of path time (at 3 cm/s, 0.25 s of path is 7.5 mm of outline) and the handle came no
  /// nearer its waiting target by progress_min_m (being led out of a pocket along the wall is progress).
  /// 3 s: a relaxed hand led round silhouette_2 at the cut level rests 2-3 s in a pocket before the guide
  /// leads it out along the wall, and that tour ends Done.
  double stall_s = 3.0;           ///< [s] of ticks
  double progress_min_s = 0.25;   ///< [s] of path time
  double progress_min_m = 0.001;  ///< [m]
  /// A tour that has run this many times its planned duration (TourPath::duration_s), and at least stall_s,
  /// ends Stuck.
  double overrun_factor = 1.5;
};

/// The tour's phase (as the kiosk's servo reports it).
enum class TourPhase : std::uint8_t {
  None,     ///< no tour taken yet
  Transit,  ///< leading the handle to the shape (walls suspended)
  Outline,  ///< tracing the outline (walls on)
  Done,     ///< traced to the end and let go (the force has faded out)
  Stopped,  ///< stopped before the end: a key, the hand holding still, the device lost or a new picture
  Stuck,    ///< ended before the end because it made no progress (TourParams::stall_s, overrun_factor)
};

/// Whether a tour in `phase` has ended (Done, Stopped or Stuck).
constexpr bool tour_ended(TourPhase phase) noexcept {
  return phase == TourPhase::Done || phase == TourPhase::Stopped || phase == TourPhase::Stuck;
}

/// A planned tour. Built off the servo thread; the servo thread only reads it.
struct TourPath {
  int id = 0;        ///< caller's tour number
  int scene_id = 0;  ///< the caller's picture number the tour is for
  int curve = -1;    ///< the shape: scene curve index
  TourParams params;
  double outline_start_s = 0.0;  ///< end of the transit: walls are on from here [s]
  int direction = 1;  ///< the outline runs along increasing segment indices of the curve (+1) or decreasing (-1)
  std::vector<TourPoint> points;  ///< timed targets; points.front() is the handle at planning time, t = 0
  /// Time of the last point [s] (0 for an empty path).
  double duration_s() const noexcept { return points.empty() ? 0.0 : points.back().t_s; }
  /// The target and press at time t [s], linear between points, clamped to the ends. `cursor` is the
  /// index of the segment used last (start at 0); t must not decrease between calls with the same cursor.
  /// Real-time safe; amortised O(1). Requires a non-empty path.
  TourPoint at(double t_s, std::size_t& cursor) const noexcept;
};

/// What the guide needs of one tick, after the walls' step.
struct TourInput {
  Vec2 handle_m;                             ///< the handle [m]
  const ContactOutput* contact = nullptr;    ///< the walls' contact of this tick (proxy, constraints)
  const Scene* scene = nullptr;              ///< the picture the walls render (segments of the contact)
  TickResult walls_result = TickResult::Ok;  ///< the walls' step result (a late tick sends no guide force)
  double period_s = 0.001;                   ///< servo period [s]
};

/// What the guide gives back for one tick.
struct TourOutput {
  Vec2 guide_force_n;                 ///< the guide force [N] (added to the walls' by the caller)
  double walls_gain = 1.0;            ///< scale the walls' force by this (fading out in the transit)
  bool outline_began = false;         ///< the outline began this tick (the TourStart earcon)
  TourPhase ended = TourPhase::None;  ///< Done or Stopped when the tour's force has faded out this tick
};

/// Follows one TourPath at a time. Holds a pointer to the path while active; the path outlives it.
class TourGuide {
 public:
  /// Takes `path` (non-empty) with the handle at `handle_m` [m]: the transit begins, force fading in.
  void start(const TourPath& path, Vec2 handle_m, double period_s) noexcept;
  /// Ends the tour early (Stopped): its force fades out over fade_s. No-op when already ending or idle.
  void stop() noexcept;
  /// Ends the tour at once (no fade): the device is lost or its sample not finite. Then idle.
  void abandon() noexcept { path_ = nullptr; }
  /// True while a tour is followed (including its fade-out).
  bool active() const noexcept { return path_ != nullptr; }
  /// Transit or Outline while active; the last phase reached once idle.
  TourPhase phase() const noexcept { return phase_; }
  /// Before the walls' step: whether the walls must let go of the proxy this tick (put it at the handle):
  /// in the transit once they have faded out, and in the outline when `last` (the previous tick's contact)
  /// touches other shapes only.
  bool walls_suspended(const ContactOutput& last) const noexcept;
  /// One tick of the force law after the walls' step. Requires active().
  void update(const TourInput& in, TourOutput& out) noexcept;

 private:
  void track_handle(Vec2 h, double period_s) noexcept;
  TourPoint point_pressed(const TourInput& in) noexcept;
  void track_trap(const TourInput& in, Vec2 error_m, bool keeping_up) noexcept;
  Vec2 follow_force(const TourInput& in, Vec2 press_n) noexcept;
  void advance(bool keeping_up, double guide_len_n, double period_s, TourOutput& out) noexcept;
  bool stalled(double error_m) noexcept;
  void end(TourPhase how) noexcept;
  bool on_toured_wall(const ContactOutput& c) const noexcept;

  static constexpr double kVelocityHz = 30.0;  // low-pass of the guide's damping velocity [Hz]
  static constexpr double kHoldHz = 5.0;       // low-pass of the "held still" velocity [Hz]
  static constexpr double kPressHz = 10.0;     // low-pass of the press force's direction changes [Hz]
  const TourPath* path_ = nullptr;
  TourPhase phase_ = TourPhase::None;
  TourPhase ending_ = TourPhase::None;  // Done / Stopped while the force fades out
  double t_s_ = 0.0;                    // the path's clock [s]
  std::size_t cursor_ = 0;
  long ticks_ = 0;                  // ticks since the tour was taken
  long fade_ticks_ = 1;             // fade_s in ticks
  long fade_left_ = 0;              // while ending: ticks of fade left
  long hold_ticks_ = 0;             // consecutive ticks "held still against it"
  long stall_ticks_ = 1;            // stall_s in ticks
  long rendered_ticks_ = 0;         // ticks since the tour was taken whose walls' step rendered
  long progress_tick_ = 0;          // rendered_ticks_ when the clock last gained progress_min_s
  double progress_t_s_ = 0.0;       // the clock then [s]
  double progress_error_m_ = 0.0;   // the handle's distance to its target then [m]
  long overrun_ticks_ = 0;          // overrun_factor × the planned duration, in ticks
  Vec2 prev_handle_, prev_target_;  // last tick's handle and target [m]
  Vec2 velocity_, hold_velocity_;   // the handle's velocity, low-passed [m/s]
  Vec2 press_;                      // the press force, low-passed [N]
  bool following_ = false;          // caught in a pocket: following the wall (track_trap)
  long trap_ticks_ = 0;             // consecutive ticks caught on the shape's wall, still
  Vec2 follow_dir_;                 // the wall's direction while following (unit)
};

}  // namespace hk
