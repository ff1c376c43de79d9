// The cases where proxy methods usually fail: hand tremor at a wall (level flapping, contact
// chatter), coincident and touching curves, a curve through the proxy's start, a zero-length chain and a
// chain of two points — each driven through the servo loop with levels from hand speed and friction on,
// every proxy move checked against the walls in force with the independent crossing predicate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "curves.hpp"
#include "haptics/servo.hpp"

using namespace hk;

namespace {

ServoParams auto_params() {
  ServoParams p;
  p.auto_level = true;
  p.level = 2;
  p.contact.static_friction = 0.4;
  p.contact.dynamic_friction = 0.3;
  p.query_box_budget = 0;  // no box-test limit: every query exact
  return p;
}

/// Drives `loop` along handle positions `path` (one per tick) and counts proxy moves that cross a wall in
/// force (the level in use, and the previous level while it is still a wall).
struct RunStats {
  long crossings = 0, contact_changes = 0, level_changes = 0, wanted_changes = 0, ticks = 0;
  long min_gap_ticks = 1 << 30;  ///< fewest ticks between two contact begin/end events
  std::vector<ContactState> states;
};

RunStats drive(const Scene& sc, SceneStep& loop, const std::vector<Vec2>& path, long settle_ticks = 0) {
  RunStats r;
  ServoOutput out;
  int prev_level = loop.level(), prev_transition = -1, prev_wanted = -1;
  long last_event = -(1 << 20);
  for (std::size_t i = 0; i < path.size(); ++i) {
    ServoInput in;
    in.sample.handle_m = path[i];
    in.sample.status = DeviceStatus::Ok;
    loop.update(in, out);
    const ContactOutput& c = out.contact;
    const int old_wall = out.level_changed ? prev_level : prev_transition;
    for (int m = 1; m < c.path_count; ++m) {
      r.crossings += test::count_crossings(sc, c.path_m[m - 1], c.path_m[m], out.level);
      if (old_wall >= 0) r.crossings += test::count_crossings(sc, c.path_m[m - 1], c.path_m[m], old_wall);
    }
    prev_transition = c.transition_level;
    prev_level = out.level;
    if (static_cast<long>(i) < settle_ticks) continue;
    if (c.events & (kEventContactBegin | kEventContactEnd)) {
      ++r.contact_changes;
      r.min_gap_ticks = std::min(r.min_gap_ticks, static_cast<long>(i) - last_event);
      last_event = static_cast<long>(i);
    }
    r.level_changes += out.level_changed;
    r.wanted_changes += prev_wanted >= 0 && out.level_wanted != prev_wanted;
    prev_wanted = out.level_wanted;
    r.states.push_back(c.state);
    ++r.ticks;
  }
  return r;
}

std::vector<Vec2> random_walk(std::mt19937& rng, Vec2 start, int n, double step_m, Vec2 half_extent) {
  std::vector<Vec2> p{start};
  std::uniform_real_distribution<double> d(-step_m, step_m);
  Vec2 v{0, 0};
  for (int i = 1; i < n; ++i) {
    // Smooth velocity, so the hand has speeds the level policy reacts to (slow stretches and fast ones).
    v = 0.97 * v + Vec2{d(rng), d(rng)};
    Vec2 h = p.back() + 0.2 * v;
    h = {std::clamp(h.x, -half_extent.x, half_extent.x), std::clamp(h.y, -half_extent.y, half_extent.y)};
    p.push_back(h);
  }
  return p;
}

}  // namespace

TEST(HardCases, TremorAtAWallNeitherFlapsLevelsNorChatters) {
  // An 8 Hz, 0.7 mm (amplitude) tremor on a hand resting 0.5 mm into a wall: the hand really leaves the
  // wall once per cycle, so two contact events per cycle are honest. The bound we hold (and document in
  // docs/PERFORMANCE.md): at most 2 contact events per tremor cycle and never two within 10 ms of each
  // other (no chatter on top of the tremor); after the first second, at most one level change.
  // A pixel-staircase circle: its error bounds (0.13, 0.19, 0.22, 0.23, 0.44 mm at levels 0–4) straddle
  // what the policy tolerates at the tremor's speed (0.1 mm + ~22 mm/s · 10 ms ≈ 0.3 mm), the case where
  // a level choice without hysteresis and speed filtering flaps.
  const Scene sc = Scene::build({test::staircase_circle({0, 0}, 0.02, 0.0004)}, 6);
  ASSERT_GT(sc.max_error_bound_m(4), 0.3e-3);
  ASSERT_LT(sc.max_error_bound_m(1), 0.3e-3);
  const Vec2* pts = sc.points(0, 0);
  // The wall point: curve point 0, outward normal roughly along it for a circle round the origin.
  const Vec2 w = pts[0];
  const Vec2 n = normalized_or(w, Vec2{1, 0});
  for (const Vec2 dir : {n, left_perp(n)}) {  // tremor across the wall, and along it
    SceneStep loop(sc, auto_params());
    std::vector<Vec2> path;
    const Vec2 rest = w - 0.0005 * n;
    for (int i = 0; i < 300; ++i) path.push_back(lerp(w + 0.01 * n, rest, i / 300.0));
    const int ticks = 5000;
    for (int i = 0; i < ticks; ++i) path.push_back(rest + (0.0007 * std::sin(2 * M_PI * 8.0 * i * 0.001)) * dir);
    loop.start(path[0]);
    const RunStats r = drive(sc, loop, path, 1300);  // settle: the approach and the first second of tremor
    const double cycles = 8.0 * (ticks - 1000) * 0.001;
    EXPECT_EQ(r.crossings, 0);
    EXPECT_LE(r.contact_changes, 2 * cycles + 1) << "dir " << dir.x << "," << dir.y;
    if (r.contact_changes > 1) {
      EXPECT_GE(r.min_gap_ticks, 10);
    }
    EXPECT_LE(r.level_changes, 1);
    EXPECT_LE(r.wanted_changes, 1);
    // The same hand with the speed unfiltered and no hysteresis or dwell: the level asked for flaps with the
    // tremor (the level in use may flap less: a change also waits for the proxy to be on the right side).
    ServoParams naive = auto_params();
    naive.policy.speed_cutoff_hz = 200.0;
    naive.policy.hysteresis = 0.0;
    naive.policy.min_dwell_s = 0.0;
    SceneStep flappy(sc, naive);
    flappy.start(path[0]);
    EXPECT_GT(drive(sc, flappy, path, 1300).wanted_changes, 20) << "the case must be one where a naive policy flaps";
  }
}

TEST(HardCases, CoincidentAndTouchingCurvesDegenerateChainsRandomWalks) {
  std::mt19937 rng(77);
  std::vector<Polyline> curves;
  // Two coincident copies of one blob.
  const Polyline blob = test::random_blob(rng, {-0.035, 0.0}, 0.012, 256);
  curves.push_back(blob);
  curves.push_back(blob);
  // Two squares sharing an edge (x = 0.01), and a third touching their corner at one point.
  Polyline a = test::square(0.01), b = test::square(0.01), t = test::square(0.005);
  for (Vec2& p : b.points_m) p.x += 0.02;
  for (Vec2& p : t.points_m) p += Vec2{0.035, 0.015};
  curves.push_back(a);
  curves.push_back(b);
  curves.push_back(t);
  // A chain of two points, and a zero-length chain (all points equal), and a one-point chain.
  Polyline two;
  two.points_m = {{0.0, -0.03}, {0.04, -0.025}};
  curves.push_back(two);
  Polyline zero;
  zero.points_m = {{0.05, 0.03}, {0.05, 0.03}, {0.05, 0.03}};
  curves.push_back(zero);
  Polyline one;
  one.points_m = {{-0.05, -0.03}};
  curves.push_back(one);
  const Scene sc = Scene::build(curves, 5);
  EXPECT_EQ(sc.skipped_curves(), 2u) << "the zero-length and one-point chains are skipped, not built";
  long contacts = 0, changes = 0;
  for (int seed = 0; seed < 4; ++seed) {
    std::mt19937 walk_rng(static_cast<unsigned>(100 + seed));
    SceneStep loop(sc, auto_params());
    const std::vector<Vec2> path = random_walk(walk_rng, {0.0, 0.04}, 20000, 0.00025, {0.06, 0.04});
    loop.start(path[0]);
    const RunStats r = drive(sc, loop, path);
    EXPECT_EQ(r.crossings, 0) << "seed " << seed;
    for (ContactState s : r.states) contacts += s != ContactState::Free;
    changes += r.level_changes;
  }
  EXPECT_GT(contacts, 2000) << "the walks must touch the curves";
  EXPECT_GT(changes, 10) << "and change levels as they speed up and slow down";
}

TEST(HardCases, CurveThroughTheProxysStartPosition) {
  // The servo loop starts with the handle exactly on a curve (a vertex, and the middle of a segment): the
  // proxy is pushed off to one side and then never crosses.
  std::mt19937 rng(5);
  const Polyline blob = test::random_blob(rng, {0, 0}, 0.02, 128);
  const Scene sc = Scene::build({blob}, 4);
  for (const Vec2 start : {blob.points_m[7], lerp(blob.points_m[40], blob.points_m[41], 0.5)}) {
    SceneStep loop(sc, auto_params());
    std::mt19937 walk_rng(9);
    const std::vector<Vec2> path = random_walk(walk_rng, start, 8000, 0.0002, {0.05, 0.04});
    loop.start(start);
    const RunStats r = drive(sc, loop, path);
    EXPECT_EQ(r.crossings, 0);
  }
}
