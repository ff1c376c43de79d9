// Push-through: a wall gives way to a press of pop_force_n held for pop_hold_s, never to
// less (weaker, or shorter), the proxy crosses on exactly that tick, the force before the pop fades out over
// pop_release_s, and a push through two touching shapes or into a corner leaves the proxy off every wall.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "curves.hpp"
#include "haptics/contact.hpp"

using namespace hk;

namespace {

constexpr double kStiffness = 800.0;  // [N/m]
constexpr double kPeriod = 0.001;     // [s]

ContactParams pop_params(double pop_force_n = 3.0) {
  ContactParams p;
  p.stiffness_n_per_m = kStiffness;
  p.max_force_n = 10.0;  // above every press here: the spring is what the hand feels
  p.pop_force_n = pop_force_n;
  p.pop_hold_s = 0.3;
  p.pop_release_s = 0.02;
  p.period_s = kPeriod;
  return p;
}

/// One tick of the solver with the handle at h.
ContactOutput step(ContactSolver& s, Vec2 h, int level = 0) {
  ContactInput in;
  in.handle_m = h;
  in.level = level;
  ContactOutput out;
  s.update(in, out);
  return out;
}

/// A 4 cm square; the handle comes from outside (left) and presses `depth_m` into its left wall (x = −0.02).
struct LeftWall {
  Scene scene = Scene::build({test::square(0.02)}, 1);
  ContactSolver solver;
  explicit LeftWall(const ContactParams& p) : solver(scene, p) { solver.reset({-0.03, 0.0}, 0); }
  Vec2 pressed(double depth_m) const { return {-0.02 + depth_m, 0.0}; }
};

TEST(PopThrough, ALighterPressNeverGivesWay) {
  LeftWall w(pop_params());
  const double depth = 2.9 / kStiffness;  // 2.9 N: just under pop_force_n
  for (int k = 0; k < 3000; ++k) {
    const ContactOutput o = step(w.solver, w.pressed(depth));
    ASSERT_EQ(o.events & kEventPopThrough, 0u) << "tick " << k;
    ASSERT_LT(o.proxy_m.x, -0.02) << "the proxy stays outside";
  }
}

TEST(PopThrough, AShorterPressNeverGivesWay) {
  LeftWall w(pop_params());
  const double hard = 3.5 / kStiffness, light = 1.0 / kStiffness;
  // Ten presses of 3.5 N for 0.29 s, each followed by a 10 ms easing to 1 N: the hold never reaches 0.3 s.
  for (int round = 0; round < 10; ++round) {
    for (int k = 0; k < 290; ++k) ASSERT_EQ(step(w.solver, w.pressed(hard)).events & kEventPopThrough, 0u);
    for (int k = 0; k < 10; ++k) ASSERT_EQ(step(w.solver, w.pressed(light)).events & kEventPopThrough, 0u);
  }
  EXPECT_LT(w.solver.proxy().x, -0.02);
}

TEST(PopThrough, OffMeansNeverEvenForAVeryHardPress) {
  LeftWall w(pop_params(0.0));
  for (int k = 0; k < 3000; ++k) {
    const ContactOutput o = step(w.solver, w.pressed(0.012));  // 9.6 N
    ASSERT_EQ(o.events & kEventPopThrough, 0u);
    ASSERT_EQ(o.press_s, 0.0);
  }
  EXPECT_LT(w.solver.proxy().x, -0.02);
}

TEST(PopThrough, AHeldPressGivesWayOnceAtTheHoldTimeAndTheForceFadesOutOverTheReleaseTime) {
  LeftWall w(pop_params());
  const double depth = 3.2 / kStiffness;
  // Pressing 3.2 N: the press is counted from the first tick in contact; it is due after 300 ticks.
  int pop_tick = -1, pops = 0;
  Vec2 before_pop;
  for (int k = 0; k < 400; ++k) {
    const ContactOutput o = step(w.solver, w.pressed(depth));
    if (o.events & kEventPopThrough) {
      ++pops;
      pop_tick = k;
      break;
    }
    before_pop = o.force_n;
  }
  ASSERT_EQ(pops, 1);
  EXPECT_EQ(pop_tick, 300) << "ticks 0..299 count the 0.3 s press; the tick after it pops";
  EXPECT_NEAR(before_pop.x, -3.2, 1e-3);  // the wall pushed the hand back out (the proxy rests a skin outside)
  // The proxy crossed to the handle (inside the square, off the wall).
  EXPECT_GT(w.solver.proxy().x, -0.02);
  EXPECT_EQ(w.solver.state(), ContactState::Free);
  // The hand goes on into the square, free: the force is what is left of the pre-pop force, fading
  // linearly over 20 ticks (the pop tick keeps all of it, so there is no step), then zero.
  for (int i = 1; i <= 25; ++i) {
    const ContactOutput o = step(w.solver, {w.pressed(depth).x + 0.0001 * i, 0.0});
    const double expect = i >= 20 ? 0.0 : -before_pop.x * (20 - i) / 20.0;
    EXPECT_NEAR(-o.force_n.x, expect, 1e-9) << "tick " << i << " after the pop";
    EXPECT_EQ(o.events & kEventPopThrough, 0u);
  }
}

TEST(PopThrough, ThePressIsNotCountedWhileTheForceRampsIn) {
  LeftWall w(pop_params());
  for (int k = 0; k < 1000; ++k) {
    ContactInput in;
    in.handle_m = w.pressed(0.006);  // 4.8 N
    in.press_counts = false;         // the servo loop's start-up ramp
    ContactOutput o;
    w.solver.update(in, o);
    ASSERT_EQ(o.events & kEventPopThrough, 0u);
  }
  EXPECT_LT(w.solver.proxy().x, -0.02);
}

TEST(PopThrough, ThroughTheSharedEdgeOfTwoTouchingShapesTheProxyEndsOffEveryWall) {
  // Two 2 cm squares side by side, 0.2 mm apart (the two edges of a drawn line between two shapes).
  Polyline a, b;
  a.closed = b.closed = true;
  a.points_m = {{-0.0201, -0.01}, {-0.0001, -0.01}, {-0.0001, 0.01}, {-0.0201, 0.01}};
  b.points_m = {{0.0001, -0.01}, {0.0201, -0.01}, {0.0201, 0.01}, {0.0001, 0.01}};
  const Scene sc = Scene::build({a, b}, 1);
  ContactParams p = pop_params();
  p.max_force_n = 4.0;
  // The handle inside the left square presses right, through both edges, at every depth from 3.75 mm to
  // 8 mm and at several heights: wherever it pops, the proxy ends off every wall, and afterwards never
  // crosses one while the hand moves about.
  for (double depth : {0.00376, 0.0045, 0.006, 0.008}) {
    for (double y : {-0.009, 0.0, 0.0095}) {
      ContactSolver s(sc, p);
      s.reset({-0.01, y}, 0);
      const Vec2 h{-0.0001 + depth, y};
      bool popped = false;
      for (int k = 0; k < 400 && !popped; ++k) popped = (step(s, h).events & kEventPopThrough) != 0;
      ASSERT_TRUE(popped) << "depth " << depth << " y " << y;
      EXPECT_GT(test::brute_closest_distance(sc, s.proxy(), 0), p.skin_m) << "depth " << depth << " y " << y;
      Vec2 last = s.proxy();
      for (int k = 0; k < 200; ++k) {
        const ContactOutput o = step(s, {h.x + 0.00005 * std::sin(k * 0.1), y + 0.00005 * k});
        ASSERT_EQ(test::count_crossings(sc, last, o.proxy_m, 0), 0) << "tick " << k << " after the pop";
        last = o.proxy_m;
      }
    }
  }
}

TEST(PopThrough, IntoAConcaveCornerTheProxyEndsOffEveryWall) {
  // The handle inside a square presses diagonally into its top-right corner: vertex contact, then a pop.
  const Scene sc = Scene::build({test::square(0.02)}, 1);
  ContactParams p = pop_params();
  p.max_force_n = 4.0;
  for (double depth : {0.003, 0.004, 0.006}) {
    ContactSolver s(sc, p);
    s.reset({0.0, 0.0}, 0);
    bool vertex = false, popped = false;
    for (int k = 0; k < 600 && !popped; ++k) {
      const ContactOutput o = step(s, {0.02 + depth, 0.02 + depth});
      vertex = vertex || o.state == ContactState::Vertex;
      popped = (o.events & kEventPopThrough) != 0;
    }
    ASSERT_TRUE(vertex) << "the corner held the proxy first";
    ASSERT_TRUE(popped) << depth;
    EXPECT_GT(s.proxy().x, 0.02);
    EXPECT_GT(s.proxy().y, 0.02);
    EXPECT_GT(test::brute_closest_distance(sc, s.proxy(), 0), p.skin_m);
  }
}

}  // namespace
