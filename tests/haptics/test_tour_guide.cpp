// The guided tour's force law as a pure step (haptics/tour_guide.hpp): a straight path through the air,
// followed by a handle on the target (the tour runs to its end, the outline begins once at its time, the
// force fades in and out) or held still (the clock stops, the tour ends Stopped after hold_s), the force
// never above its limit, the walls suspended only in the transit after the fade.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "haptics/tour_guide.hpp"

namespace hk {
namespace {

// 10 cm to the right in 1 s, then 0.5 s of outline 5 cm up (press 0.6 N to the left), at 1 ms points.
TourPath straight_path() {
  TourPath p;
  p.curve = 0;
  p.outline_start_s = 1.0;
  for (int i = 0; i <= 1500; ++i) {
    const double t = i * 0.001;
    TourPoint q;
    q.t_s = t;
    q.target_m = t <= 1.0 ? Vec2{0.1 * t, 0.0} : Vec2{0.1, 0.1 * (t - 1.0)};
    q.press_n = t <= 1.0 ? Vec2{} : Vec2{-0.6, 0.0};
    p.points.push_back(q);
  }
  return p;
}

TourInput input(Vec2 handle_m, const ContactOutput& contact) {
  TourInput in;
  in.handle_m = handle_m;
  in.contact = &contact;
  in.period_s = 0.001;
  return in;
}

TEST(TourGuide, AHandleOnTheTargetIsLedToTheEnd) {
  const TourPath path = straight_path();
  TourGuide g;
  g.start(path, {0.0, 0.0}, 0.001);
  const ContactOutput free_contact;
  TourOutput out;
  int outline_began = 0, ticks = 0;
  double t = 0.0;
  while (g.active() && ticks < 5000) {
    std::size_t cursor = 0;
    g.update(input(path.at(t, cursor).target_m, free_contact), out);
    outline_began += out.outline_began;
    if (out.outline_began) {
      EXPECT_NEAR(ticks * 0.001, path.outline_start_s, 0.0015) << "the outline begins at its time";
    }
    EXPECT_LE(length(out.guide_force_n), path.params.max_force_n + 1e-12);
    if (ticks == 0) {
      EXPECT_LE(length(out.guide_force_n), path.params.max_force_n / 50.0 + 1e-9) << "the force fades in";
    }
    t += 0.001;
    ++ticks;
  }
  EXPECT_FALSE(g.active());
  EXPECT_EQ(out.ended, TourPhase::Done);
  EXPECT_EQ(g.phase(), TourPhase::Done);
  EXPECT_EQ(outline_began, 1);
  // The path's 1.5 s, then the 50 ms fade-out.
  EXPECT_NEAR(ticks, 1500 + 50, 3);
  EXPECT_LT(length(out.guide_force_n), 0.6 / 40.0) << "faded out at the end";
}

TEST(TourGuide, AHandleHeldStillStopsTheTourAndTheClock) {
  const TourPath path = straight_path();
  TourGuide g;
  g.start(path, {0.0, 0.0}, 0.001);
  const ContactOutput free_contact;
  TourOutput out;
  int ticks = 0;
  double peak_n = 0.0;
  while (g.active() && ticks < 5000) {
    g.update(input({0.0, 0.0}, free_contact), out);
    peak_n = std::max(peak_n, length(out.guide_force_n));
    EXPECT_FALSE(out.outline_began) << "a held handle never reaches the outline";
    ++ticks;
  }
  EXPECT_EQ(out.ended, TourPhase::Stopped);
  EXPECT_NEAR(peak_n, path.params.max_force_n, 1e-9) << "the spring saturates at its limit, never beyond";
  // The clock runs while the spring is under its limit (4 mm of error), then the hold (0.5 s) and the fade.
  EXPECT_GT(ticks, 500);
  EXPECT_LT(ticks, 500 + 50 + 200);
}

// A handle pinned 5 mm off the target (the spring at its limit: the clock stops) that jitters ±1 mm every
// tick (2 m/s raw, ~30 mm/s low-passed at 5 Hz, above hold_speed: never "held still") is what a handle caught in a
// shape's tip does. The tour must still end: Stuck, stall_s (3 s) after the clock last moved, then the fade.
TEST(TourGuide, AHandleThatJittersWithoutProgressEndsTheTourStuckAfterTheStallTime) {
  const TourPath path = straight_path();
  TourGuide g;
  g.start(path, {0.0, 0.0}, 0.001);
  const ContactOutput free_contact;
  TourOutput out;
  int ticks = 0;
  while (g.active() && ticks < 20000) {
    const double jitter = (ticks % 2 == 0 ? 0.001 : -0.001);
    g.update(input({-0.005, jitter}, free_contact), out);
    EXPECT_LE(length(out.guide_force_n), path.params.max_force_n + 1e-12);
    ++ticks;
  }
  EXPECT_FALSE(g.active());
  EXPECT_EQ(out.ended, TourPhase::Stuck);
  EXPECT_EQ(g.phase(), TourPhase::Stuck);
  EXPECT_TRUE(tour_ended(g.phase()));
  // The clock never gains 0.25 s (the spring is at its limit from the first tick), so: stall_s, then the fade.
  const long stall = static_cast<long>(path.params.stall_s / 0.001);
  EXPECT_GE(ticks, stall);
  EXPECT_LE(ticks, stall + 50 + 2);
}

// A handle that keeps up only now and then (the clock gains a little, more than progress_min_s in every
// stall_s, but far slower than planned) still ends: Stuck once overrun_factor × the path's duration is up.
TEST(TourGuide, ATourThatCrawlsEndsStuckAtOneAndAHalfTimesItsPlannedDuration) {
  const TourPath path = straight_path();  // 1.5 s planned
  TourGuide g;
  g.start(path, {0.0, 0.0}, 0.001);
  const ContactOutput free_contact;
  TourOutput out;
  int ticks = 0;
  double t = 0.0;
  while (g.active() && ticks < 20000) {
    std::size_t cursor = 0;
    // On the target one tick in three (the clock runs), 5 mm behind it otherwise (the clock stops).
    const Vec2 target = path.at(t, cursor).target_m;
    const bool keep_up = ticks % 3 == 0;
    g.update(input(keep_up ? target : target - Vec2{0.005, 0.0}, free_contact), out);
    if (keep_up) t += 0.001;
    ++ticks;
  }
  EXPECT_EQ(out.ended, TourPhase::Stuck);
  // overrun_factor × the duration, but never sooner than stall_s (a short path still gets that long).
  const long overrun = std::max(static_cast<long>(path.params.stall_s / 0.001 + 0.5),
                                static_cast<long>(path.params.overrun_factor * path.duration_s() / 0.001 + 0.5));
  EXPECT_GE(ticks, overrun);
  EXPECT_LE(ticks, overrun + 50 + 2);
  EXPECT_LT(t, path.duration_s()) << "it ended before the path's end";
}

TEST(TourGuide, WallsAreSuspendedInTheTransitOnceFadedAndInTheOutlineOnlyForOtherShapes) {
  const TourPath path = straight_path();
  TourGuide g;
  const ContactOutput free_contact;
  EXPECT_FALSE(g.walls_suspended(free_contact)) << "no tour";
  g.start(path, {0.0, 0.0}, 0.001);
  TourOutput out;
  EXPECT_FALSE(g.walls_suspended(free_contact)) << "the walls fade out first";
  double t = 0.0;
  for (int k = 0; k < 49; ++k, t += 0.001) {
    std::size_t cursor = 0;
    g.update(input(path.at(t, cursor).target_m, free_contact), out);
    EXPECT_GT(out.walls_gain, 0.0);
  }
  std::size_t cursor = 0;
  g.update(input(path.at(t, cursor).target_m, free_contact), out);
  EXPECT_EQ(out.walls_gain, 0.0) << "faded out over fade_s";
  EXPECT_TRUE(g.walls_suspended(free_contact));
  while (g.phase() == TourPhase::Transit) {
    t += 0.001;
    cursor = 0;
    g.update(input(path.at(t, cursor).target_m, free_contact), out);
  }
  EXPECT_EQ(out.walls_gain, 0.0) << "the tick the outline begins was still the transit's";
  t += 0.001;
  cursor = 0;
  g.update(input(path.at(t, cursor).target_m, free_contact), out);
  EXPECT_EQ(out.walls_gain, 1.0) << "walls on in the outline";
  ContactOutput other;
  other.state = ContactState::Edge;
  other.constraint[0].curve = 3;
  EXPECT_TRUE(g.walls_suspended(other)) << "another shape's wall is let go of";
  ContactOutput toured = other;
  toured.constraint[0].curve = 0;
  EXPECT_FALSE(g.walls_suspended(toured));
  EXPECT_FALSE(g.walls_suspended(free_contact));
}

TEST(TourGuide, StopFadesTheForceOut) {
  const TourPath path = straight_path();
  TourGuide g;
  g.start(path, {0.0, 0.0}, 0.001);
  const ContactOutput free_contact;
  TourOutput out;
  for (int k = 0; k < 200; ++k) g.update(input({0.0, 0.0}, free_contact), out);
  const double before_n = length(out.guide_force_n);
  ASSERT_GT(before_n, 0.5);
  g.stop();
  int ticks = 0;
  double prev_n = before_n;
  while (g.active()) {
    g.update(input({0.0, 0.0}, free_contact), out);
    EXPECT_LE(length(out.guide_force_n), prev_n + 1e-12) << "fading out";
    prev_n = length(out.guide_force_n);
    ++ticks;
  }
  EXPECT_EQ(ticks, 50);
  EXPECT_EQ(out.ended, TourPhase::Stopped);
}

}  // namespace
}  // namespace hk
