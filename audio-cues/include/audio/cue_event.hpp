#pragma once
/// @file cue_event.hpp
/// What the servo loop tells the audio side (DESIGN.md "Data flow": haptic events → lock-free queue →
/// audio-cues). A plain 24-byte value: it crosses threads through SpscRing and is copied, never shared.
/// The audio module knows nothing of haptics' types; the app translates a servo tick into these.

#include <cstdint>

namespace hk::audio {

/// Kinds of cue. Each has its own earcon (earcons.hpp).
enum class CueKind : std::uint8_t {
  ContactBegin,   ///< the proxy touched a curve (free → edge or vertex); speed = approach speed
  ContactEnd,     ///< the proxy left the curve (contact → free)
  Slide,          ///< still sliding along an edge; speed = sliding speed of the proxy. Sent every few ticks
  VertexContact,  ///< the proxy is held in a concave corner (vertex contact)
  ConvexCorner,   ///< the proxy passed over a convex corner onto the next edge
  LevelFiner,     ///< the rendered resolution level became finer (level = the new level)
  LevelCoarser,   ///< the rendered resolution level became coarser (level = the new level)
  WorkspaceEdge,  ///< the handle reached the edge of the usable workspace
  TextBlock,      ///< the proxy entered a block of text on a document page (curve = the block's id)
  PopThrough,     ///< the visitor pushed through a wall on purpose (pressed over pop_force_n for pop_hold_s)
  TourStart,      ///< the guided tour starts tracing a shape's outline (curve = the shape)
  Shutter,        ///< the camera took the picture (sent by the window thread, AudioSystem::play)
};

/// Number of CueKind values.
inline constexpr int kCueKindCount = 12;

/// One cue. 24 bytes (checked below): small enough that a 4096-entry queue is 96 KiB.
struct CueEvent {
  std::int64_t tick = 0;       ///< servo tick index k; the cue belongs at t = k · period
  float speed_m_per_s = 0.0f;  ///< approach (ContactBegin) or sliding (Slide) speed [m/s]; 0 otherwise
  std::int32_t curve = -1;     ///< curve touched (its pitch); −1 when none
  std::int16_t level = 0;      ///< level in use (LevelFiner/LevelCoarser: the new one)
  CueKind kind = CueKind::ContactBegin;
};
static_assert(sizeof(CueEvent) == 24, "CueEvent is a hot queue entry: keep it 24 bytes");

/// Lower-case name of a kind ("contact_begin", ...), for logs and CSV files.
const char* cue_kind_name(CueKind kind);

}  // namespace hk::audio
