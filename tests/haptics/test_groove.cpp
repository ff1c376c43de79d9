// The grooves rendering mode: each curve an engraved line that pulls the hand towards
// its closest point within a capture radius, with a continuous trapezoid profile, and never blocks.
// Checked here on synthetic scenes: the golden profile, force continuity along sweeps (a lone line, where
// the per-tick limiter is never needed, and a hairpin, where the closest point jumps), a released hand
// settling in the groove's centre, a hand dragged across a groove, a closed curve that does not block.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "curves.hpp"
#include "haptics/groove.hpp"
#include "haptics/servo.hpp"
#include "haptics/sim_pantograph.hpp"

using namespace hk;

namespace {

constexpr double kK = 800.0;    // stiffness [N/m]
constexpr double kR = 0.003;    // capture radius [m]
constexpr double kDepth = 1.0;  // [N]
constexpr double kJump = 0.05;  // [N]

Polyline line_polyline(Vec2 a, Vec2 b) {
  Polyline p;
  p.closed = false;
  p.points_m = {a, b};
  return p;
}

// A straight horizontal curve y = 0 from x = −0.04 to 0.04 (straight at every level).
Scene line_scene() { return Scene::build({line_polyline({-0.04, 0.0}, {0.04, 0.0})}, 4); }

// A hairpin: two straight legs 4 mm apart (closer than 2R: a medial axis at y = 0 between them) joined by
// a half circle at x = 0.02.
Scene hairpin_scene() {
  Polyline p;
  p.closed = false;
  for (int i = 0; i <= 50; ++i) p.points_m.push_back({-0.03 + 0.05 * i / 50.0, 0.002});
  for (int i = 1; i < 16; ++i) {
    const double th = M_PI / 2 - M_PI * i / 16.0;
    p.points_m.push_back({0.02 + 0.002 * std::cos(th), 0.002 * std::sin(th)});
  }
  for (int i = 0; i <= 50; ++i) p.points_m.push_back({0.02 - 0.05 * i / 50.0, -0.002});
  return Scene::build({p}, 4);
}

ServoParams groove_servo_params(bool auto_level = false, int level = 0) {
  ServoParams sp;
  sp.render = RenderMode::Grooves;
  sp.level = level;
  sp.auto_level = auto_level;
  sp.guard.ramp_s = 0.0;  // no start-up ramp: every force change seen is the groove's
  sp.guard.max_force_n = 3.5;
  ServoGains g = gains_of(sp);
  g.stiffness_n_per_m = kK;
  g.max_force_n = 3.5;
  g.max_force_step_n = kJump;
  apply_gains(sp, g);
  sp.groove.capture_radius_m = kR;
  sp.groove.depth_n = kDepth;
  return sp;
}

// A raster of the rectangle [lo, hi] (rows `spacing` apart, alternating direction, joined by vertical
// steps), sampled every `speed` × 1 ms: the handle's positions tick by tick.
std::vector<Vec2> raster(Vec2 lo, Vec2 hi, double spacing, double speed_m_per_s) {
  std::vector<Vec2> corners;
  bool right = true;
  for (double y = lo.y; y <= hi.y + 1e-12; y += spacing) {
    corners.push_back({right ? lo.x : hi.x, y});
    corners.push_back({right ? hi.x : lo.x, y});
    right = !right;
  }
  std::vector<Vec2> pts;
  const double step = speed_m_per_s * 0.001;
  for (std::size_t i = 0; i + 1 < corners.size(); ++i) {
    const double len = distance(corners[i], corners[i + 1]);
    const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
    for (int j = 0; j < n; ++j)
      pts.push_back(corners[i] + (static_cast<double>(j) / n) * (corners[i + 1] - corners[i]));
  }
  pts.push_back(corners.back());
  return pts;
}

// The handle's positions tick by tick along a → b at speed_m_per_s (1 ms ticks).
std::vector<Vec2> segment_path(Vec2 a, Vec2 b, double speed_m_per_s) {
  const int n = std::max(1, static_cast<int>(std::ceil(distance(a, b) / (speed_m_per_s * 0.001))));
  std::vector<Vec2> pts;
  for (int j = 0; j <= n; ++j) pts.push_back(a + (static_cast<double>(j) / n) * (b - a));
  return pts;
}

struct SweepStats {
  long ticks = 0, contact_ticks = 0;
  long over_lipschitz = 0;    // ticks with |ΔF| > k·|Δh| + 1e-9 (the limiter's jump allowance in use)
  long over_limit = 0;        // ticks with |ΔF| > k·|Δh| + jump_step + 1e-9 (must be none)
  double worst_excess_n = 0;  // max of |ΔF| − k·|Δh| [N]
  double max_force_n = 0;
};

// Drives the servo loop with the handle at `pts` (kinematically: the device reports exactly these).
SweepStats sweep(const Scene& sc, const ServoParams& sp, const std::vector<Vec2>& pts,
                 std::vector<ServoOutput>* outs = nullptr) {
  SceneStep loop(sc, sp);
  loop.start(pts.front());
  SweepStats st;
  Vec2 prev_f{0, 0}, prev_h = pts.front();
  ServoOutput so;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    ServoInput in;
    in.sample.handle_m = pts[i];
    in.sample.status = DeviceStatus::Ok;
    loop.update(in, so);
    const double df = distance(so.force_n, prev_f);
    const double lip = kK * distance(pts[i], prev_h);
    st.over_lipschitz += df > lip + 1e-9;
    st.over_limit += df > lip + kJump + 1e-9;
    st.worst_excess_n = std::max(st.worst_excess_n, df - lip);
    st.max_force_n = std::max(st.max_force_n, length(so.force_n));
    st.contact_ticks += so.contact.state != ContactState::Free;
    ++st.ticks;
    prev_f = so.force_n;
    prev_h = pts[i];
    if (outs) outs->push_back(so);
  }
  return st;
}

}  // namespace

// ── The profile ───────────────────────────────────────────────────────────────────────────────────

TEST(GrooveProfile, GoldenMagnitudesAndDirectionOnAStraightLine) {
  const Scene sc = line_scene();
  GrooveParams gp;
  gp.capture_radius_m = kR;
  gp.depth_n = kDepth;
  gp.stiffness_n_per_m = kK;
  gp.max_force_n = 3.5;
  gp.jump_step_n = 1e9;  // the golden values are the profile's, not the limiter's
  // min(k r, depth, k (R − r)) computed by hand for k = 800 N/m, R = 3 mm, depth = 1 N.
  const struct {
    double r_mm, f_n;
  } golden[] = {{0.0, 0.0}, {0.5, 0.4}, {1.25, 1.0}, {1.5, 1.0}, {2.9, 0.08}, {3.0, 0.0}, {3.5, 0.0}};
  for (const auto& g : golden) {
    GrooveSolver solver(sc, gp);
    const Vec2 h{0.0013, -g.r_mm * 1e-3};  // below the line: the pull points up, +y
    solver.reset(h, 0);
    ContactInput in;
    in.handle_m = h;
    in.level = 0;
    ContactOutput out;
    solver.update(in, out);
    EXPECT_NEAR(length(out.force_n), g.f_n, 1e-9) << "r = " << g.r_mm << " mm";
    EXPECT_NEAR(out.force_n.x, 0.0, 1e-9) << "r = " << g.r_mm << " mm";
    if (g.f_n > 0) {
      EXPECT_GT(out.force_n.y, 0.0) << "towards the line, r = " << g.r_mm << " mm";
    }
    if (g.r_mm < 2.99) {
      EXPECT_EQ(out.state, ContactState::Edge) << "r = " << g.r_mm << " mm";
      EXPECT_NEAR(out.proxy_m.x, h.x, 1e-12);
      EXPECT_NEAR(out.proxy_m.y, 0.0, 1e-12) << "the proxy holds the closest point";
      EXPECT_EQ(out.constraint[0].curve, 0);
      EXPECT_EQ(out.level, 0);
    }
    if (g.r_mm > 3.01) {
      EXPECT_EQ(out.state, ContactState::Free);
      EXPECT_EQ(out.proxy_m, h) << "outside the radius the proxy is the handle";
    }
  }
}

TEST(GrooveProfile, DepthAboveHalfTheRimSlopeGivesTheTriangle) {
  GrooveParams gp;
  gp.capture_radius_m = kR;
  gp.stiffness_n_per_m = kK;
  gp.depth_n = 5.0;  // more than k R / 2 = 1.2 N
  gp.max_force_n = 10.0;
  EXPECT_NEAR(groove_profile_n(gp, 0.0015), 1.2, 1e-12);
  EXPECT_NEAR(groove_profile_n(gp, 0.001), 0.8, 1e-12);
  EXPECT_NEAR(groove_profile_n(gp, 0.0025), 0.4, 1e-12);
  gp.max_force_n = 0.5;
  EXPECT_NEAR(groove_profile_n(gp, 0.0015), 0.5, 1e-12) << "clamped to max_force_n";
  EXPECT_EQ(groove_profile_n(gp, -1e-3), 0.0);
  EXPECT_EQ(groove_profile_n(gp, std::nan("")), 0.0);
}

TEST(GrooveSolver, EventsOnEnteringAndLeavingTheRadius) {
  const Scene sc = line_scene();
  GrooveParams gp;
  GrooveSolver solver(sc, gp);
  solver.reset({0.0, -0.005}, 0);
  ContactOutput out;
  int begins = 0, ends = 0, walks = 0, most_box_tests = 0;
  for (int i = 0; i <= 100; ++i) {
    ContactInput in;
    in.handle_m = {0.0, -0.005 + 0.0001 * i};
    in.level = 0;
    solver.update(in, out);
    begins += (out.events & kEventContactBegin) != 0;
    ends += (out.events & kEventContactEnd) != 0;
    EXPECT_EQ(out.path_count, 2);
    EXPECT_EQ(out.path_m[1], out.proxy_m);
    if (i == 0) {
      EXPECT_GE(out.budget_used, 1) << "the first closest point walks the tree";
    }
    walks += out.budget_used > 0;
    most_box_tests = std::max(most_box_tests, static_cast<int>(out.budget_used));
  }
  EXPECT_EQ(begins, 1);
  EXPECT_EQ(ends, 1);
  // Every tick walks the wide index, charged to the tick's budget, and opens no more than the nodes on
  // one path from the root and their neighbours.
  EXPECT_EQ(walks, 101);
  EXPECT_LE(most_box_tests, 2 * kWideBoxTestsPerNode * sc.wide_index().depth);
  EXPECT_EQ(out.state, ContactState::Free);
}

TEST(GrooveSolver, OutOfBudgetKeepsTheLastClosestPointWhileWithinTheRadius) {
  const Scene sc = line_scene();
  GrooveParams gp;
  GrooveSolver solver(sc, gp);
  solver.reset({0.001, -0.001}, 0);
  ContactInput in;
  in.level = 0;
  in.handle_m = {0.001, -0.001};
  ContactOutput out;
  solver.update(in, out);  // no limit: the exact answer
  ASSERT_EQ(out.state, ContactState::Edge);
  const Vec2 q = out.proxy_m;
  in.budget.max_box_tests = 1;  // too little for any walk below the root
  // 1.5 mm on, 2.5 mm from the line: the closest point needs a walk, which the budget refuses; within R of
  // the last closest point.
  in.handle_m = {0.001, -0.0025};
  solver.update(in, out);
  EXPECT_NE(out.events & kEventQueryBudget, 0u);
  EXPECT_TRUE(out.query.budget_exhausted);
  EXPECT_EQ(out.state, ContactState::Edge) << "the groove is followed from where it was";
  EXPECT_EQ(out.proxy_m, q);
  EXPECT_LE(out.budget_used, 1);
  EXPECT_GT(out.force_n.y, 0.0);
  in.handle_m = {0.0012, -0.0045};  // out of the last closest point's radius: free, no guess
  solver.update(in, out);
  EXPECT_EQ(out.state, ContactState::Free);
  EXPECT_NE(out.events & kEventContactEnd, 0u);
  EXPECT_EQ(out.proxy_m, in.handle_m);
}

// ── Continuity ────────────────────────────────────────────────────────────────────────────────────

TEST(GrooveContinuity, LoneStraightLineNeverNeedsTheLimiter) {
  const Scene sc = line_scene();
  for (const double speed : {0.08, 0.01}) {
    const auto pts = raster({-0.045, -0.006}, {0.045, 0.006}, speed > 0.02 ? 0.0005 : 0.0013, speed);
    const SweepStats st = sweep(sc, groove_servo_params(), pts);
    EXPECT_GT(st.contact_ticks, 0);
    EXPECT_NEAR(st.max_force_n, kDepth, 1e-6) << "the sweep reaches the groove's flat top";
    EXPECT_EQ(st.over_lipschitz, 0) << "speed " << speed << ": worst |ΔF| − k|Δh| = " << st.worst_excess_n << " N";
  }
}

TEST(GrooveContinuity, HairpinJumpsAreLimitedPerTick) {
  const Scene sc = hairpin_scene();
  for (const double speed : {0.08, 0.01}) {
    const auto pts = raster({-0.035, -0.006}, {0.03, 0.006}, speed > 0.02 ? 0.0005 : 0.0011, speed);
    const SweepStats st = sweep(sc, groove_servo_params(), pts);
    EXPECT_GT(st.contact_ticks, 0);
    EXPECT_EQ(st.over_limit, 0) << "speed " << speed << ": worst |ΔF| − k|Δh| = " << st.worst_excess_n << " N";
    // The medial axis between the legs is crossed: the closest point jumps there, so the jump allowance is
    // in use (otherwise the hairpin would not test the limiter at all).
    EXPECT_GT(st.over_lipschitz, 0) << "speed " << speed;
  }
}

TEST(GrooveContinuity, RandomBlobsAndStrokesWithLevelsFromSpeed) {
  std::mt19937 rng(14);
  std::vector<Polyline> curves;
  for (int i = 0; i < 4; ++i) curves.push_back(test::random_blob(rng, {-0.03 + 0.02 * i, 0.0}, 0.008, 200));
  curves.push_back(test::random_stroke(rng, {-0.04, 0.02}, 0.0005, 160));
  const Scene sc = Scene::build(curves, 5);
  // Alternately fast and slow rows (joined by short slow steps): the level follows the hand's speed in
  // grooves mode too.
  std::vector<Vec2> pts;
  bool fast = true, right = true;
  for (double y = -0.02; y <= 0.03; y += 0.004, fast = !fast, right = !right) {
    const Vec2 a{right ? -0.05 : 0.05, y}, b{right ? 0.05 : -0.05, y};
    if (!pts.empty()) {
      const auto join = segment_path(pts.back(), a, 0.02);
      pts.insert(pts.end(), join.begin(), join.end());
    }
    const auto row = segment_path(a, b, fast ? 0.25 : 0.02);
    pts.insert(pts.end(), row.begin(), row.end());
  }
  std::vector<ServoOutput> outs;
  const SweepStats st = sweep(sc, groove_servo_params(true, 1), pts, &outs);
  EXPECT_EQ(st.over_limit, 0) << "worst |ΔF| − k|Δh| = " << st.worst_excess_n << " N";
  long changes = 0, waits = 0;
  int lo = 99, hi = -1;
  for (const ServoOutput& so : outs) {
    changes += so.level_changed;
    waits += so.level != so.level_wanted;
    lo = std::min<int>(lo, so.level);
    hi = std::max<int>(hi, so.level);
  }
  EXPECT_GE(changes, 2) << "levels from hand speed apply in grooves mode";
  EXPECT_LT(lo, hi);
  EXPECT_EQ(waits, 0) << "in grooves mode a level change never waits (no wall to cross)";
}

// ── On the simulated pantograph ─────────────────────────────────────────────────────────────────

namespace {

struct DeviceRun {
  std::vector<Vec2> handle;  // what the servo saw [m]
  std::vector<Vec2> force;   // what it sent [N]
  std::vector<ServoOutput> out;
  Vec2 final_true;
};

// Runs the servo loop on the simulated pantograph with a model hand pulled along target(t).
template <class Target>
DeviceRun run_device(const Scene& sc, const ServoParams& sp, Vec2 start, double seconds, const ModelHandParams* hand,
                     Target target) {
  SimPantographParams dp;
  SimulatedPantograph dev(dp, start);
  dev.open();
  SceneStep loop(sc, sp);
  loop.start(dev.read().handle_m);
  DeviceRun run;
  ServoOutput so;
  const long n = static_cast<long>(seconds / sp.period_s);
  for (long k = 0; k < n; ++k) {
    ServoInput in;
    in.sample = dev.read();
    loop.update(in, so);
    dev.write_force(so.force_n);
    const Vec2 fh = hand ? model_hand_force(*hand, target(static_cast<double>(k) * sp.period_s), dev.true_position_m(),
                                            dev.velocity_m_per_s())
                         : Vec2{0.0, 0.0};
    dev.step(sp.period_s, fh);
    run.handle.push_back(in.sample.handle_m);
    run.force.push_back(so.force_n);
    run.out.push_back(so);
  }
  run.final_true = dev.true_position_m();
  return run;
}

}  // namespace

TEST(GrooveOnDevice, ReleasedHandRestsInTheCentre) {
  const Scene sc = line_scene();
  ServoParams sp = groove_servo_params();
  sp.guard.ramp_s = 0.5;  // as in the kiosk
  const Vec2 start{0.005, -0.002};
  // No hand at all, then a relaxed hand that stays near where it let go (a soft spring to the release point).
  ModelHandParams relaxed;
  relaxed.stiffness_n_per_m = 20.0;
  relaxed.damping_n_s_per_m = 0.5;
  const ModelHandParams* hands[] = {nullptr, &relaxed};
  for (const ModelHandParams* hand : hands) {
    const DeviceRun run = run_device(sc, sp, start, 3.0, hand, [&](double) { return start; });
    EXPECT_LT(std::fabs(run.final_true.y), 0.0002)
        << (hand ? "relaxed hand" : "no hand") << ": rests at y = " << run.final_true.y;
    // Settled: the last 0.2 s all within 0.2 mm of the line, in contact.
    for (std::size_t i = run.handle.size() - 200; i < run.handle.size(); ++i) {
      EXPECT_LT(std::fabs(run.handle[i].y), 0.0002);
      EXPECT_EQ(run.out[i].contact.state, ContactState::Edge);
    }
  }
  // Released outside the radius nothing pulls: the handle stays where it is.
  const Vec2 far{0.005, -0.005};
  const DeviceRun run = run_device(sc, sp, far, 1.0, nullptr, [&](double) { return far; });
  EXPECT_NEAR(run.final_true.y, far.y, 1e-6);
  for (const Vec2& f : run.force) EXPECT_EQ(length(f), 0.0);
}

TEST(GrooveOnDevice, HandDraggedAcrossFeelsTheGrooveAndLeavesIt) {
  const Scene sc = line_scene();
  ServoParams sp = groove_servo_params();
  sp.guard.ramp_s = 0.5;
  ModelHandParams hand;  // 200 N/m, 4 N·s/m, 2 N: the kiosk's default visitor
  ASSERT_EQ(hand.max_force_n, 2.0);
  const Vec2 from{0.0, -0.010}, to{0.0, 0.010};
  const double t0 = 0.6, speed = 0.05, t1 = t0 + distance(from, to) / speed;  // start after the ramp
  auto target = [&](double t) { return t < t0 ? from : (t > t1 ? to : from + ((t - t0) / (t1 - t0)) * (to - from)); };
  const DeviceRun run = run_device(sc, sp, from, t1 + 0.5, &hand, target);
  double peak_below = 0, peak_above = 0;
  long in_radius = 0;
  for (std::size_t i = 0; i < run.handle.size(); ++i) {
    const double y = run.handle[i].y;
    const Vec2 f = run.force[i];
    // Towards the line: up below it, down above it.
    if (y < 0) peak_below = std::max(peak_below, f.y);
    if (y > 0) peak_above = std::max(peak_above, -f.y);
    if (std::fabs(y) < kR) {
      ++in_radius;
      EXPECT_GE(f.y * -y, -1e-12) << "tick " << i << ": the pull never points away from the line";
    } else {
      EXPECT_EQ(length(f), 0.0) << "tick " << i << ": no force beyond the capture radius (y = " << y << ")";
    }
  }
  const double expected_peak = std::min(kDepth, kK * kR / 2);
  EXPECT_GE(peak_below, 0.8 * expected_peak) << "felt while going in";
  EXPECT_GE(peak_above, 0.8 * expected_peak) << "felt while climbing out";
  EXPECT_GT(in_radius, 50);
  EXPECT_GT(run.final_true.y, kR) << "the 2 N hand leaves the 1 N groove";
  EXPECT_EQ(length(run.force.back()), 0.0);
  EXPECT_EQ(run.out.back().contact.state, ContactState::Free);
}

TEST(GrooveOnDevice, ClosedCurveNeverBlocks) {
  const Scene sc = Scene::build({test::square(0.01)}, 3);
  const Vec2 from{-0.025, 0.0}, to{0.0, 0.0};  // from outside the square to its centre, 10 mm from every side
  ModelHandParams hand;
  const double t1 = distance(from, to) / 0.05;
  auto target = [&](double t) { return t > t1 ? to : from + (t / t1) * (to - from); };
  ServoParams grooves = groove_servo_params(false, 0);
  const DeviceRun in_grooves = run_device(sc, grooves, from, t1 + 1.0, &hand, target);
  EXPECT_LT(distance(in_grooves.final_true, to), 0.0005) << "the hand reaches the inside";
  bool touched = false;
  for (const ServoOutput& so : in_grooves.out) touched = touched || so.contact.state == ContactState::Edge;
  EXPECT_TRUE(touched) << "the groove was felt on the way";
  // The same hand with walls stays outside: the path does cross the curve.
  ServoParams walls = grooves;
  walls.render = RenderMode::Walls;
  const DeviceRun in_walls = run_device(sc, walls, from, t1 + 1.0, &hand, target);
  EXPECT_LT(in_walls.final_true.x, -0.005) << "a wall holds the hand outside (2.5 mm into it at 2 N)";
}

TEST(GrooveServo, SectionFollowsTheSolverInUseAndGainsReachTheGroove) {
  const Scene sc = line_scene();
  SceneStep loop(sc, groove_servo_params());
  EXPECT_EQ(&loop.section(), &loop.groove().section());
  ServoParams walls = groove_servo_params();
  walls.render = RenderMode::Walls;
  SceneStep wloop(sc, walls);
  EXPECT_EQ(&wloop.section(), &wloop.solver().section());

  // A gains change reaches the groove's law, through the per-tick limit.
  loop.start({0.0, -0.0005});
  ServoInput in;
  in.sample.handle_m = {0.0, -0.0005};
  in.sample.status = DeviceStatus::Ok;
  ServoOutput so;
  for (int i = 0; i < 20; ++i) loop.update(in, so);
  EXPECT_NEAR(so.force_n.y, 0.4, 1e-9);
  ServoGains g = loop.gains();
  g.stiffness_n_per_m = 400.0;
  g.max_force_n = 3.0;
  loop.set_gains(g);
  EXPECT_EQ(loop.params().groove.stiffness_n_per_m, 400.0);
  EXPECT_EQ(loop.params().groove.max_force_n, 3.0);
  EXPECT_EQ(loop.params().groove.jump_step_n, kJump);
  Vec2 prev = so.force_n;
  for (int i = 0; i < 20; ++i) {
    loop.update(in, so);
    EXPECT_LE(distance(so.force_n, prev), kJump + 1e-12) << "a still hand: at most jump_step per tick";
    prev = so.force_n;
  }
  EXPECT_NEAR(so.force_n.y, 0.2, 1e-9) << "400 N/m × 0.5 mm";
}
