// Gains changed live under a pressing hand (SceneStep level): stiffness, damping, max
// force and friction take effect from the next tick, yet the force never moves by more than the configured
// step per tick (plus what the hand's own motion does to the wall), and it ends exactly on the new force
// law (golden values from F = k · penetration, Coulomb's μ_d · F_n, damping b · v), after the number of
// ticks the step limit implies.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "curves.hpp"
#include "haptics/servo.hpp"

using namespace hk;

namespace {

constexpr double kSkin = ContactParams{}.skin_m;  // the proxy rests this far above the wall's line [m]
constexpr double kStep = 0.05;                    // max_force_step_n [N]
constexpr double kTol = 1e-12;                    // rounding allowance on a step [N]

ServoParams params(double k = 800.0) {
  ServoParams p;
  p.level = 0;
  p.auto_level = false;
  p.max_force_step_n = kStep;
  p.query_box_budget = 0;
  p.contact.stiffness_n_per_m = k;
  p.contact.max_force_n = 3.5;
  p.guard.max_force_n = 3.5;
  return p;
}

/// A long straight wall along y = 0; the hand comes from above (y > 0) and presses down into it.
Scene straight_wall() {
  Polyline wall;
  wall.points_m = {{-0.06, 0.0}, {0.06, 0.0}};
  return Scene::build({wall}, 2);
}

/// The handle where the penetration |handle − proxy| is `depth` (the proxy rests a skin above the line).
Vec2 pressed(double x, double depth) { return {x, kSkin - depth}; }

/// A servo loop over `scene`, driven by handle positions one tick at a time; every output kept.
struct Rig {
  Scene scene;
  SceneStep loop;
  ServoOutput out;
  std::vector<Vec2> forces, handles, proxies;

  explicit Rig(const ServoParams& p, Scene sc = straight_wall()) : scene(std::move(sc)), loop(scene, p) {}

  Vec2 tick(Vec2 h) {
    ServoInput in;
    in.sample.handle_m = h;
    in.sample.status = DeviceStatus::Ok;
    EXPECT_EQ(loop.update(in, out), TickResult::Ok);
    forces.push_back(out.force_n);
    handles.push_back(h);
    proxies.push_back(out.contact.proxy_m);
    return out.force_n;
  }
  /// From 1 cm above the wall down to `to` in 200 ticks, then held there until the start-up ramp is over.
  void press(Vec2 to) {
    const Vec2 from{to.x, 0.01};
    loop.start(from);
    for (int i = 1; i <= 200; ++i) tick(lerp(from, to, i / 200.0));
    for (int i = 0; i < 500; ++i) tick(to);
  }
  /// Largest per-tick force change from tick `from` on, less what the hand's motion may do (k · |Δh|).
  double worst_excess(std::size_t from, double k) const {
    double worst = -1e300;
    for (std::size_t i = from; i < forces.size(); ++i) {
      worst = std::max(worst, distance(forces[i], forces[i - 1]) - k * distance(handles[i], handles[i - 1]));
    }
    return worst;
  }
};

/// Ticks a force difference of `diff_n` takes to fade at kStep per tick, counting the tick of the change.
int fade_ticks(double diff_n) { return static_cast<int>(std::ceil(diff_n / kStep - 1e-9)); }

}  // namespace

TEST(LiveGains, StiffnessDoublesUnderAStillHandAtTheStepLimitAndEndsOnTheNewSpring) {
  const double d = 0.002, k0 = 800.0, k1 = 1600.0;
  Rig r(params(k0));
  const Vec2 h = pressed(0.0, d);
  r.press(h);
  ASSERT_NEAR(length(r.forces.back()), k0 * d, 1e-9);  // 1.6 N
  ASSERT_FALSE(r.loop.transition_active());

  ServoGains g = r.loop.gains();
  g.stiffness_n_per_m = k1;
  r.loop.set_gains(g);
  EXPECT_EQ(r.loop.gains(), g) << "the gains in use are the new ones at once";
  const int n = fade_ticks((k1 - k0) * d);  // ceil(1.6 N / 0.05 N) = 32
  ASSERT_EQ(n, 32);
  const std::size_t at = r.forces.size();
  for (int i = 0; i < n + 20; ++i) {
    const Vec2 f = r.tick(h);
    // The force climbs one step per tick from the tick of the change on: 1.6 + 0.05 (i + 1) N, up to 3.2 N.
    EXPECT_NEAR(length(f), std::min(k0 * d + kStep * (i + 1), k1 * d), 1e-9) << "tick " << i;
    EXPECT_NEAR(f.x, 0.0, 1e-12);
    EXPECT_EQ(r.loop.transition_active(), i < n - 1) << "tick " << i;
  }
  EXPECT_LE(r.worst_excess(at, 0.0), kStep + kTol);
  // The 32nd tick after set_gains (index n − 1) is the first on the new spring law: 1600 N/m × 2 mm.
  EXPECT_NEAR(length(r.forces[at + n - 1]), 3.2, 1e-9);
  EXPECT_NEAR(length(r.forces[at + n - 2]), 3.2 - kStep, 1e-9);
}

TEST(LiveGains, LoweringMaxForceUnderAPressFadesToTheNewClampAndRaisingItFadesBack) {
  const double k = 800.0, press_n = 3.0;
  Rig r(params(k));
  const Vec2 h = pressed(0.0, press_n / k);  // 3.75 mm: 3 N, under the 3.5 N clamp
  r.press(h);
  ASSERT_NEAR(length(r.forces.back()), press_n, 1e-9);

  ServoGains g = r.loop.gains();
  ASSERT_EQ(g.max_force_n, 3.5);
  g.max_force_n = 1.0;
  r.loop.set_gains(g);
  std::size_t at = r.forces.size();
  const int force_ticks = fade_ticks(press_n - 1.0);  // the solver's force: 3 N → 1 N, 40 ticks
  const int clamp_ticks = fade_ticks(3.5 - 1.0);      // the guard's clamp: 3.5 N → 1 N, 50 ticks
  for (int i = 0; i < clamp_ticks + 20; ++i) {
    const Vec2 f = r.tick(h);
    EXPECT_NEAR(length(f), std::max(1.0, press_n - kStep * (i + 1)), 1e-9) << "tick " << i;
    EXPECT_GT(f.y, 0.0);
    EXPECT_EQ(r.loop.transition_active(), i < clamp_ticks - 1) << "tick " << i;
  }
  EXPECT_NEAR(length(r.forces[at + force_ticks - 1]), 1.0, 1e-9);
  EXPECT_LE(r.worst_excess(at, 0.0), kStep + kTol);
  EXPECT_NEAR(length(r.forces.back()), 1.0, 1e-12) << "ends on the new clamp";

  g.max_force_n = 3.5;  // and back: the force climbs to the spring's 3 N at the same rate
  r.loop.set_gains(g);
  at = r.forces.size();
  for (int i = 0; i < clamp_ticks + 20; ++i) {
    const Vec2 f = r.tick(h);
    EXPECT_NEAR(length(f), std::min(press_n, 1.0 + kStep * (i + 1)), 1e-9) << "tick " << i;
  }
  EXPECT_LE(r.worst_excess(at, 0.0), kStep + kTol);
  EXPECT_FALSE(r.loop.transition_active());
}

TEST(LiveGains, DampingChangeUnderAHandMovingIntoTheWallDoesNotStep) {
  const double k = 800.0, b = 50.0, v = 0.01;  // 10 mm/s into the wall: b · v = 0.5 N, ten steps
  Rig r(params(k));
  r.press(pressed(0.0, 0.0005));
  auto hand = [&](int i) { return pressed(0.0, 0.0005 + v * 0.001 * i); };
  for (int i = 1; i <= 100; ++i) r.tick(hand(i));  // the filtered velocity settles at v
  const Vec2 spring_before = k * (r.out.contact.proxy_m - r.handles.back());
  ASSERT_NEAR(r.forces.back().y, spring_before.y, 1e-9) << "no damping yet";

  ServoGains g = r.loop.gains();
  g.damping_n_s_per_m = b;
  r.loop.set_gains(g);
  const std::size_t at = r.forces.size();
  const int n = fade_ticks(b * v);
  for (int i = 101; i <= 100 + n + 20; ++i) r.tick(hand(i));
  EXPECT_LE(r.worst_excess(at, k), kStep + 1e-9) << "no step beyond the limit and the hand's own motion";
  // On the new law: spring plus b · v pushing the handle back out (+y).
  const Vec2 spring = k * (r.out.contact.proxy_m - r.handles.back());
  EXPECT_NEAR(r.forces.back().y, spring.y + b * v, 1e-9);
  EXPECT_FALSE(r.loop.transition_active());
  EXPECT_GT(b * v, 5 * kStep) << "the change is one the limit has to spread";
}

TEST(LiveGains, LoweringFrictionUnderAStickingOrSlidingHandDoesNotStep) {
  const double k = 800.0, d = 0.002;  // the solver's depth below the wall's line (handle y = −d)
  const double depth_line = d;        // friction cone: |tangential offset| ≤ μ · (depth below the line)
  ServoParams p = params(k);
  p.contact.static_friction = 0.8;
  p.contact.dynamic_friction = 0.8;
  {  // Sticking: the hand pressed in, then moved 1 mm along (inside μ_s · d = 1.6 mm) slower than the stick band.
    Rig r(p);
    r.press({0.0, -d});
    for (int i = 1; i <= 1000; ++i) r.tick({0.001 * i / 1000.0, -d});
    for (int i = 0; i < 50; ++i) r.tick({0.001, -d});
    ASSERT_TRUE(r.out.contact.sticking);
    ASSERT_NEAR(r.forces.back().x, -k * 0.001, 1e-9);
    ServoGains g = r.loop.gains();
    g.static_friction = 0.2;
    g.dynamic_friction = 0.2;
    r.loop.set_gains(g);
    const std::size_t at = r.forces.size();
    const double diff = k * (0.001 - 0.2 * depth_line);  // the tangential force drops by 0.48 N
    for (int i = 0; i < fade_ticks(diff) + 20; ++i) r.tick({0.001, -d});
    EXPECT_LE(r.worst_excess(at, 0.0), kStep + kTol);
    EXPECT_NEAR(r.forces.back().x, -k * 0.2 * depth_line, 1e-9) << "trails on the new dynamic cone";
    EXPECT_NEAR(r.forces.back().y, k * (d + kSkin), 1e-9);
    EXPECT_FALSE(r.loop.transition_active());
  }
  {  // Sliding: the hand moves along at 5 mm/s (above the stick band), pressed to d.
    p.contact.static_friction = 0.6;
    p.contact.dynamic_friction = 0.6;
    Rig r(p);
    r.press({0.0, -d});
    auto hand = [&](int i) { return Vec2{-0.02 + 0.005 * 0.001 * i, -d}; };
    for (int i = 0; i < 4000; ++i) r.tick(hand(i));
    ASSERT_FALSE(r.out.contact.sticking);
    ASSERT_NEAR(r.forces.back().x, -k * 0.6 * depth_line, 1e-9);
    ServoGains g = r.loop.gains();
    g.static_friction = 0.2;
    g.dynamic_friction = 0.2;
    r.loop.set_gains(g);
    const std::size_t at = r.forces.size();
    const double diff = k * 0.4 * depth_line;  // 0.64 N
    for (int i = 4000; i < 4000 + fade_ticks(diff) + 20; ++i) r.tick(hand(i));
    EXPECT_LE(r.worst_excess(at, k), kStep + 1e-9);
    EXPECT_NEAR(r.forces.back().x, -k * 0.2 * depth_line, 1e-9);
    EXPECT_FALSE(r.loop.transition_active());
  }
}

TEST(LiveGains, StiffnessDoublesUnderASlowlyMovingHandWithinTheLimitPlusTheHandsMotion) {
  const double k0 = 800.0, k1 = 1600.0, d = 0.0015;
  Rig r(params(k0));
  // Along the wall at 20 mm/s while the press breathes ±0.4 mm at 2 Hz (frictionless: the proxy follows along).
  auto hand = [&](int i) {
    const double t = 0.001 * i;
    return pressed(-0.03 + 0.02 * t, d + 0.0004 * std::sin(2 * M_PI * 2.0 * t));
  };
  r.press(hand(0));
  for (int i = 1; i < 300; ++i) r.tick(hand(i));
  ServoGains g = r.loop.gains();
  g.stiffness_n_per_m = k1;
  r.loop.set_gains(g);
  const std::size_t at = r.forces.size();
  const Vec2 before = r.forces.back();
  r.tick(hand(300));
  // The difference the change made at its tick, and the ticks it takes to fade.
  const double diff = distance(before, k1 * (r.out.contact.proxy_m - r.handles.back()));
  const int n = fade_ticks(diff);
  EXPECT_GT(n, 10);
  for (int i = 301; i < 300 + n + 50; ++i) {
    r.tick(hand(i));
    EXPECT_EQ(r.loop.transition_active(), i - 300 < n - 1) << "tick " << i - 300;
  }
  EXPECT_LE(r.worst_excess(at, k1), kStep + 1e-9) << "|ΔF| ≤ limit + k · |Δhandle| on every tick";
  // Fully in force from the n-th tick on (F = k1 · (proxy − handle)), and not before.
  for (std::size_t i = at + static_cast<std::size_t>(n) - 1; i < r.forces.size(); ++i) {
    EXPECT_NEAR(r.forces[i].y, k1 * (r.proxies[i].y - r.handles[i].y), 1e-9) << "tick " << i - at;
    EXPECT_NEAR(r.forces[i].x, 0.0, 1e-9);
  }
  const std::size_t last_faded = at + static_cast<std::size_t>(n) - 2;
  EXPECT_GT(std::fabs(r.forces[last_faded].y - k1 * (r.proxies[last_faded].y - r.handles[last_faded].y)), 1e-6);
}

TEST(LiveGains, ALevelChangeAndAGainsChangeInOneTickStillObeyTheLimit) {
  // A pixel-like circle whose coarse levels lie off the fine one: pressed from outside at level 3, then
  // level 0 and a doubled stiffness asked for before the same tick.
  const Scene sc = Scene::build({test::staircase_circle({0, 0}, 0.02, 0.0004)}, 6);
  ServoParams p = params(800.0);
  p.level = 3;
  Rig r(p, sc);
  const Vec2 out_dir = normalized_or(sc.points(0, 0)[0], Vec2{1, 0});
  const Vec2 wall = sc.points(0, 0)[0];
  const Vec2 from = wall + 0.01 * out_dir, to = wall - 0.0015 * out_dir;
  r.loop.start(from);
  for (int i = 1; i <= 200; ++i) r.tick(lerp(from, to, i / 200.0));
  for (int i = 0; i < 500; ++i) r.tick(to);
  ASSERT_NE(r.out.contact.state, ContactState::Free);
  ASSERT_EQ(r.loop.level(), 3);

  r.loop.set_level(0);
  ServoGains g = r.loop.gains();
  g.stiffness_n_per_m = 1600.0;
  r.loop.set_gains(g);
  const std::size_t at = r.forces.size();
  const Vec2 before = r.forces.back();
  r.tick(to);
  ASSERT_TRUE(r.out.level_changed) << "the level change must be taken in the tick of the gains change";
  // Without the limit the force would jump by this much.
  const double jump = distance(before, 1600.0 * (r.out.contact.proxy_m - to));
  EXPECT_GT(jump, 10 * kStep);
  for (int i = 0; i < fade_ticks(jump) + 100; ++i) r.tick(to);
  EXPECT_LE(r.worst_excess(at, 0.0), kStep + kTol);
  EXPECT_EQ(r.loop.level(), 0);
  EXPECT_FALSE(r.loop.transition_active());
  const Vec2 spring = 1600.0 * (r.out.contact.proxy_m - to);
  EXPECT_NEAR(r.forces.back().x, spring.x, 1e-9);
  EXPECT_NEAR(r.forces.back().y, spring.y, 1e-9);
}

TEST(LiveGains, GainsSetBeforeTheFirstTickApplyAtOnceAndEqualGainsChangeNothing) {
  Rig r(params(800.0));
  const Vec2 h = pressed(0.0, 0.002);
  r.press(h);
  r.loop.set_gains(r.loop.gains());  // the same gains: no transition
  r.tick(h);
  EXPECT_FALSE(r.loop.transition_active());

  ServoGains g = r.loop.gains();
  g.stiffness_n_per_m = 1600.0;
  r.loop.set_gains(g);
  r.loop.start({0.0, 0.01});  // a restart above the wall: the ramp brings the force in from zero, nothing to fade
  r.tick({0.0, 0.01});
  EXPECT_FALSE(r.loop.transition_active());
  r.press(h);
  EXPECT_NEAR(length(r.forces.back()), 1600.0 * 0.002, 1e-9) << "the new stiffness, with no fade from the old";
}

TEST(LiveGains, GainsOfServoParamsRoundTrip) {
  ServoParams p;
  ServoGains g;
  g.stiffness_n_per_m = 1234.0;
  g.damping_n_s_per_m = 2.5;
  g.max_force_n = 2.0;
  g.static_friction = 0.4;
  g.dynamic_friction = 0.3;
  g.max_force_step_n = 0.02;
  g.query_box_budget = 1500;
  apply_gains(p, g);
  EXPECT_EQ(gains_of(p), g);
  EXPECT_EQ(p.guard.max_force_n, 2.0) << "the guard's clamp is the solver's";
  EXPECT_EQ(p.contact.max_force_n, 2.0);
}
