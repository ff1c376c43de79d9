// Equal results: our collision tree (first_hit with its boundary section, first_hit_wide through the wide
// index), brute force, a Boost.Geometry R-tree and Embree answer the same first-hit and closest-point
// queries identically (the benchmark's peers must be checked, not trusted).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "curves.hpp"
#include "embree_peer.hpp"
#include "haptics/collision_query.hpp"
#include "haptics/tolerance_cut.hpp"
#include "peers.hpp"

using namespace hk;

namespace {

// Blobs and thin strokes, one per cell of a square grid of 25 mm cells, about `segments` level-0 segments
// in all: the density of a picture stays the same as the scene grows, as in bench/first_hit.cpp's tiling.
// Writes the half extent of the plane they cover [m].
std::vector<Polyline> scene_curves(std::mt19937& rng, std::size_t segments, Vec2* half_extent) {
  constexpr int kPerCurve = 200;
  constexpr double kCell = 0.025;
  const std::size_t n = std::max<std::size_t>(2, segments / kPerCurve);
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  const double half = 0.5 * kCell * static_cast<double>(side);
  std::uniform_real_distribution<double> jitter(-0.2 * kCell, 0.2 * kCell);
  std::vector<Polyline> curves;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 c{-half + kCell * (static_cast<double>(i % side) + 0.5) + jitter(rng),
                 -half + kCell * (static_cast<double>(i / side) + 0.5) + jitter(rng)};
    curves.push_back(i % 2 == 0 ? test::random_blob(rng, c, 0.01, kPerCurve)
                                : test::random_stroke(rng, c, 0.0003, kPerCurve));
  }
  *half_extent = {half, half};
  return curves;
}

// The hand: a random walk with steps up to `step` [m] and, every fourth query, a jump of up to 30 mm
// (a fast stroke), kept within the plane.
struct Walk {
  std::mt19937 rng;
  double step;
  Vec2 half;
  Vec2 p{0, 0};
  int count = 0;
  Vec2 next() {
    const double reach = (count++ % 4 == 3) ? 0.03 : step;
    std::uniform_real_distribution<double> d(-reach, reach);
    return {std::clamp(p.x + d(rng), -half.x, half.x), std::clamp(p.y + d(rng), -half.y, half.y)};
  }
};

}  // namespace

// The original small scene, finer than, at and coarser than the wide index's item level (3), every query
// also against brute force and closest points.
TEST(Peers, FirstHitAndClosestPointAgreeAcrossMethods) {
  std::mt19937 rng(40);
  Vec2 half;
  const Scene sc = Scene::build(scene_curves(rng, 24 * 200, &half), 6);
  for (int level : {0, 1, 3, 5}) {
    const auto segs = bench::flat_segments(sc, level);
    const bench::BruteForce brute(segs);
    const bench::RtreeIndex rtree(segs);
    const bench::EmbreeIndex embree(segs);
    BoundarySection ours(sc), wide(sc);
    Walk walk{std::mt19937(41 + level), 0.0005, half};
    int hits = 0, ball_answers = 0;
    for (int i = 0; i < 20000; ++i) {
      const Vec2 q = walk.next();
      const Vec2 p = walk.p;
      const SweepHit h = ours.first_hit(p, q, level, nullptr, 0, QueryBudget{});
      QueryBudget unlimited;
      QueryStats stw;
      const SweepHit hw = wide.first_hit_wide(p, q, level, nullptr, 0, unlimited, &stw);
      ball_answers += stw.box_tests == 0;
      const bench::PeerHit hb = brute.first_hit(p, q);
      const bench::PeerHit hr = rtree.first_hit(p, q);
      const bench::PeerHit he = embree.first_hit(p, q);
      ASSERT_EQ(h.hit, hb.hit) << "query " << i;
      ASSERT_EQ(hw.hit, hb.hit) << "level " << level << " query " << i;
      ASSERT_EQ(hr.hit, hb.hit) << "query " << i;
      ASSERT_EQ(he.hit, hb.hit) << "query " << i;
      if (hb.hit) {
        ++hits;
        ASSERT_EQ(h.t, hb.t);  // same segment, same formula: bit-identical
        ASSERT_EQ(hw.t, hb.t);
        ASSERT_EQ(hr.t, hb.t);
        ASSERT_EQ(he.t, hb.t);
      }
      if (i % 10 == 0) {
        Vec2 cp;
        SegmentRef s;
        ASSERT_TRUE(ours.closest_point(q, level, 1.0, &cp, &s));
        const double d = brute.closest_distance(q);
        ASSERT_NEAR(distance(q, cp), d, 1e-15);
        ASSERT_NEAR(rtree.closest_distance(q), d, 1e-15);
        ASSERT_EQ(embree.closest_distance(q), d);  // the same segment's distance, same function
      }
      walk.p = q;
    }
    EXPECT_GT(hits, 1000);
    std::printf("level %d: first_hit_wide's ball answered %d of 20000 queries\n", level, ball_answers);
    if (level <= kWideItemLevel) {
      EXPECT_GT(ball_answers, 2000);  // the equality covers both of the wide index's paths, the walk and its ball
    } else {
      EXPECT_EQ(ball_answers, 0);  // coarser than the items: the tree's descent, which keeps no ball
    }
  }
}

// First hits and closest points at the tolerance cut instead of a level. Each of the eight steps' cuts (segments
// of mixed levels, joined where the level changes) is taken apart by the cut's own functions (tolerance_cut,
// joined_cut_points: bench::cut_segments) and handed to brute force, the R-tree and Embree; first_hit at
// level id kCutLevelBase + step walks the boundary section with the cut masks instead. 15 000 queries a step, 120 000
// in all, every one against the three peers: the same hits and t bit for bit; every 5th also a closest point on the
// whole cut (against brute force) and on one curve's (against its joined polyline, within 20 mm). Every 7th query is
// repeated on a second section with a budget of 6 optional box tests (a new one each step): an exact answer there must
// be the same, a blocked one must not claim the sweep clear past the true hit. The scene mixes smooth blobs and strokes
// with a staircase circle and squares, so that the cuts change level along curves (counted: the check must cover
// joins).
TEST(Peers, FirstHitAndClosestPointAtTheToleranceCutAgreeAcrossMethods) {
  std::mt19937 rng(44);
  Vec2 half;
  std::vector<Polyline> curves = scene_curves(rng, 20 * 200, &half);
  curves.push_back(test::staircase_circle({-0.02, 0.01}, 0.015, 0.0004));
  curves.push_back(test::sampled_square(0.012, 0.0005));
  curves.push_back(test::square(0.02));
  const Scene sc = Scene::build(curves, 6);
  BoundarySection ours(sc);
  std::size_t joined_levels = 0;  // consecutive cut segments of two levels, over all steps
  for (int step = 0; step < kToleranceSteps; ++step) {
    // A new budgeted section per step, from the root: one kept from the step before (a change of step keeps the
    // section) is refined near the walk already, and 6 box tests then seldom run out.
    BoundarySection budgeted(sc, 3e-4, ours.cut_walls());
    const auto segs = bench::cut_segments(sc, step);
    const bench::BruteForce brute(segs);
    const bench::RtreeIndex rtree(segs);
    const bench::EmbreeIndex embree(segs);
    std::vector<std::vector<Vec2>> joined(
        sc.curve_count());  // each curve's joined polyline, for closest points on one curve
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      std::vector<SegmentRef> cut;
      tolerance_cut(sc, c, kToleranceLadder_m[step], &cut);
      for (std::size_t i = 0; i + 1 < cut.size(); ++i) joined_levels += cut[i].level != cut[i + 1].level;
      joined[c] = joined_cut_points(sc, c, cut.data(), cut.size());  // closed: n vertices, open: n + 1
    }
    const auto curve_distance = [&](Vec2 q, std::size_t c) {
      const std::vector<Vec2>& v = joined[c];
      const std::size_t pieces = sc.curve(c).closed ? v.size() : v.size() - 1;
      double d = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < pieces; ++i) d = std::min(d, distance_to_segment(q, v[i], v[(i + 1) % v.size()]));
      return d;
    };
    Walk walk{std::mt19937(45 + step), 0.0005, half};
    int hits = 0, blocked = 0;
    for (int i = 0; i < 15000; ++i) {
      const Vec2 p = walk.p, q = walk.next();
      QueryBudget unlimited;
      const SweepHit h = ours.first_hit(p, q, kCutLevelBase + step, nullptr, 0, unlimited);
      const bench::PeerHit hb = brute.first_hit(p, q);
      const bench::PeerHit hr = rtree.first_hit(p, q);
      const bench::PeerHit he = embree.first_hit(p, q);
      ASSERT_FALSE(h.blocked) << "step " << step << " query " << i;
      ASSERT_EQ(h.hit, hb.hit) << "step " << step << " query " << i;
      ASSERT_EQ(hr.hit, hb.hit) << "step " << step << " query " << i;
      ASSERT_EQ(he.hit, hb.hit) << "step " << step << " query " << i;
      if (hb.hit) {
        ++hits;
        ASSERT_EQ(h.t, hb.t) << "step " << step << " query " << i;  // the same joined piece, the same formula
        ASSERT_EQ(hr.t, hb.t) << "step " << step << " query " << i;
        ASSERT_EQ(he.t, hb.t) << "step " << step << " query " << i;
        ASSERT_EQ(ours.cut_masks()[sc.node_of(h.segment)] >> step & 1, 1) << "the answer names a segment of the cut";
      }
      if (i % 5 == 0) {  // closest points on the cut: the whole scene, and one curve
        Vec2 cp;
        SegmentRef s;
        ASSERT_TRUE(ours.closest_point_cut(q, step, 1.0, &cp, &s)) << "step " << step << " query " << i;
        ASSERT_NEAR(distance(q, cp), brute.closest_distance(q), 1e-15) << "step " << step << " query " << i;
        ASSERT_EQ(ours.cut_masks()[sc.node_of(s)] >> step & 1, 1);
        const auto c = static_cast<std::size_t>(i / 5) % sc.curve_count();
        const double want = curve_distance(q, c);
        SegmentRef sc_seg;
        const bool found = ours.closest_point_cut(q, step, 0.02, &cp, &sc_seg, static_cast<int>(c));
        ASSERT_EQ(found, want <= 0.02) << "step " << step << " query " << i;
        if (found) {
          ASSERT_EQ(sc_seg.curve, static_cast<int>(c));
          ASSERT_NEAR(distance(q, cp), want, 1e-15) << "step " << step << " query " << i;
        }
      }
      if (i % 7 == 0) {
        QueryBudget small;
        small.max_box_tests = 6;
        const SweepHit hs = budgeted.first_hit(p, q, kCutLevelBase + step, nullptr, 0, small);
        if (hs.hit) {
          ASSERT_TRUE(hb.hit) << "step " << step << " query " << i;
          ASSERT_EQ(hs.t, hb.t) << "step " << step << " query " << i;
        } else if (hs.blocked) {
          ++blocked;
          if (hb.hit) {
            ASSERT_LE(hs.t, hb.t) << "step " << step << " query " << i;
          }
        } else {
          ASSERT_FALSE(hb.hit) << "step " << step << " query " << i;
        }
      }
      walk.p = q;
    }
    EXPECT_GT(hits, 1000) << "step " << step;
    EXPECT_GT(blocked, 0) << "step " << step;  // the budgeted path is exercised
  }
  EXPECT_GT(joined_levels, 100u);
}

// 100 000 queries per size, ours against the R-tree and Embree on every one, and against brute
// force on every query of the smallest size and on every 50th of the larger ones (brute force costs a
// pass over all segments per query). Closest points on every 10th query.
class PeersAtSize : public ::testing::TestWithParam<std::size_t> {};

TEST_P(PeersAtSize, HundredThousandQueriesAgree) {
  const std::size_t target = GetParam();
  std::mt19937 rng(static_cast<unsigned>(target));
  Vec2 half;
  const Scene sc = Scene::build(scene_curves(rng, target, &half), 6);
  const auto segs = bench::flat_segments(sc, 0);
  ASSERT_GT(segs.size(), target * 9 / 10);
  const bench::BruteForce brute(segs);
  const bench::RtreeIndex rtree(segs);
  const bench::EmbreeIndex embree(segs);
  BoundarySection ours(sc), wide(sc);
  Walk walk{std::mt19937(7), 0.001, half};
  const std::size_t brute_every = target <= 1000 ? 1 : 50;
  int hits = 0, brute_checked = 0, closest_checked = 0;
  for (int i = 0; i < 100000; ++i) {
    const Vec2 p = walk.p, q = walk.next();
    const SweepHit h = ours.first_hit(p, q, 0, nullptr, 0, QueryBudget{});
    QueryBudget unlimited;
    const SweepHit hw = wide.first_hit_wide(p, q, 0, nullptr, 0, unlimited);
    const bench::PeerHit hr = rtree.first_hit(p, q);
    const bench::PeerHit he = embree.first_hit(p, q);
    ASSERT_EQ(h.hit, hr.hit) << "query " << i;
    ASSERT_EQ(hw.hit, hr.hit) << "query " << i;
    ASSERT_EQ(he.hit, hr.hit) << "query " << i;
    if (hr.hit) {
      ++hits;
      ASSERT_EQ(h.t, hr.t) << "query " << i;
      ASSERT_EQ(hw.t, hr.t) << "query " << i;
      ASSERT_EQ(he.t, hr.t) << "query " << i;
    }
    if (i % brute_every == 0) {
      const bench::PeerHit hb = brute.first_hit(p, q);
      ASSERT_EQ(hb.hit, hr.hit) << "query " << i;
      if (hb.hit) {
        ASSERT_EQ(hb.t, hr.t) << "query " << i;
      }
      ++brute_checked;
    }
    if (i % 10 == 0) {
      Vec2 cp;
      SegmentRef s;
      ASSERT_TRUE(ours.closest_point(q, 0, 1.0, &cp, &s));
      const double d = rtree.closest_distance(q);
      ASSERT_NEAR(distance(q, cp), d, 1e-15) << "query " << i;
      ASSERT_NEAR(embree.closest_distance(q), d, 1e-15) << "query " << i;
      ++closest_checked;
    }
    walk.p = q;
  }
  EXPECT_GT(hits, 5000);  // the stream meets walls often enough for the equality to mean something
  EXPECT_GE(brute_checked, 2000);
  EXPECT_EQ(closest_checked, 10000);
}

INSTANTIATE_TEST_SUITE_P(Sizes, PeersAtSize,
                         ::testing::Values(std::size_t{1000}, std::size_t{10000}, std::size_t{100000}));

// ── Closest points seeded by the previous answer (closest points from coherence) ───────────

namespace {

// A closest-point answer, compared whole: found, point and segment.
struct Closest {
  bool found = false;
  Vec2 point;
  SegmentRef segment;
};
Closest closest(BoundarySection& section, Vec2 p, int level, double max_distance_m, int curve = -1,
                QueryBudget* budget = nullptr) {
  Closest c;
  c.found = section.closest_point(p, level, max_distance_m, &c.point, &c.segment, curve, budget);
  return c;
}
void expect_same(const Closest& a, const Closest& b, int query) {
  ASSERT_EQ(a.found, b.found) << "query " << query;
  if (!a.found) return;
  ASSERT_EQ(a.point.x, b.point.x) << "query " << query;
  ASSERT_EQ(a.point.y, b.point.y) << "query " << query;
  ASSERT_TRUE(a.segment == b.segment) << "query " << query << ": segment " << a.segment.segment << " against "
                                      << b.segment.segment;
}

}  // namespace

// Every tick of a hand's walk, seeded by the tick before, against a section reset before every call (so
// its walk is not seeded) and against brute force: the same point and segment, bit for bit. Calls with a
// 2 mm search radius are mixed in (the seed must not make "nothing within 2 mm" wrong). A seeded walk
// never opens more wide nodes than an unseeded one (counted on their budgets); what the seed mostly saves
// is exact segment distances, which the budget does not count (bench_first_hit: BM_Closest).
TEST(ClosestPointSeed, EveryTickAgreesWithAnUnseededWalkAndBruteForce) {
  std::mt19937 rng(52);
  Vec2 half;
  const Scene sc = Scene::build(scene_curves(rng, 10000, &half), 6);
  for (int level : {0, 2}) {
    const bench::BruteForce brute(bench::flat_segments(sc, level));
    BoundarySection seeded(sc), fresh(sc);
    Walk walk{std::mt19937(53 + level), 0.0003, half};
    int found_near = 0, nothing_near = 0;
    QueryBudget seeded_tests, fresh_tests;  // no limit: they count
    for (int i = 0; i < 20000; ++i) {
      const Vec2 q = walk.next();
      const double max_d = i % 3 == 2 ? 0.002 : 1.0;
      const int s0 = seeded_tests.box_tests_used, f0 = fresh_tests.box_tests_used;
      const Closest a = closest(seeded, q, level, max_d, -1, &seeded_tests);
      fresh.reset();
      const Closest b = closest(fresh, q, level, max_d, -1, &fresh_tests);
      // A tighter bound from the start prunes a subset of what the unseeded walk prunes, in the same order.
      ASSERT_LE(seeded_tests.box_tests_used - s0, fresh_tests.box_tests_used - f0) << "query " << i;
      expect_same(a, b, i);
      if (max_d < 1.0) (a.found ? found_near : nothing_near) += 1;
      if (i % 10 == 0 && max_d == 1.0) {
        ASSERT_TRUE(a.found);
        ASSERT_NEAR(distance(q, a.point), brute.closest_distance(q), 1e-15) << "query " << i;
      }
      walk.p = q;
    }
    EXPECT_GT(found_near, 500);
    EXPECT_GT(nothing_near, 500);
    EXPECT_LT(seeded_tests.box_tests_used, fresh_tests.box_tests_used) << "level " << level;
  }
}

// A seed is for one level and one curve: a call for another level or curve answers as an unseeded walk.
TEST(ClosestPointSeed, AnotherLevelOrCurveAnswersRight) {
  std::mt19937 rng(54);
  Vec2 half;
  const Scene sc = Scene::build(scene_curves(rng, 2000, &half), 6);
  BoundarySection seeded(sc), fresh(sc);
  const Vec2 p{0.001, -0.002};
  const Closest first = closest(seeded, p, 0, 1.0);
  ASSERT_TRUE(first.found);
  const Vec2 p2 = p + Vec2{1e-5, 0.0};
  expect_same(closest(seeded, p2, 0, 1.0), closest(fresh, p2, 0, 1.0), 0);
  fresh.reset();
  expect_same(closest(seeded, p2, 3, 1.0), closest(fresh, p2, 3, 1.0), 1);
  const int other_curve = first.segment.curve == 0 ? 1 : 0;
  fresh.reset();
  const Closest on_curve = closest(seeded, p2, 3, 1.0, other_curve);
  ASSERT_TRUE(on_curve.found);
  EXPECT_EQ(on_curve.segment.curve, other_curve);
  expect_same(on_curve, closest(fresh, p2, 3, 1.0, other_curve), 2);
  fresh.reset();
  expect_same(closest(seeded, p2, 0, 1.0), closest(fresh, p2, 0, 1.0), 3);  // back to the first level and every curve
}

// A point on a vertex is as near to the two segments that share it: the answer is the smaller segment
// index, unseeded and seeded alike, whichever of the two the seed is (segment n−1 and 0 share vertex 0
// of a closed curve).
TEST(ClosestPointSeed, TiesGoToTheSmallerSegment) {
  const Scene sc = Scene::build({test::sampled_square(0.01, 0.001)}, 3);
  const Vec2* pts = sc.points(0, 0);
  const std::uint32_t n = sc.curve(0).point_count[0];
  ASSERT_GT(n, 8u);
  for (std::uint32_t k : {0u, 5u, n - 1}) {
    BoundarySection section(sc);
    const Closest walked = closest(section, pts[k], 0, 1.0);
    ASSERT_TRUE(walked.found);
    EXPECT_EQ(walked.segment.segment, static_cast<std::int32_t>(k == 0 ? 0 : k - 1)) << "vertex " << k;
    EXPECT_EQ(walked.point.x, pts[k].x);
    EXPECT_EQ(walked.point.y, pts[k].y);
    // Seeded from either side of the vertex: from the larger segment, then the smaller.
    const Vec2 along = pts[(k + 1) % n] - pts[k];
    const Vec2 back = pts[(k + n - 1) % n] - pts[k];
    for (Vec2 from : {pts[k] + 0.2 * along, pts[k] + 0.2 * back}) {
      closest(section, from, 0, 1.0);
      expect_same(closest(section, pts[k], 0, 1.0), walked, static_cast<int>(k));
    }
  }
}

// Many segments about as near (60 parallel strokes 0.03 mm apart): every seeded answer stays exact.
TEST(ClosestPointSeed, ParallelStrokesStayExact) {
  std::vector<Polyline> curves;
  for (int i = 0; i < 60; ++i) {
    Polyline p;
    for (int j = 0; j <= 40; ++j) p.points_m.push_back({-0.01 + 0.0005 * j, -0.0009 + 0.00003 * i});
    curves.push_back(p);
  }
  const Scene sc = Scene::build(curves, 3);
  BoundarySection seeded(sc), fresh(sc);
  std::mt19937 rng(55);
  std::uniform_real_distribution<double> step(-2e-4, 2e-4);
  Vec2 p{0.0, 0.003};
  for (int i = 0; i < 4000; ++i) {
    p = {std::clamp(p.x + step(rng), -0.012, 0.012), std::clamp(p.y + step(rng), -0.004, 0.004)};
    const Closest a = closest(seeded, p, 0, 1.0);
    fresh.reset();
    expect_same(a, closest(fresh, p, 0, 1.0), i);
  }
}

// A walk the budget cuts short answers "unknown" (false, ran_out set), not "nothing close", and leaves
// no seed behind: the next call answers as an unseeded walk would.
TEST(ClosestPointSeed, ABudgetCutShortWalkIsUnknownAndLeavesNoSeed) {
  std::mt19937 rng(56);
  Vec2 half;
  const Scene sc = Scene::build(scene_curves(rng, 2000, &half), 6);
  BoundarySection section(sc);
  const Vec2 p{0.002, 0.001};
  QueryBudget walk_budget;
  const Closest walked = closest(section, p, 0, 1.0, -1, &walk_budget);
  ASSERT_TRUE(walked.found);
  EXPECT_GT(walk_budget.box_tests_used, 5);
  QueryBudget one;
  one.max_box_tests = 1;
  EXPECT_FALSE(closest(section, p + Vec2{1e-5, 0.0}, 0, 1.0, -1, &one).found);
  EXPECT_TRUE(one.ran_out);
  EXPECT_LE(one.box_tests_used, 1);
  QueryBudget after, unseeded;
  const Closest next = closest(section, p + Vec2{2e-5, 0.0}, 0, 1.0, -1, &after);
  BoundarySection fresh(sc);
  expect_same(next, closest(fresh, p + Vec2{2e-5, 0.0}, 0, 1.0, -1, &unseeded), 0);
  EXPECT_EQ(after.box_tests_used, unseeded.box_tests_used) << "no seed after a cut-short walk";
}
