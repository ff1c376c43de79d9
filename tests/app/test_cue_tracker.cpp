// Servo ticks → audio cues: the rules of CueTracker on hand-made tick outputs.
#include <gtest/gtest.h>

#include <vector>

#include "runtime/cue_tracker.hpp"

namespace hk::app {
namespace {

using audio::CueEvent;
using audio::CueKind;

struct CueRun {
  CueTracker tracker;
  std::vector<CueEvent> cues;
  std::int64_t tick = 0;
  explicit CueRun(const CueTrackerParams& p = {}) : tracker(p) {}
  void step(ContactState state, int curve, Vec2 proxy, std::uint32_t events = 0, Vec2 handle = {0, 0}, int level = 1,
            Vec2 velocity = {0, 0}, double turn_rad = 0.0) {
    ServoOutput so;
    so.contact.corner_turn_rad = turn_rad;
    so.contact.state = state;
    so.contact.constraint[0].curve = curve;
    so.contact.proxy_m = proxy;
    so.contact.events = events;
    so.handle_velocity_m_per_s = velocity;
    CueEvent out[CueTracker::kMaxCuesPerTick];
    const int n = tracker.update(tick++, so, handle, level, out);
    cues.insert(cues.end(), out, out + n);
  }
  int count(CueKind k) const {
    int n = 0;
    for (const CueEvent& e : cues) n += e.kind == k;
    return n;
  }
};

TEST(CueTracker, ContactBeginAndEndCarryCurveTickAndSpeed) {
  CueRun r;
  r.step(ContactState::Free, -1, {0, 0});
  r.step(ContactState::Edge, 3, {0, 0}, kEventContactBegin, {0, 0}, 1, {0.3, 0.4});
  ASSERT_EQ(r.cues.size(), 1u);
  EXPECT_EQ(r.cues[0].kind, CueKind::ContactBegin);
  EXPECT_EQ(r.cues[0].tick, 1);
  EXPECT_EQ(r.cues[0].curve, 3);
  EXPECT_FLOAT_EQ(r.cues[0].speed_m_per_s, 0.5f);
  r.step(ContactState::Free, -1, {0, 0}, kEventContactEnd);
  ASSERT_EQ(r.cues.size(), 2u);
  EXPECT_EQ(r.cues[1].kind, CueKind::ContactEnd);
  EXPECT_EQ(r.cues[1].curve, 3) << "the end sounds at the pitch of the curve that was left";
}

TEST(CueTracker, APushThroughSoundsItsOwnCueInsteadOfTheRelease) {
  CueRun r;
  r.step(ContactState::Edge, 4, {0, 0}, kEventContactBegin);
  r.step(ContactState::Free, -1, {0, 0}, kEventContactEnd | kEventPopThrough);
  ASSERT_EQ(r.cues.size(), 2u);
  EXPECT_EQ(r.cues[1].kind, CueKind::PopThrough);
  EXPECT_EQ(r.cues[1].curve, 4) << "at the pitch of the wall pushed through";
  EXPECT_EQ(r.count(CueKind::ContactEnd), 0);
}

TEST(CueTracker, MovingOntoAnotherCurveSoundsItsPitch) {
  CueRun r;
  r.step(ContactState::Edge, 1, {0, 0}, kEventContactBegin);
  r.step(ContactState::Vertex, 2, {0, 0}, kEventVertexBegin, {0, 0}, 1, {0, 0}, 1.2);
  EXPECT_EQ(r.count(CueKind::ContactBegin), 2);
  EXPECT_EQ(r.cues.back().kind, CueKind::VertexContact);
  EXPECT_EQ(r.cues[1].curve, 2);
}

TEST(CueTracker, SlideCuesEveryFiveTicksWithTheProxySpeed) {
  CueTrackerParams p;
  p.period_s = 0.001;
  p.slide_every_ticks = 5;
  CueRun r(p);
  r.step(ContactState::Edge, 0, {0, 0}, kEventContactBegin);
  for (int k = 1; k <= 20; ++k) r.step(ContactState::Edge, 0, {0.00005 * k, 0});  // 0.05 m/s
  ASSERT_EQ(r.count(CueKind::Slide), 4);
  for (const CueEvent& e : r.cues) {
    if (e.kind == CueKind::Slide) {
      EXPECT_NEAR(e.speed_m_per_s, 0.05, 1e-6);
    }
  }
  // Vertex contact is not sliding.
  const int before = r.count(CueKind::Slide);
  for (int k = 0; k < 20; ++k) r.step(ContactState::Vertex, 0, {0.001 * k, 0});
  EXPECT_EQ(r.count(CueKind::Slide), before);
}

TEST(CueTracker, LevelChangesAndCorners) {
  CueRun r;
  r.step(ContactState::Free, -1, {0, 0}, 0, {0, 0}, 2);
  r.step(ContactState::Free, -1, {0, 0}, 0, {0, 0}, 1);
  r.step(ContactState::Free, -1, {0, 0}, 0, {0, 0}, 3);
  r.step(ContactState::Edge, 0, {0, 0}, kEventContactBegin | kEventConvexCorner, {0, 0}, 3, {0, 0}, 0.6);
  ASSERT_EQ(r.cues.size(), 4u);
  EXPECT_EQ(r.cues[0].kind, CueKind::LevelFiner);
  EXPECT_EQ(r.cues[0].level, 1);
  EXPECT_EQ(r.cues[1].kind, CueKind::LevelCoarser);
  EXPECT_EQ(r.cues[1].level, 3);
  EXPECT_EQ(r.cues[3].kind, CueKind::ConvexCorner);
}

TEST(CueTracker, OnlySharpCornersTick) {
  CueTrackerParams p;
  p.corner_min_turn_rad = 0.5;
  CueRun r(p);
  r.step(ContactState::Edge, 0, {0, 0}, kEventContactBegin);
  r.step(ContactState::Edge, 0, {0, 0}, kEventConvexCorner, {0, 0}, 1, {0, 0}, 0.1);  // a vertex of a smooth curve
  r.step(ContactState::Vertex, 0, {0, 0}, kEventVertexBegin, {0, 0}, 1, {0, 0}, 0.2);
  EXPECT_EQ(r.count(CueKind::ConvexCorner) + r.count(CueKind::VertexContact), 0);
  r.step(ContactState::Edge, 0, {0, 0}, kEventConvexCorner, {0, 0}, 1, {0, 0}, 0.5);
  r.step(ContactState::Vertex, 0, {0, 0}, kEventVertexBegin, {0, 0}, 1, {0, 0}, 1.5);
  EXPECT_EQ(r.count(CueKind::ConvexCorner), 1);
  EXPECT_EQ(r.count(CueKind::VertexContact), 1);
}

TEST(CueTracker, WorkspaceEdgeOnceUntilTheHandComesBack) {
  CueTrackerParams p;
  p.workspace_half_extent_m = {0.07, 0.045};
  p.edge_margin_m = 0.002;
  CueRun r(p);
  for (double x : {0.0, 0.067, 0.069, 0.0685, 0.069, 0.067, 0.0665, 0.0, 0.069})
    r.step(ContactState::Free, -1, {0, 0}, 0, {x, 0});
  EXPECT_EQ(r.count(CueKind::WorkspaceEdge), 2) << "one at the first approach, one after coming back in by 2 margins";
  r.step(ContactState::Free, -1, {0, 0}, 0, {0, -0.0449});
  EXPECT_EQ(r.count(CueKind::WorkspaceEdge), 2) << "still latched";
}

// A chime when the proxy enters a block of text, once per entry, not on its border.
TEST(CueTracker, TextBlockOnEnteringEachBlockOnce) {
  CueRun r;
  const Aabb blocks[2] = {{{0.0, 0.0}, {0.02, 0.01}}, {{0.03, 0.0}, {0.05, 0.01}}};
  r.tracker.set_text_blocks(blocks, 2);
  r.step(ContactState::Free, -1, {-0.01, 0.005});
  EXPECT_EQ(r.count(CueKind::TextBlock), 0);
  r.step(ContactState::Free, -1, {0.001, 0.005});
  ASSERT_EQ(r.count(CueKind::TextBlock), 1);
  EXPECT_EQ(r.cues.back().curve, 0) << "curve carries the block's id";
  r.step(ContactState::Free, -1, {0.010, 0.005});
  r.step(ContactState::Free, -1, {0.0205, 0.005});  // 0.5 mm outside: within the 1 mm margin, still in
  r.step(ContactState::Free, -1, {0.019, 0.005});
  EXPECT_EQ(r.count(CueKind::TextBlock), 1) << "moving inside or along the border does not repeat it";
  r.step(ContactState::Free, -1, {0.025, 0.005});  // 5 mm outside: left
  r.step(ContactState::Free, -1, {0.019, 0.005});
  EXPECT_EQ(r.count(CueKind::TextBlock), 2) << "entering again is a new cue";
  r.step(ContactState::Free, -1, {0.031, 0.005});
  ASSERT_EQ(r.count(CueKind::TextBlock), 3);
  EXPECT_EQ(r.cues.back().curve, 1) << "another block";
  r.tracker.set_text_blocks(nullptr, 0);
  r.step(ContactState::Free, -1, {0.001, 0.005});
  EXPECT_EQ(r.count(CueKind::TextBlock), 3) << "a picture has no text blocks";
}

}  // namespace
}  // namespace hk::app
