// The servo step: the force guard every force passes, the tick as a pure function of
// (state, sample, scene), and the tick's one box-test budget shared by its collision queries and its
// level-change check.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "curves.hpp"
#include "haptics/servo.hpp"

using namespace hk;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

ForceGuard guard(double max_force_n = 4.0, double ramp_s = 0.5) {
  ForceGuard g;
  g.max_force_n = max_force_n;
  g.ramp_s = ramp_s;
  return g;
}

// ── ForceGuard ────────────────────────────────────────────────────────────────────────────────────

TEST(ForceGuard, NonFiniteForceGivesZero) {
  const ForceGuard g = guard();
  for (const Vec2 f : {Vec2{kNaN, 0.0}, Vec2{0.0, kNaN}, Vec2{kInf, 1.0}, Vec2{1.0, -kInf}}) {
    TickResult why = TickResult::Ok;
    const Vec2 out = g.apply(f, 10.0, DeviceStatus::Ok, false, &why);
    EXPECT_EQ(why, TickResult::NonFinite) << f.x << ", " << f.y;
    EXPECT_EQ(out.x, 0.0);
    EXPECT_EQ(out.y, 0.0);
  }
}

TEST(ForceGuard, DeviceNotOkGivesZero) {
  const ForceGuard g = guard();
  for (const DeviceStatus st : {DeviceStatus::Lost, DeviceStatus::Fault, DeviceStatus::Closed}) {
    TickResult why = TickResult::Ok;
    const Vec2 out = g.apply({1.0, -0.5}, 10.0, st, false, &why);
    EXPECT_EQ(why, TickResult::DeviceNotOk) << static_cast<int>(st);
    EXPECT_EQ(out.x, 0.0);
    EXPECT_EQ(out.y, 0.0);
  }
}

TEST(ForceGuard, MissedDeadlineGivesZero) {
  const ForceGuard g = guard();
  TickResult why = TickResult::Ok;
  const Vec2 out = g.apply({1.0, -0.5}, 10.0, DeviceStatus::Ok, true, &why);
  EXPECT_EQ(why, TickResult::DeadlineMissed);
  EXPECT_EQ(out.x, 0.0);
  EXPECT_EQ(out.y, 0.0);
}

TEST(ForceGuard, StartUpRampClampsToTheRampedLimitInTheSameDirection) {
  const ForceGuard g = guard(4.0, 0.5);
  TickResult why = TickResult::NonFinite;
  const Vec2 f{30.0, -40.0};  // 50 N
  const Vec2 out = g.apply(f, 0.5 / 4.0, DeviceStatus::Ok, false, &why);
  EXPECT_EQ(why, TickResult::Ok);
  EXPECT_NEAR(length(out), 4.0 / 4.0, 1e-12) << "a quarter of the ramp: a quarter of max_force_n";
  EXPECT_NEAR(cross(out, f), 0.0, 1e-12);
  EXPECT_GT(dot(out, f), 0.0);
  // At the start nothing gets out; half-way, half.
  EXPECT_EQ(length(g.apply(f, 0.0, DeviceStatus::Ok, false, &why)), 0.0);
  EXPECT_NEAR(length(g.apply(f, 0.25, DeviceStatus::Ok, false, &why)), 2.0, 1e-12);
}

TEST(ForceGuard, ClampKeepsTheDirectionAndGivesExactlyTheMaximum) {
  const ForceGuard g = guard(4.0, 0.5);
  TickResult why = TickResult::NonFinite;
  const Vec2 f{-7.0, 2.0};
  const Vec2 out = g.apply(f, 3.0, DeviceStatus::Ok, false, &why);
  EXPECT_EQ(why, TickResult::Ok);
  EXPECT_NEAR(length(out), 4.0, 1e-12);
  EXPECT_NEAR(cross(out, f), 0.0, 1e-12);
  EXPECT_GT(dot(out, f), 0.0);
}

TEST(ForceGuard, ForceUnderTheLimitPassesUnchanged) {
  const ForceGuard g = guard(4.0, 0.5);
  TickResult why = TickResult::NonFinite;
  const Vec2 f{1.25, -2.5};  // 2.8 N
  const Vec2 out = g.apply(f, 3.0, DeviceStatus::Ok, false, &why);
  EXPECT_EQ(why, TickResult::Ok);
  EXPECT_EQ(out.x, f.x);
  EXPECT_EQ(out.y, f.y);
}

// ── Through the servo loop ────────────────────────────────────────────────────────────────────────

std::vector<Polyline> blobs() {
  std::mt19937 rng(13);
  std::vector<Polyline> curves;
  for (int i = 0; i < 5; ++i) curves.push_back(test::random_blob(rng, {-0.04 + 0.02 * i, 0.004 * (i % 3)}, 0.009, 120));
  for (int i = 0; i < 3; ++i) curves.push_back(test::random_stroke(rng, {-0.05 + 0.035 * i, -0.03}, 0.0004, 150));
  return curves;
}

ServoInput sample(Vec2 h, DeviceStatus st = DeviceStatus::Ok) {
  ServoInput in;
  in.sample.handle_m = h;
  in.sample.status = st;
  return in;
}

/// A hand that wanders over the scene, alternating slow and fast phases (so automatic levels change),
/// one position per tick.
std::vector<Vec2> wander(std::uint32_t seed, int ticks) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec2> path;
  Vec2 h{0.0, 0.04};
  Vec2 dir{0.3, -1.0};
  for (int i = 0; i < ticks; ++i) {
    const double speed_m_per_tick = (i / 150) % 2 == 0 ? 2e-5 : 4e-4;
    dir = normalized_or(dir + 0.3 * Vec2{u(rng), u(rng)}, Vec2{1.0, 0.0});
    h = h + speed_m_per_tick * dir;
    if (std::fabs(h.x) > 0.065) dir.x = -dir.x;
    if (std::fabs(h.y) > 0.042) dir.y = -dir.y;
    h = {std::clamp(h.x, -0.065, 0.065), std::clamp(h.y, -0.042, 0.042)};
    path.push_back(h);
  }
  return path;
}

ServoParams auto_params(std::int32_t box_budget) {
  ServoParams p;
  p.auto_level = true;
  p.level = 2;
  p.contact.static_friction = 0.4;
  p.contact.dynamic_friction = 0.3;
  p.query_box_budget = box_budget;
  return p;
}

TEST(ServoStep, NaNSampleGivesZeroForceAndKeepsTheState) {
  const Scene sc = Scene::build({test::square(0.02)}, 2);
  ServoParams p;
  p.level = 0;
  p.guard.ramp_s = 0.0;
  SceneStep loop(sc, p);
  loop.start({-0.03, 0.0});
  ServoOutput out;
  for (int i = 1; i <= 22; ++i) loop.update(sample({-0.03 + 0.0005 * i, 0.0}), out);  // 1 mm into the left wall
  ASSERT_EQ(out.contact.state, ContactState::Edge);
  ASSERT_GT(length(out.force_n), 0.5);
  const Vec2 proxy = loop.solver().proxy();
  const std::int64_t ticks = loop.ticks();
  for (const Vec2 bad : {Vec2{kNaN, 0.0}, Vec2{-0.02, kInf}}) {
    EXPECT_EQ(loop.update(sample(bad), out), TickResult::NonFinite);
    EXPECT_EQ(out.result, TickResult::NonFinite);
    EXPECT_EQ(out.force_n.x, 0.0);
    EXPECT_EQ(out.force_n.y, 0.0);
  }
  EXPECT_EQ(loop.solver().proxy(), proxy) << "a bad sample moves nothing";
  EXPECT_EQ(loop.ticks(), ticks);
  EXPECT_EQ(loop.update(sample({-0.019, 0.0}), out), TickResult::Ok);
  EXPECT_NEAR(out.force_n.x, -800.0 * (0.001 + p.contact.skin_m), 1e-3) << "the wall is still there";
}

TEST(ServoStep, DeviceNotOkAndLateTicksGiveZeroThroughTheLoop) {
  const Scene sc = Scene::build({test::square(0.02)}, 2);
  ServoParams p;
  p.level = 0;
  p.guard.ramp_s = 0.0;
  SceneStep loop(sc, p);
  loop.start({-0.03, 0.0});
  ServoOutput out;
  for (int i = 1; i <= 22; ++i) loop.update(sample({-0.03 + 0.0005 * i, 0.0}), out);
  ASSERT_GT(length(out.force_n), 0.5);
  EXPECT_EQ(loop.update(sample({-0.019, 0.0}, DeviceStatus::Lost), out), TickResult::DeviceNotOk);
  EXPECT_EQ(length(out.force_n), 0.0);
  ServoInput late = sample({-0.019, 0.0});
  late.deadline_missed = true;
  EXPECT_EQ(loop.update(late, out), TickResult::DeadlineMissed);
  EXPECT_EQ(length(out.force_n), 0.0);
}

bool same(const ServoOutput& a, const ServoOutput& b) {
  return a.force_n.x == b.force_n.x && a.force_n.y == b.force_n.y && a.contact.proxy_m == b.contact.proxy_m &&
         a.contact.state == b.contact.state && a.contact.events == b.contact.events && a.level == b.level &&
         a.level_wanted == b.level_wanted && a.result == b.result && a.contact.budget_used == b.contact.budget_used &&
         a.handle_velocity_m_per_s == b.handle_velocity_m_per_s;
}

TEST(ServoStep, TwoLoopsFedTheSameSamplesGiveBitIdenticalOutputs) {
  const Scene sc = Scene::build(blobs(), 5);
  const std::vector<Vec2> path = wander(5, 3000);
  for (const std::int32_t budget : {0, 8, 200}) {  // the anytime path is deterministic too: no clock
    SceneStep a(sc, auto_params(budget)), b(sc, auto_params(budget));
    a.start(path[0]);
    b.start(path[0]);
    ServoOutput oa, ob;
    long contacts = 0, changes = 0;
    for (std::size_t i = 1; i < path.size(); ++i) {
      a.update(sample(path[i]), oa);
      b.update(sample(path[i]), ob);
      ASSERT_TRUE(same(oa, ob)) << "tick " << i << " budget " << budget;
      contacts += oa.contact.state != ContactState::Free;
      changes += oa.level_changed;
    }
    EXPECT_GT(contacts, 100) << "the walk must touch walls, budget " << budget;
    if (budget != 8) {
      EXPECT_GT(changes, 2) << "and change levels, budget " << budget;
    }
  }
}

TEST(ServoStep, SameInputsFromTheSameStateGiveTheSameOutput) {
  const Scene sc = Scene::build(blobs(), 5);
  const std::vector<Vec2> path = wander(9, 2000);
  SceneStep loop(sc, auto_params(kDefaultQueryBoxBudget));
  loop.start(path[0]);
  ServoOutput out, again;
  int compared = 0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    if (i % 97 == 0) {  // branch off a copy and give both the same next sample
      SceneStep copy = loop;
      copy.update(sample(path[i]), again);
      loop.update(sample(path[i]), out);
      ASSERT_TRUE(same(out, again)) << "tick " << i;
      ++compared;
    } else {
      loop.update(sample(path[i]), out);
    }
  }
  EXPECT_GE(compared, 20);
}

// ── The tick's box-test budget ────────────────────────────────────────────────────────────────────

TEST(ServoStep, StarvedBudgetNeverCrossesAndNeverOverspends) {
  const Scene sc = Scene::build(blobs(), 5);
  const std::vector<Vec2> path = wander(21, 6000);
  for (std::int32_t budget = 1; budget <= 12; ++budget) {
    SceneStep loop(sc, auto_params(budget));
    loop.start(path[0]);
    ServoOutput out;
    int prev_level = loop.level(), prev_transition = -1;
    long crossings = 0, contacts = 0, budget_ticks = 0;
    for (std::size_t i = 1; i < path.size(); ++i) {
      loop.update(sample(path[i]), out);
      const ContactOutput& c = out.contact;
      const int old_wall = out.level_changed ? prev_level : prev_transition;
      for (int m = 1; m < c.path_count; ++m) {
        crossings += test::count_crossings(sc, c.path_m[m - 1], c.path_m[m], out.level);
        if (old_wall >= 0) crossings += test::count_crossings(sc, c.path_m[m - 1], c.path_m[m], old_wall);
      }
      // The documented slack: only the scans of the boundary section may go past the budget.
      ASSERT_LE(c.budget_used - c.query.section_box_tests, budget) << "tick " << i;
      ASSERT_GE(c.budget_used, c.query.box_tests);
      prev_transition = c.transition_level;
      prev_level = out.level;
      contacts += c.state != ContactState::Free;
      budget_ticks += (c.events & kEventQueryBudget) != 0;
    }
    EXPECT_EQ(crossings, 0) << "budget " << budget;
    EXPECT_GT(contacts, 100) << "budget " << budget;
    EXPECT_GT(budget_ticks, 0) << "a budget this small must bite, budget " << budget;
  }
}

TEST(ServoStep, BudgetIsOneCounterForTheWholeTick) {
  // With a budget that does not bind, a tick's budget_used is its level check plus its queries' box tests;
  // with a binding one, the optional work stops at the limit.
  const Scene sc = Scene::build(blobs(), 5);
  const std::vector<Vec2> path = wander(33, 3000);
  for (const std::int32_t budget : {0, 30, 100}) {
    SceneStep loop(sc, auto_params(budget));
    loop.start(path[0]);
    ServoOutput out;
    long binding = 0;
    for (std::size_t i = 1; i < path.size(); ++i) {
      loop.update(sample(path[i]), out);
      const ContactOutput& c = out.contact;
      ASSERT_GE(c.budget_used, c.query.box_tests) << "tick " << i;
      if (!out.level_changed && out.level == out.level_wanted) {
        ASSERT_EQ(c.budget_used, c.query.box_tests) << "no level check: queries only";
      }
      if (budget > 0) {
        ASSERT_LE(c.budget_used - c.query.section_box_tests, budget) << "tick " << i;
      }
      binding += budget > 0 && c.budget_used >= budget;
    }
    if (budget > 0) {
      EXPECT_GT(binding, 0) << "budget " << budget << " must bind on some ticks for this test to mean anything";
    }
  }
}

TEST(ServoStep, LevelChangeWaitsWhenTheBudgetCannotPayForItsCheck) {
  const Scene sc = Scene::build({test::square(0.02)}, 3);
  for (const std::int32_t budget : {1, 2, 0}) {
    ServoParams p;
    p.level = 2;
    p.query_box_budget = budget;
    SceneStep loop(sc, p);
    const Vec2 h{-0.0185, 0.003};  // inside the square, near its left wall: the check must walk the tree
    loop.start(h);
    ServoOutput out;
    loop.update(sample(h), out);
    loop.set_level(0);
    int changed_at = -1;
    for (int i = 0; i < 200 && changed_at < 0; ++i) {
      loop.update(sample(h), out);
      if (budget > 0) {
        ASSERT_LE(out.contact.budget_used - out.contact.query.section_box_tests, budget);
      }
      if (out.level_changed) changed_at = i;
    }
    if (budget == 0) {
      EXPECT_EQ(changed_at, 0) << "unlimited: the change is made at once";
      EXPECT_EQ(loop.level(), 0);
    } else {
      EXPECT_EQ(changed_at, -1) << "budget " << budget << ": the change waits rather than overspend";
      EXPECT_EQ(loop.level(), 2);
      EXPECT_EQ(out.level_wanted, 0);
    }
  }
}

TEST(ServoStep, LevelCheckDrawsOnTheTickBudget) {
  const Scene sc = Scene::build({test::square(0.02)}, 3);
  ContactParams cp;
  ContactSolver solver(sc, cp);
  // Each check from the same state: reset forgets the closest-point seed a check leaves behind (with it, a
  // second check could walk less).
  const auto fresh = [&] { solver.reset({-0.0185, 0.003}, 2); };
  fresh();
  QueryBudget unlimited;
  ASSERT_TRUE(solver.level_change_is_safe(0, &unlimited));
  EXPECT_GT(unlimited.box_tests_used, 2) << "the check walks the tree";
  EXPECT_FALSE(unlimited.ran_out);
  for (std::int32_t limit = 1; limit < unlimited.box_tests_used; ++limit) {
    fresh();
    QueryBudget b;
    b.max_box_tests = limit;
    EXPECT_FALSE(solver.level_change_is_safe(0, &b)) << "limit " << limit;
    EXPECT_LE(b.box_tests_used, limit);
    EXPECT_TRUE(b.ran_out);
  }
  fresh();
  QueryBudget enough;
  enough.max_box_tests = unlimited.box_tests_used;
  EXPECT_TRUE(solver.level_change_is_safe(0, &enough));
  EXPECT_EQ(enough.box_tests_used, unlimited.box_tests_used);
}

}  // namespace
