#pragma once
/// @file servo_step.hpp
/// What the servo does each tick (DESIGN.md "Data flow", "Real-time rules"): a pure step from the device
/// sample to the force command, ServoStep::step. It holds no device and reads no clock, so it is
/// deterministic; ServoRunner (servo_runner.hpp) reads the device, calls it and writes the force, for the
/// kiosk's servo thread and for every headless run alike. The step swaps in a newly published picture,
/// applies the owner's requests, runs the picture in use's SceneStep, adds the guided tour's force,
/// pushes audio cues and fills the display state.
///
/// A device that comes back (the sample's status Ok again after Lost, Fault or Closed) gets its force back
/// gently: the picture in use restarts at the handle (SceneStep::start: proxy there, force ramped in from
/// zero over guard.ramp_s), so a hand that moved while the device was away is not kicked out of a wall.
///
/// A picture crosses threads as a SceneBundle built on another thread (the scene and a SceneStep sized for
/// it: all allocation happens there). publish() hands it over with one atomic exchange. The servo thread
/// first fades the old picture's force to zero, one force ramp step (max_force_n · period / ramp_s) a tick
/// at most, so a wall never vanishes under a pressing hand in one tick (no force: no wait; at the clamp: the
/// whole ramp time, guard.ramp_s); then it takes the new bundle, places the proxy where the
/// handle is (SceneStep::start: outside every curve, forces ramped in from zero by the force guard), and
/// passes the previous bundle back through a small ring, so it is freed outside the servo thread
/// (collect_retired()). Every force step of a swap is thus at most max_force_n · period / ramp_s.
///
/// Live gains: set_gains() hands stiffness, damping, max force and friction to the servo thread through a
/// triple buffer (latest value wins, no lock, no allocation). The servo thread takes them at its next tick
/// for the picture in use (SceneStep::set_gains: the force moves to the new law at no more than
/// max_force_step_n per tick) and gives them to every picture it takes afterwards, before starting it, so a
/// bundle built with older ServoParams cannot bring the old gains back.
///
/// The guided tour (guided_tour.hpp plans it): publish_tour() hands a planned TourPath to the servo thread
/// as publish() hands a picture (one atomic exchange; the path the servo let go of goes back through a ring
/// and is freed by collect_retired()). A TourGuide (haptics/tour_guide.hpp: the force law, the walls
/// suspended in the transit, the pocket-following, the tour's clock and ending) follows it; the command is
/// the walls' force (after the guard) plus the guide force, clamped to the guard's max_force_n. The tour
/// stops (force faded out) at cancel_tour() or when the picture changes, and at once when the device is not
/// Ok or the sample not finite. A TourStart cue marks the outline's start.

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "audio/cue_event.hpp"
#include "audio/spsc_ring.hpp"
#include "haptics/device.hpp"
#include "haptics/scene.hpp"
#include "haptics/servo.hpp"
#include "haptics/tour_guide.hpp"
#include "haptics/triple_buffer.hpp"
#include "runtime/cue_tracker.hpp"
#include "runtime/guided_tour.hpp"

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
  SceneStep loop;
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
  int level = 0;            ///< level in use
  bool auto_level = false;  ///< the level follows the hand's speed
  int scene_id = -1;        ///< SceneBundle::id in use, −1 before the first
  /// The device sample's status of this tick, so the display thread can announce a lost or returned device.
  DeviceStatus device_status = DeviceStatus::Closed;
  std::int64_t tick_compute_ns = 0;  ///< time of this tick's work [ns] (set by ServoThread)
  std::int64_t period_error_ns = 0;  ///< wake-up minus deadline of this tick [ns] (set by ServoThread)
  std::int64_t missed_deadlines = 0;
  /// |handle − proxy| while in contact, else 0 [m] (the operator panel's live plot: force against it).
  double penetration_m = 0.0;
  /// Wall stiffness the picture in use renders with [N/m] (0 before the first picture); the new value
  /// after a set_gains, from the tick that takes it. Fully in force once gains_transition is false.
  double stiffness_n_per_m = 0.0;
  /// A gains (or level) change is still fading in (SceneStep::transition_active).
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
class ServoStep {
 public:
  /// `cues` may be null (no sound). Holds no device: the caller reads it and writes the force (step()).
  ServoStep(const CueTrackerParams& cue_params, audio::SpscRing<audio::CueEvent>* cues);
  /// Frees every bundle. Call only when the servo thread has stopped.
  ~ServoStep();

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

  /// request_level(kAutoLevel): the level follows the hand's speed (SceneStep::set_auto_level).
  static constexpr int kAutoLevel = -2;
  /// Any thread: fix the level rendered from the next tick on (clamped per curve by the scene), or
  /// kAutoLevel. Applied once, to the picture in use; a picture published later brings its own ServoParams.
  void request_level(int level) noexcept { requested_level_.store(level, std::memory_order_relaxed); }

  /// Any thread but the servo's (one writer): new gains for the picture in use (from the next tick, faded
  /// in as SceneStep::set_gains describes) and for every picture taken afterwards (a bundle built before
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
  audio::SpscRing<SceneBundle*> retired_{16};  // servo → owner
  SceneBundle* current_ = nullptr;             // owned by the servo thread while running
  SceneBundle* to_retire_ = nullptr;           // waiting for room in retired_
  std::atomic<int> requested_level_{-1};
  struct GainsSlot {
    ServoGains gains;
    std::uint64_t seq = 0;  // 0: set_gains never called (pictures keep their own ServoParams)
  };
  TripleBuffer<GainsSlot> gains_in_;     // set_gains' thread → servo
  std::uint64_t gains_written_ = 0;      // writer's count of set_gains
  GainsSlot gains_;                      // servo thread: the gains last taken
  bool fading_ = false;                  // the old picture's force fades before a swap
  long fade_total_ = 0, fade_left_ = 0;  // [ticks]
  double fade_step_n_ = 0.0;             // the force may fall this much a tick while fading [N]
  TripleBuffer<ServoDisplayState> display_;
  ServoOutput out_;
  DeviceStatus last_status_ = DeviceStatus::Ok;  // the previous tick's sample status (a return restarts the picture)
  // The phases of step, in order (each documented where it is defined; tour_* below).
  void take_gains() noexcept;
  void swap_scene(Vec2 handle_m) noexcept;
  void apply_requests(const DeviceSample& sample, bool device_returned) noexcept;
  TickResult render_walls(ServoInput& in) noexcept;
  void add_guide_force() noexcept;
  void emit_cues(Vec2 handle_m) noexcept;
  void write_display(const DeviceSample& sample) noexcept;
  // The guided tour: the path handed over (atomics, ring) and the force law following it (TourGuide).
  void tour_before_update(const DeviceSample& sample) noexcept;
  void take_tour(const DeviceSample& sample) noexcept;
  void tour_after_update(const DeviceSample& sample) noexcept;
  void end_tour(TourPhase how) noexcept;
  std::atomic<TourPath*> tour_pending_{nullptr};
  std::atomic<bool> tour_cancel_{false};
  audio::SpscRing<TourPath*> tour_retired_{8};  // servo → owner
  TourPath* tour_ = nullptr;                    // running (or fading out)
  TourPath* tour_to_retire_ = nullptr;          // waiting for room in tour_retired_
  TourGuide guide_;                             // the force law following tour_
  TourPhase tour_phase_ = TourPhase::None;      // reported
  int tour_id_ = 0, tour_curve_ = -1;
  Vec2 guide_force_;  // this tick's guide force [N]
  std::int64_t tick_ = 0;
};

}  // namespace hk::app
