// The visitor-like explorer hand on its own: parameter checks, determinism from the seed,
// and in a closed loop with the simulated pantograph and the servo (walls at the default 800 N/m, friction
// 0.4/0.3 as the kiosk's defaults) that it traces a shape round, remembers it, and then pushes at it with
// 1.4 x pop_force_n.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "haptics/explorer_hand.hpp"
#include "haptics/multires.hpp"
#include "haptics/scene.hpp"
#include "haptics/servo.hpp"
#include "haptics/sim_pantograph.hpp"
#include "hk/error.hpp"

namespace hk {
namespace {

Polyline square(Vec2 c, double half, double step) {
  Polyline p;
  p.closed = true;
  const int n = static_cast<int>(std::lround(2 * half / step));
  for (int i = 0; i < n; ++i) p.points_m.push_back(c + Vec2{-half + i * step, -half});
  for (int i = 0; i < n; ++i) p.points_m.push_back(c + Vec2{half, -half + i * step});
  for (int i = 0; i < n; ++i) p.points_m.push_back(c + Vec2{half - i * step, half});
  for (int i = 0; i < n; ++i) p.points_m.push_back(c + Vec2{-half, half - i * step});
  return p;
}

struct LoopResult {
  double max_command_force_n = 0.0;
  std::vector<Vec2> handle_m;  // per tick
  std::vector<HandCommand> commands;
};

// The headless loop of app/runtime/src/simulation.cpp, reduced: read, servo, write, hand, step.
LoopResult run_loop(const Scene& sc, ExplorerHand& hand, double seconds, bool keep_commands = false) {
  ServoParams sp;
  sp.level = 0;
  sp.contact.static_friction = 0.4;
  sp.contact.dynamic_friction = 0.3;
  sp.contact.max_force_n = 3.5;
  sp.guard.max_force_n = 3.5;
  SceneStep servo(sc, sp);
  SimulatedPantograph dev(SimPantographParams{}, hand.start_m());
  dev.open();
  servo.start(dev.read().handle_m);
  ModelHandParams hp;
  LoopResult r;
  ServoOutput so;
  const long n = static_cast<long>(seconds / sp.period_s);
  for (long k = 0; k < n; ++k) {
    ServoInput in;
    in.sample = dev.read();
    servo.update(in, so);
    dev.write_force(so.force_n);
    const bool heard_pop = (so.contact.events & kEventPopThrough) != 0;
    const HandCommand c = hand.command(
        HandFeel{k * sp.period_s, dev.true_position_m(), dev.velocity_m_per_s(), dev.commanded_force_n(), heard_pop});
    r.handle_m.push_back(dev.true_position_m());
    r.max_command_force_n = std::max(r.max_command_force_n, c.max_force_n);
    if (keep_commands) r.commands.push_back(c);
    hp.max_force_n = c.max_force_n;
    dev.step(sp.period_s, model_hand_force(hp, c.target_m, dev.true_position_m(), dev.velocity_m_per_s()));
  }
  return r;
}

// Runs the hand open-loop against nothing: the handle goes where the hand pulls it (an ideal, massless hand).
std::vector<Vec2> run_free(ExplorerHand& hand, double seconds) {
  std::vector<Vec2> path;
  Vec2 handle = hand.start_m();
  for (long k = 0; k < static_cast<long>(seconds / 0.001); ++k) {
    handle = hand.command(HandFeel{k * 0.001, handle, {}, {}}).target_m;
    path.push_back(handle);
  }
  return path;
}

// The largest and the mean distance from the points of a 1 mm grid over |x| <= hx, |y| <= hy to the path [m].
struct Gap {
  double largest_m = 0.0;
  double mean_m = 0.0;
};
Gap gap_to(const std::vector<Vec2>& path, double hx, double hy) {
  Gap g;
  long n = 0;
  for (double y = -hy; y <= hy + 1e-12; y += 0.001)
    for (double x = -hx; x <= hx + 1e-12; x += 0.001) {
      double best = 1e9;
      for (std::size_t k = 0; k < path.size(); k += 5) best = std::min(best, distance(path[k], {x, y}));
      g.largest_m = std::max(g.largest_m, best);
      g.mean_m += best;
      ++n;
    }
  g.mean_m /= static_cast<double>(std::max(n, 1L));
  return g;
}

}  // namespace

TEST(ExplorerHand, RefusesBadParametersNamingTheField) {
  auto message = [](ExplorerParams p) {
    try {
      ExplorerHand h(p);
    } catch (const hk::ArgumentError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  ExplorerParams p;
  p.sweep_spacing_m = 0.0;
  EXPECT_NE(message(p).find("sweep_spacing_m"), std::string::npos);
  p = {};
  p.press_force_n = 2.5;  // above max_force_n = 2
  EXPECT_NE(message(p).find("press_force_n"), std::string::npos);
  p = {};
  p.pop_force_n = 0.5;  // below the press: a trace would push through
  EXPECT_NE(message(p).find("pop_force_n"), std::string::npos);
  p = {};
  p.trace_speed_m_per_s = std::nan("");
  EXPECT_NE(message(p).find("trace_speed_m_per_s"), std::string::npos);
  p = {};
  EXPECT_EQ(message(p), "") << "the defaults are valid";
  EXPECT_EQ(message(p).find('\n'), std::string::npos);
}

TEST(ExplorerHand, StartsInsideTheWorkspaceAndTheSeedChoosesTheStart) {
  int differing = 0;
  ExplorerParams p;
  const Vec2 first = ExplorerHand(p).start_m();
  for (std::uint64_t seed = 1; seed <= 16; ++seed) {
    p.seed = seed;
    const ExplorerHand a(p), b(p);
    EXPECT_EQ(a.start_m(), b.start_m());
    EXPECT_EQ(a.turning_sense(), b.turning_sense());
    EXPECT_LE(std::abs(a.start_m().x), p.workspace_width_m / 2);
    EXPECT_LE(std::abs(a.start_m().y), p.workspace_height_m / 2);
    differing += !(a.start_m() == first);
  }
  EXPECT_GE(differing, 4) << "16 seeds give more than one start corner";
}

TEST(ExplorerHand, SameFeelsGiveTheSameCommands) {
  ExplorerParams p;
  p.seed = 7;
  ExplorerHand a(p), b(p);
  for (int k = 0; k < 3000; ++k) {
    // A made-up feel: a wall pushing back along +x for a while, then nothing.
    const double t = k * 0.001;
    const HandFeel f{
        t, {0.01 * std::sin(t), 0.005 * std::cos(2 * t)}, {0.01, 0.0}, k > 500 && k < 1500 ? Vec2{1.2, 0.1} : Vec2{}};
    const HandCommand ca = a.command(f), cb = b.command(f);
    ASSERT_EQ(ca.target_m, cb.target_m) << "tick " << k;
    ASSERT_EQ(ca.max_force_n, cb.max_force_n) << "tick " << k;
  }
}

TEST(ExplorerHand, FeelingAWallStartsATraceThatPressesIntoItGently) {
  ExplorerParams p;
  ExplorerHand h(p);
  const Vec2 at = h.start_m();
  h.command(HandFeel{0.0, at, {}, {}});
  EXPECT_EQ(h.phase(), ExplorerPhase::Move);
  const HandCommand c = h.command(HandFeel{0.001, at, {}, {0.0, 1.5}});  // a wall below pushes up
  EXPECT_EQ(h.phase(), ExplorerPhase::Trace);
  EXPECT_LE(c.max_force_n, p.max_force_n);
  // Pressing down into the wall with press_force_n (the hand's spring), sliding sideways.
  EXPECT_NEAR((c.target_m - at).y, -p.press_force_n / p.hand_stiffness_n_per_m, 1e-9);
  EXPECT_GT(std::abs((c.target_m - at).x), 0.0);
  EXPECT_TRUE(h.traced_at(at));
}

TEST(ExplorerHand, TracesASquareRoundThenPushesIntoItWithMoreThanThePopForce) {
  const Scene sc = Scene::build({square({0.0, 0.0}, 0.015, 0.001)}, 4);
  ExplorerParams p;
  p.seed = 3;
  ExplorerHand h(p);
  const LoopResult r = run_loop(sc, h, 25.0);
  EXPECT_GE(h.stats().traces_closed, 1) << "the square is traced round to where the trace began";
  // The memory holds the outline: points along the four sides (1.5 mm outside the square, where the handle
  // pressing on the outside runs) are traced.
  int traced = 0, points = 0;
  for (int side = 0; side < 4; ++side)
    for (double u = -0.013; u <= 0.013; u += 0.002) {
      const double o = 0.0155;
      const Vec2 q = side == 0 ? Vec2{u, -o} : side == 1 ? Vec2{o, u} : side == 2 ? Vec2{u, o} : Vec2{-o, u};
      ++points;
      traced += h.traced_at(q) || h.traced_at(q + Vec2{0.002, 0}) || h.traced_at(q - Vec2{0.002, 0}) ||
                h.traced_at(q + Vec2{0, 0.002}) || h.traced_at(q - Vec2{0, 0.002});
    }
  EXPECT_GE(traced, points * 9 / 10) << traced << " of " << points;
  EXPECT_GE(h.stats().pops, 1) << "the sweep met the traced square again and pushed at it";
  EXPECT_NEAR(r.max_command_force_n, 1.1 * p.pop_force_n, 1e-9)
      << "over the give-way force, under the wall's 3.5 N clamp";
}

TEST(ExplorerHand, OnAnEmptyWorkspaceItsPlansSweepEveryPlaceAboutASpacingApart) {
  // Nothing to feel: the plans alone must reach every cell of the memory grid, so no place of the workspace (less
  // the 3 mm margin) lies farther from the path than the footprint reaches (sweep_spacing_m across from the far side
  // of the handle's cell, half a cell along), and the first pass must end. The lines lie about a spacing apart: on
  // average a place is within a third of a spacing of the path (a perfect raster: a quarter), and the first pass takes
  // no longer than 1.5 x its lines' length at the sweep speed.
  ExplorerParams p;
  for (std::uint64_t seed : {1u, 2u}) {
    p.seed = seed;
    ExplorerHand h(p);
    const double hx = p.workspace_width_m / 2 - 0.003, hy = p.workspace_height_m / 2 - 0.003;
    const double lines_s = (2 * hx) * (2 * hy) / p.sweep_spacing_m / p.sweep_speed_m_per_s;
    const std::vector<Vec2> path = run_free(h, 1.5 * lines_s);
    EXPECT_GE(h.stats().passes, 2) << "seed " << seed << ": the first pass ended";
    EXPECT_EQ(h.stats().traces, 0);
    EXPECT_EQ(h.stats().pops, 0);
    const Gap g = gap_to(path, hx, hy);
    EXPECT_LE(g.largest_m, p.sweep_spacing_m + p.cell_m / 2) << "seed " << seed;
    EXPECT_LE(g.mean_m, p.sweep_spacing_m / 3) << "seed " << seed;
    for (const Vec2& q : path) {
      ASSERT_LE(std::abs(q.x), p.workspace_width_m / 2) << "seed " << seed;
      ASSERT_LE(std::abs(q.y), p.workspace_height_m / 2) << "seed " << seed;
    }
  }
}

TEST(ExplorerHand, AWallGivesWayWhenThePushThroughEarconIsHeardEvenIfItPressesBackAgainAtOnce) {
  // Pressing through one wall onto another just behind it, the force never falls: the earcon tells the hand.
  ExplorerParams p;
  ExplorerHand h(p);
  const Vec2 at = h.start_m();
  h.command(HandFeel{0.0, at, {}, {}});
  h.command(HandFeel{0.001, at, {}, {0.0, 1.5}});  // a wall: a trace begins and marks it
  ASSERT_EQ(h.phase(), ExplorerPhase::Trace);
  ASSERT_TRUE(h.traced_at(at));
  // Hold it until the trace gives up (no progress for stall_s), back in Move beside a remembered wall.
  double t = 0.002;
  for (; t < 3.0 && h.phase() != ExplorerPhase::Move; t += 0.001) h.command(HandFeel{t, at, {}, {0.0, 1.5}});
  ASSERT_EQ(h.phase(), ExplorerPhase::Move);
  // Planned towards the wall (y decreasing from a top corner, or across it) it pushes where it stands across the way;
  // feel the remembered wall square against the way until a push begins.
  for (int k = 0; k < 2000 && h.phase() != ExplorerPhase::Pop; ++k, t += 0.001) {
    const HandCommand c = h.command(HandFeel{t, at, {}, {}});
    const Vec2 way = c.target_m - at;
    if (length(way) > 1e-4) h.command(HandFeel{t += 0.001, at, {}, -(1.5 / length(way)) * way});
  }
  ASSERT_EQ(h.phase(), ExplorerPhase::Pop);
  const long through = h.stats().pops_through;
  h.command(HandFeel{t + 0.001, at, {}, {0.0, 3.2}, false});
  EXPECT_EQ(h.phase(), ExplorerPhase::Pop) << "still pressed back, nothing heard: still pushing";
  h.command(HandFeel{t + 0.002, at, {}, {0.0, 3.2}, true});
  EXPECT_EQ(h.phase(), ExplorerPhase::Move) << "the earcon: the wall gave way";
  EXPECT_EQ(h.stats().pops_through, through + 1);
}

TEST(ExplorerHand, WithPushThroughOffItNeverPushesHardAndSweepsRoundAClosedShape) {
  // pop_force_n = 0: remembered walls are impassable to the plans; the hand never presses harder than its usual
  // max_force_n, the square is traced, and the sweep carries on outside it (plans keep being made).
  const Scene sc = Scene::build({square({0.0, 0.0}, 0.015, 0.001)}, 4);
  ExplorerParams p;
  p.pop_force_n = 0.0;
  ExplorerHand h(p);
  const LoopResult r = run_loop(sc, h, 40.0);
  EXPECT_LE(r.max_command_force_n, p.max_force_n);
  EXPECT_EQ(h.stats().pops, 0);
  EXPECT_GE(h.stats().traces_closed, 1);
  EXPECT_GE(h.stats().plans, 50);
  long inside = 0;
  for (const Vec2& q : r.handle_m) inside += std::abs(q.x) < 0.012 && std::abs(q.y) < 0.012;
  EXPECT_EQ(inside, 0) << "the handle came well inside the square without pushing through";
}

}  // namespace hk
