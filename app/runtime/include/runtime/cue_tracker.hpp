#pragma once
/// @file cue_tracker.hpp
/// Turns servo ticks into audio cues (DESIGN.md "Data flow": haptic events → lock-free queue →
/// audio-cues). Lives in the app because it is the one place that knows both haptics' and
/// audio-cues' types. Runs in the servo thread: no allocation, lock or throw.

#include <cstdint>

#include "audio/cue_event.hpp"
#include "haptics/scene.hpp"
#include "haptics/servo.hpp"

namespace hk::app {

/// Tuning of the tracker. Units in names.
struct CueTrackerParams {
  double period_s = 0.001;                    ///< servo period [s]
  int slide_every_ticks = 5;                  ///< a Slide cue every this many ticks of edge contact (200 Hz at 1 kHz)
  Vec2 workspace_half_extent_m{0.07, 0.045};  ///< half width and height of the usable rectangle [m]
  double edge_margin_m = 0.002;               ///< WorkspaceEdge when the handle comes this close to the border [m]
  /// ConvexCorner / VertexContact only at corners that turn at least this much [rad] (30°): a smooth curve
  /// is a chain of slightly convex vertices, and ticking at each would drown the corners that matter.
  double corner_min_turn_rad = 0.5235987755982988;
  /// The proxy leaves a text block only once it is this far outside its box [m], so resting on a box's
  /// border does not repeat the TextBlock cue.
  double text_block_margin_m = 0.001;
};

/// Per-tick cue extraction with the little state it needs (previous proxy, last level, edge latch).
class CueTracker {
 public:
  static constexpr int kMaxCuesPerTick = 6;

  explicit CueTracker(const CueTrackerParams& params) : p_(params) {}

  /// Cues of tick `tick` into out[0 .. return value). `level_in_use` is the level the servo renders.
  /// Rules: ContactBegin / ContactEnd from the solver's events (approach speed = handle speed), PopThrough in
  /// place of ContactEnd when the contact ended by a push-through (kEventPopThrough); a new
  /// ContactBegin when contact moves to another curve (its pitch changes); VertexContact on entering a
  /// concave corner; ConvexCorner when one is passed (both only at corners of corner_min_turn_rad or more); Slide with
  /// the proxy's mean speed over the last slide_every_ticks ticks of edge contact; LevelFiner / LevelCoarser when
  /// level_in_use changes; WorkspaceEdge when the handle reaches the margin (re-armed once it is 2 margins inside);
  /// TextBlock (curve = block id) when the proxy enters a text block set with set_text_blocks, from outside every block
  /// or from another (it has left one when it is text_block_margin_m outside its box).
  int update(std::int64_t tick, const ServoOutput& out, Vec2 handle_m, int level_in_use,
             audio::CueEvent* cues) noexcept;
  /// Forgets the state (a new scene or session).
  void reset() noexcept;
  /// The text blocks of the page in use [m] (flat array owned by the caller, alive while in use; null / 0:
  /// none). Real-time: stores the pointer only.
  void set_text_blocks(const Aabb* blocks, int count) noexcept {
    text_blocks_ = blocks;
    text_block_count_ = blocks ? count : 0;
    in_text_block_ = -1;
  }

 private:
  CueTrackerParams p_;
  bool have_prev_ = false;
  Vec2 prev_proxy_;
  int prev_curve_ = -1;
  int prev_level_ = -1;
  bool at_edge_ = false;
  double slide_path_m_ = 0;
  int slide_ticks_ = 0;
  const Aabb* text_blocks_ = nullptr;
  int text_block_count_ = 0;
  int in_text_block_ = -1;
};

}  // namespace hk::app
