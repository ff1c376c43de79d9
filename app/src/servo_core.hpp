#pragma once
/// @file servo_core.hpp
/// What the kiosk's servo thread does each tick (issue 5, item 2; issue 13, item 5; DESIGN.md "Data flow",
/// "Real-time rules"): a pure step from the device sample to the force command. The caller reads the
/// device, calls step(), writes the command's force: `sample = device.read(); core.step(sample, late, cmd);
/// device.write_force(cmd.force_n);`. The step swaps in a newly published picture, runs the servo loop,
/// pushes audio cues and fills the display state. It holds no device, reads no clock and is deterministic,
/// so tests drive it tick by tick; ServoThread (servo_thread.hpp) calls it on time.
///
/// A device that comes back (the sample's status Ok again after Lost, Fault or Closed) gets its force back
/// gently: the picture in use restarts at the handle (ServoLoop::start: proxy there, force ramped in from
/// zero over guard.ramp_s), so a hand that moved while the device was away is not kicked out of a wall.
///
/// A picture crosses threads as a SceneBundle built on another thread (the scene and a ServoLoop sized for
/// it: all allocation happens there). publish() hands it over with one atomic exchange. The servo thread
/// first fades the old picture's force to zero over the force ramp time (guard.ramp_s), so a wall never
/// vanishes under a pressing hand in one tick; then it takes the new bundle, places the proxy where the
/// handle is (ServoLoop::start: outside every curve, forces ramped in from zero by the force guard), and
/// passes the previous bundle back through a small ring, so it is freed outside the servo thread
/// (collect_retired()). Every force step of a swap is thus at most max_force_n · period / ramp_s.
///
/// Live gains (issue 12, item 4): set_gains() hands stiffness, damping, max force and friction to the servo
/// thread through a triple buffer (latest value wins, no lock, no allocation). The servo thread takes them
/// at its next tick for the picture in use (ServoLoop::set_gains: the force moves to the new law at no more
/// than max_force_step_n per tick) and gives them to every picture it takes afterwards, before starting it,
/// so a bundle built with older ServoParams cannot bring the old gains back.
///
/// The guided tour (issue 14, item 3; guided_tour.hpp): publish_tour() hands a planned TourPath to the
/// servo thread as publish() hands a picture (one atomic exchange; the path the servo let go of goes back
/// through a ring and is freed by collect_retired()). Each tick of a tour the target is read off the path
/// and the guide force is F_g = k_g·(target − handle) + b_g·(target velocity − handle velocity) + press
/// (the handle's velocity low-passed at 30 Hz: encoder steps are noise to a damper; press: the path's force
/// onto the wall along the outline, turned along the inward normal of the wall segment the handle touches
/// when it touches the shape, low-passed at 10 Hz so it turns smoothly), clamped in length to TourParams::max_force_n; it fades in and out over fade_s. The command is the walls' force (after the
/// guard) plus F_g, clamped to the guard's max_force_n. During the transit the walls are suspended: they
/// fade out over fade_s, then the proxy is put at the handle every tick (ServoLoop::relocate); from the
/// outline on the toured shape is a wall, and a contact with other shapes only is let go of at the next
/// tick (relocate again: one tick's depth, a few hundredths of a newton), so a neighbouring outline never
/// holds the handle back. The path's clock runs only while |spring + press| stays below max_force_n, so
/// a held handle is not left behind by a target running away; the tour stops (force faded out)
/// at cancel_tour(), when the hand holds still against it (guide force at ≥ 95 % of its limit, or the
/// clock stopped, while the handle, its velocity low-passed at 5 Hz, moves slower than
/// hold_speed_m_per_s, for hold_s), when the device is not Ok or the sample not
/// finite (at once), or when the picture changes. A TourStart cue marks the outline's start.

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "audio/cue_event.hpp"
#include "audio/spsc_ring.hpp"
#include "cue_tracker.hpp"
#include "guided_tour.hpp"
#include "haptics/device.hpp"
#include "haptics/scene.hpp"
#include "haptics/servo.hpp"
#include "haptics/triple_buffer.hpp"

namespace hk::app {

/// A picture ready for the servo thread: its scene and a servo loop sized for it. Build on any thread
/// but the servo's (allocates).
struct SceneBundle {
  /// Owns `s` (the kiosk's pictures).
  SceneBundle(std::unique_ptr<Scene> s, const ServoParams& params) : scene(std::move(s)), loop(*scene, params) {}
  /// Shares `s`: a headless run borrows its caller's scene with a non-owning pointer
  /// (std::shared_ptr's aliasing constructor), which must outlive the bundle.
  SceneBundle(std::shared_ptr<const Scene> s, const ServoParams& params) : scene(std::move(s)), loop(*scene, params) {}
  std::shared_ptr<const Scene> scene;
  ServoLoop loop;
  int id = 0;  ///< caller's picture number (shown in the display state)
  /// Text blocks of a document page [m] (TextBlock cues, CueTracker::set_text_blocks); empty for a picture.
  std::vector<Aabb> text_blocks_m;
};

/// The servo thread's state of one tick, for the display (latest value wins). ~1.1 KiB, of which the tick
/// copies only the section entries in use.
struct ServoDisplayState {
  std::int64_t tick = 0;
  Vec2 handle_m, proxy_m, force_n;
  ContactState state = ContactState::Free;
  int curve = -1;
  int level = 0;                   ///< level in use
  bool auto_level = false;         ///< the level follows the hand's speed
  int scene_id = -1;               ///< SceneBundle::id in use, −1 before the first
  /// The device sample's status of this tick, so the display thread can announce a lost or returned device.
  DeviceStatus device_status = DeviceStatus::Closed;
  std::int64_t tick_compute_ns = 0;///< time of this tick's work [ns] (set by ServoThread)
  std::int64_t period_error_ns = 0;///< wake-up minus deadline of this tick [ns] (set by ServoThread)
  std::int64_t missed_deadlines = 0;
  /// |handle − proxy| while in contact, else 0 [m] (the operator panel's live plot: force against it).
  double penetration_m = 0.0;
  /// Wall stiffness the picture in use renders with [N/m] (0 before the first picture); the new value
  /// after a set_gains, from the tick that takes it. Fully in force once gains_transition is false.
  double stiffness_n_per_m = 0.0;
  /// A gains (or level) change is still fading in (ServoLoop::transition_active).
  bool gains_transition = false;
  /// The guided tour: phase, its path's id and shape (TourPath::id, curve; −1 / 0 before the first), and
  /// the guide force of this tick [N] (included in force_n; zero without a tour).
  TourPhase tour_phase = TourPhase::None;
  int tour_id = 0;
  int tour_curve = -1;
  Vec2 guide_force_n;
  /// The boundary section (seed §3): the first kMaxSection node ids of the collision tree's frontier.
  static constexpr int kMaxSection = 256;
  std::int32_t section_count = 0;  ///< entries in the section (may exceed kMaxSection; only those are copied)
  std::uint32_t section[kMaxSection];
};

/// What one step asks the caller to send to the device.
struct ServoCommand {
  Vec2 force_n;  ///< force to write to the device this tick [N], workspace frame (after the force guard)
};

/// Per-tick work of the servo thread. Methods marked real-time are called by the servo thread only.
class ServoCore {
 public:
  /// `cues` may be null (no sound). Holds no device: the caller reads it and writes the force (step()).
  ServoCore(const CueTrackerParams& cue_params, audio::SpscRing<audio::CueEvent>* cues);
  /// Frees every bundle. Call only when the servo thread has stopped.
  ~ServoCore();

  /// One thread but the servo's (the owner): hands `bundle` to the servo thread (taken at its next tick).
  /// A bundle published before and not yet taken is freed here (the servo thread never saw it).
  void publish(std::unique_ptr<SceneBundle> bundle);
  /// Any thread but the servo's (one caller): frees bundles and tour paths the servo thread has let go of.
  /// Returns how many bundles.
  int collect_retired();

  /// The owner's thread: hands a planned tour to the servo thread. It is taken at the first tick with no
  /// tour running (a running one is let go of first: cancel_tour()) and no picture being swapped in, and
  /// only for the picture in use (TourPath::scene_id == SceneBundle::id; else it is dropped, reported
  /// Stopped). A path published before
  /// and not yet taken is freed here. `path` must be non-empty.
  void publish_tour(std::unique_ptr<TourPath> path);
  /// Any thread: stops the running tour at the next tick (its force fades out over fade_s; then reported
  /// Stopped). Nothing happens without one.
  void cancel_tour() noexcept { tour_cancel_.store(true, std::memory_order_release); }
  /// Servo thread (or when stopped): the guide force of the last tick [N] (zero without a tour).
  Vec2 last_guide_force() const noexcept { return guide_force_; }

  /// request_level(kAutoLevel): the level follows the hand's speed (ServoLoop::set_auto_level).
  static constexpr int kAutoLevel = -2;
  /// Any thread: fix the level rendered from the next tick on (clamped per curve by the scene), or
  /// kAutoLevel. Applied once, to the picture in use; a picture published later brings its own ServoParams.
  void request_level(int level) noexcept { requested_level_.store(level, std::memory_order_relaxed); }

  /// Any thread but the servo's (one writer): new gains for the picture in use (from the next tick, faded
  /// in as ServoLoop::set_gains describes) and for every picture taken afterwards (a bundle built before
  /// the change does not bring the old gains back). Lock-free: a triple buffer; nothing is allocated on
  /// either side.
  void set_gains(const ServoGains& g) noexcept;

  /// Real-time: one tick from the device sample `sample` (handle [m], status) to the command `out` (force
  /// [N] to write to the device). `deadline_missed` zeroes the force (the force guard). Returns the tick's
  /// result (TickResult::Ok before the first picture). No clock, no device, no allocation, lock, throw, I/O.
  TickResult step(const DeviceSample& sample, bool deadline_missed, ServoCommand& out) noexcept;

  /// Real-time (servo thread): the display slot's back buffer, for ServoThread to add timing before publishing.
  ServoDisplayState& display_back() noexcept { return display_.back(); }
  void publish_display() noexcept { display_.publish(); }
  /// Display thread: the newest state.
  const ServoDisplayState& display() noexcept { return display_.read(); }

  /// Servo thread (or when stopped): the last tick's output.
  const ServoOutput& last_output() const noexcept { return out_; }
  std::int64_t ticks() const noexcept { return tick_; }

 private:
  CueTracker tracker_;
  audio::SpscRing<audio::CueEvent>* cues_;
  std::atomic<SceneBundle*> pending_{nullptr};
  audio::SpscRing<SceneBundle*> retired_{16};          // servo → owner
  SceneBundle* current_ = nullptr;                     // owned by the servo thread while running
  SceneBundle* to_retire_ = nullptr;                   // waiting for room in retired_
  std::atomic<int> requested_level_{-1};
  struct GainsSlot {
    ServoGains gains;
    std::uint64_t seq = 0;  // 0: set_gains never called (pictures keep their own ServoParams)
  };
  TripleBuffer<GainsSlot> gains_in_;                   // set_gains' thread → servo
  std::uint64_t gains_written_ = 0;                    // writer's count of set_gains
  GainsSlot gains_;                                    // servo thread: the gains last taken
  bool fading_ = false;                                // the old picture's force fades before a swap
  long fade_total_ = 0, fade_left_ = 0;                // [ticks]
  TripleBuffer<ServoDisplayState> display_;
  ServoOutput out_;
  DeviceStatus last_status_ = DeviceStatus::Ok;        // the previous tick's sample status (a return restarts the picture)
  // The phases of step, in order (each documented where it is defined; tour_* below).
  void take_gains() noexcept;
  void swap_scene(Vec2 handle_m) noexcept;
  void apply_requests(const DeviceSample& sample, bool device_returned) noexcept;
  TickResult render_walls(ServoInput& in) noexcept;
  void add_guide_force() noexcept;
  void emit_cues(Vec2 handle_m) noexcept;
  void write_display(const DeviceSample& sample) noexcept;
  // The guided tour (servo thread but the atomics and the ring).
  void tour_before_update(const DeviceSample& sample) noexcept;
  void tour_after_update(const DeviceSample& sample) noexcept;
  void track_tour_handle(Vec2 h, double period_s) noexcept;
  TourPoint tour_point_pressed(double period_s) noexcept;
  void advance_tour(bool keeping_up, double guide_len_n, double period_s) noexcept;
  void track_trap(Vec2 error_m, bool keeping_up, double period_s) noexcept;
  Vec2 follow_force(Vec2 press_n) noexcept;
  void end_tour(TourPhase how) noexcept;
  std::atomic<TourPath*> tour_pending_{nullptr};
  std::atomic<bool> tour_cancel_{false};
  audio::SpscRing<TourPath*> tour_retired_{8};         // servo → owner
  TourPath* tour_ = nullptr;                           // running (or fading out)
  TourPath* tour_to_retire_ = nullptr;                 // waiting for room in tour_retired_
  TourPhase tour_phase_ = TourPhase::None;             // reported
  TourPhase tour_ending_ = TourPhase::None;            // Done / Stopped while the force fades out
  int tour_id_ = 0, tour_curve_ = -1;
  double tour_t_s_ = 0.0;                              // the path's clock [s]
  std::size_t tour_cursor_ = 0;
  long tour_ticks_ = 0;                                // ticks since the tour was taken
  long tour_fade_ticks_ = 1;                           // fade_s in ticks
  long tour_fade_left_ = 0;                            // while ending: ticks of fade left
  long tour_hold_ticks_ = 0;                           // consecutive ticks "held still against it"
  Vec2 guide_force_;                                   // this tick's guide force [N]
  Vec2 tour_prev_handle_, tour_prev_target_;           // last tick's handle and target [m]
  Vec2 tour_velocity_, tour_hold_velocity_;            // the handle's velocity, low-passed [m/s]
  static constexpr double kTourVelocityHz = 30.0;      // low-pass of the guide's damping velocity [Hz]
  static constexpr double kHoldVelocityHz = 5.0;       // low-pass of the "held still" velocity [Hz]
  static constexpr double kPressHz = 10.0;             // low-pass of the press force's direction changes [Hz]
  Vec2 tour_press_;                                    // the press force, low-passed [N]
  bool tour_following_ = false;                        // caught in a pocket: following the wall (track_trap)
  long tour_trap_ticks_ = 0;                           // consecutive ticks caught on the shape's wall, still
  Vec2 tour_follow_dir_;                               // the wall's direction while following (unit)
  std::int64_t tick_ = 0;
};

}  // namespace hk::app
