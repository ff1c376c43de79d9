// Collision tree and swept query: containment of every error box, and first hits equal to brute force
// on ≥100,000 seeded swept segments, both coherent (servo-like) and random.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <unordered_set>

#include "crossing_grid.hpp"
#include "curves.hpp"
#include "haptics/collision_query.hpp"
#include "haptics/float_round.hpp"
#include "haptics/scene.hpp"

using namespace hk;

namespace {

std::vector<Polyline> random_scene(std::mt19937& rng, int blobs, int strokes) {
  std::uniform_real_distribution<double> ux(-0.06, 0.06), uy(-0.035, 0.035), ur(0.004, 0.02);
  std::uniform_int_distribution<int> un(20, 400);
  std::vector<Polyline> curves;
  for (int i = 0; i < blobs; ++i) curves.push_back(test::random_blob(rng, {ux(rng), uy(rng)}, ur(rng), un(rng)));
  for (int i = 0; i < strokes; ++i) curves.push_back(test::random_stroke(rng, {ux(rng), uy(rng)}, 0.0003, un(rng)));
  curves.push_back(test::staircase_circle({0.0, 0.0}, 0.03, 0.0002));
  return curves;
}

// Every original vertex lies in the box of the level-l segment that stands for it, at every level, within
// the level's measured error of that segment, and every finer segment under it lies in the box too. Arc
// positions computed here, independently of the tree.
void check_containment(const Scene& sc, const std::vector<Polyline>& input) {
  constexpr double tol = 1e-12;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    const Polyline& src = input[sc.source_index(c)];
    const CurveMultires m = build_multires(src, ci.levels - 1);  // the model on its own, outside the scene
    double arc = 0.0;
    std::size_t k = 0;
    const std::size_t s0 = ci.segment_count[0];
    for (std::size_t j = 0; j < src.points_m.size(); ++j) {
      if (j > 0) arc += distance(src.points_m[j - 1], src.points_m[j]);
      while (k + 1 < s0 && m.arc_m[k + 1] <= arc) ++k;
      for (int l = 0; l < ci.levels; ++l) {
        const std::uint32_t node = ci.box_offset[l] + static_cast<std::uint32_t>(k >> l);
        ASSERT_TRUE(box_contains(sc.box(node), src.points_m[j], tol))
            << "curve " << c << " vertex " << j << " level " << l;
        // The level's measured error covers the vertex's distance from the segment standing for it.
        Vec2 a, b;
        sc.segment_points(node, &a, &b);
        ASSERT_LE(distance_to_segment(src.points_m[j], a, b), ci.max_error_m[l] * (1.0 + 1e-12) + 1e-15)
            << "curve " << c << " vertex " << j << " level " << l;
      }
    }
    for (int l = 0; l < ci.levels; ++l) {
      for (std::uint32_t s = 0; s < ci.segment_count[l]; ++s) {
        const std::uint32_t node = ci.box_offset[l] + s;
        Vec2 a, b;
        sc.segment({static_cast<int>(c), l, static_cast<int>(s)}, &a, &b);
        ASSERT_TRUE(box_contains(sc.box(node), a, tol) && box_contains(sc.box(node), b, tol));
        // Every segment of every finer level under it (children, grandchildren, ... down to level 0),
        // found by index arithmetic here rather than through the tree's links: a miss on the box must
        // prove a miss on each of them, whatever level the query targets.
        for (int j = 0; j < l; ++j) {
          const std::uint32_t span = 1u << (l - j);
          for (std::uint32_t f = s * span; f < (s + 1) * span; ++f) {
            Vec2 fa, fb;
            sc.segment({static_cast<int>(c), j, static_cast<int>(f)}, &fa, &fb);
            ASSERT_TRUE(box_contains(sc.box(node), fa, tol) && box_contains(sc.box(node), fb, tol))
                << "curve " << c << " level " << l << " segment " << s << ": level-" << j << " segment " << f
                << " outside";
          }
        }
        // The links agree: a level-l segment's children are segments 2s and 2s+1 of level l−1.
        std::uint32_t first = 0, count = 0;
        sc.children(node, &first, &count);
        if (l == 0) {
          ASSERT_EQ(count, 0u);
        } else {
          ASSERT_EQ(count, 2u);
          ASSERT_EQ(first, ci.box_offset[l - 1] + 2 * s);
        }
      }
    }
  }
}

// A starved-budget run for an anytime first hit: 3000 random sweeps over a small random scene (seed
// `seed`), each through a fresh section with a budget of 1–12 box tests, at level `level_of(i)`. Checks
// what every anytime answer must satisfy (never a hit and blocked at once; exact when not blocked; a
// blocked answer never claims clear space past the true first wall) and hands each answer to
// `check(h, budget, st, hit_ref, t_ref, scene)` for the method's own checks. Counts the blocked and the exact answers.
template <class Query, class LevelOf, class Check>
void starved_queries(unsigned seed, Query&& query, LevelOf&& level_of, Check&& check, int* blocked, int* exact) {
  std::mt19937 rng(seed);
  const auto curves = random_scene(rng, 6, 6);
  const Scene sc = Scene::build(curves, 6);
  std::uniform_real_distribution<double> ux(-0.075, 0.075), uy(-0.05, 0.05);
  for (int i = 0; i < 3000; ++i) {
    BoundarySection section(sc);
    const Vec2 a{ux(rng), uy(rng)}, b{ux(rng), uy(rng)};
    QueryStats st;
    QueryBudget budget;
    budget.max_box_tests = 1 + i % 12;
    const int level = level_of(i);
    const SweepHit h = query(section, a, b, level, budget, st);
    double t_ref = 1.0;
    const bool hit_ref = test::brute_first_hit(sc, a, b, level, &t_ref, nullptr);
    ASSERT_FALSE(h.hit && h.blocked);
    check(h, budget, st, hit_ref, t_ref, sc);
    if (h.blocked) {
      ++*blocked;
      if (hit_ref) {
        ASSERT_LE(h.t, t_ref + 1e-12);
      }
    } else {
      ++*exact;
      ASSERT_EQ(h.hit, hit_ref) << "query " << i;
      if (hit_ref) {
        ASSERT_NEAR(h.t, t_ref, 1e-9);
      }
    }
  }
}

}  // namespace

TEST(CollisionTree, BoxesContainOriginalsAndChildren) {
  std::mt19937 rng(10);
  for (int trial = 0; trial < 5; ++trial) {
    const auto curves = random_scene(rng, 6, 6);
    const Scene sc = Scene::build(curves, 6);
    ASSERT_EQ(sc.curve_count(), curves.size());
    check_containment(sc, curves);
  }
}

// The box pass reads each level's originals in as many steps as the most any segment holds, except where
// the vertices bunch up (then each segment takes its own count): both must hold every original vertex, and
// the measured error must cover each one's distance from its segment. Curves: a long straight edge of two
// vertices running into a tight curl of 600 (a level-0 segment there holds over a dozen), the same closed, and a
// straight run whose vertices fall exactly on the level-0 points (3·2^6 segments of 2^-10 m: every arc
// length exact, so every vertex sits where the rounding of its segment's guess can tip either way).
TEST(CollisionTree, BoxesContainOriginalsWhereVerticesBunchUpOrSitOnLevelZeroPoints) {
  Polyline curl;
  curl.points_m.push_back({-0.06, 0.0});
  for (int i = 0; i < 600; ++i) {
    const double t = 0.05 * i;
    curl.points_m.push_back({0.02 + 0.0002 * std::sin(t) * (1.0 + 0.001 * i), 0.0002 * (1.0 - std::cos(t))});
  }
  Polyline closed_curl = curl;
  closed_curl.closed = true;
  Polyline exact;
  for (int i = 0; i <= 3 * 64; ++i) exact.points_m.push_back({std::ldexp(i, -10), 0.0});
  const std::vector<Polyline> curves{curl, closed_curl, exact};
  const Scene sc = Scene::build(curves, 6);
  ASSERT_EQ(sc.curve_count(), 3u);
  check_containment(sc, curves);
  // The straight run: level 0 is the original itself, so nothing deviates from it.
  EXPECT_EQ(sc.curve(2).max_error_m[0], 0.0);
}

// A box is no wider than it must be. For every segment box, the true deviation of the original
// under it (the largest distance of an original vertex or level-0 point under it from the segment's
// line, found here by arc length, not through the tree) against the box half-width: never below it
// (containment), and the median within 5 %.
TEST(CollisionTree, BoxesAreTightAroundTheOriginalUnderThem) {
  std::mt19937 rng(13);
  std::vector<double> ratio;
  for (int trial = 0; trial < 3; ++trial) {
    const auto curves = random_scene(rng, 6, 6);
    const Scene sc = Scene::build(curves, 6);
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      const CurveInfo& ci = sc.curve(c);
      const Polyline& src = curves[sc.source_index(c)];
      const CurveMultires m = build_multires(src, ci.levels - 1);  // the model on its own, outside the scene
      // Original vertices by the level-0 segment they fall in.
      std::vector<std::vector<Vec2>> under(ci.segment_count[0]);
      double arc = 0.0;
      std::size_t k = 0;
      for (std::size_t j = 0; j < src.points_m.size(); ++j) {
        if (j > 0) arc += distance(src.points_m[j - 1], src.points_m[j]);
        while (k + 1 < ci.segment_count[0] && m.arc_m[k + 1] <= arc) ++k;
        under[k].push_back(src.points_m[j]);
      }
      for (int l = 0; l < ci.levels; ++l) {
        for (std::uint32_t s = 0; s < ci.segment_count[l]; ++s) {
          Vec2 a, b;
          sc.segment({static_cast<int>(c), l, static_cast<int>(s)}, &a, &b);
          if (distance(a, b) == 0.0) continue;
          const Vec2 axis = (1.0 / distance(a, b)) * (b - a);
          double dev = 0.0;
          for (std::size_t k0 = static_cast<std::size_t>(s) << l; k0 < (static_cast<std::size_t>(s) + 1) << l; ++k0) {
            dev = std::max(dev, std::abs(cross(axis, m.scaling[0][k0] - a)));
            for (const Vec2& q : under[k0]) dev = std::max(dev, std::abs(cross(axis, q - a)));
          }
          const double half = box_half_width(sc.box(ci.box_offset[l] + s));
          ASSERT_GE(half + 1e-12, dev) << "curve " << c << " level " << l << " segment " << s;
          if (dev > 1e-6) ratio.push_back(half / dev);  // straight runs have no meaningful ratio
        }
      }
    }
  }
  ASSERT_GT(ratio.size(), 1000u);
  std::sort(ratio.begin(), ratio.end());
  const double median = ratio[ratio.size() / 2];
  EXPECT_LE(median, 1.05) << "median box half-width / true deviation over " << ratio.size() << " boxes";
  std::printf("box half-width / true deviation: median %.4f, p90 %.4f over %zu boxes\n", median,
              ratio[ratio.size() * 9 / 10], ratio.size());
}

// Compact storage: a level is a run of slots, one per point, a closed curve's first point
// repeated at the end, so segment k runs from point k to point k + 1 and the last segment of a closed
// level closes the loop on its first point (checked against the scaling coefficients of build_multires,
// the model built on its own: the scene transforms into its slots, bit for bit the same).
TEST(CollisionTree, SegmentsRunBetweenTheLevelsPointsAndClosedLevelsCloseTheLoop) {
  std::mt19937 rng(14);
  auto curves = random_scene(rng, 5, 5);
  // Curves without a model among them (one point; zero length): skipped, the others keep their sources.
  curves.insert(curves.begin() + 2, Polyline{{{0.01, 0.02}}, false});
  curves.insert(curves.begin() + 5, Polyline{{{0.03, 0.04}, {0.03, 0.04}, {0.03, 0.04}}, true});
  const Scene sc = Scene::build(curves, 6);
  ASSERT_EQ(sc.skipped_curves(), 2u);
  ASSERT_EQ(sc.curve_count(), curves.size() - 2);
  EXPECT_EQ(sc.source_index(2), 3u);
  EXPECT_EQ(sc.source_index(4), 6u);
  int closed = 0;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    closed += ci.closed ? 1 : 0;
    const CurveMultires m = build_multires(curves[sc.source_index(c)], ci.levels - 1);
    ASSERT_EQ(m.levels, ci.levels);
    for (std::size_t i = 0; i < m.arc_m.size(); ++i)
      ASSERT_EQ(sc.level0_arc_m(c, i), m.arc_m[i]) << "curve " << c << " point " << i;
    for (int l = 0; l < ci.levels; ++l) {
      const auto& pts = m.scaling[static_cast<std::size_t>(l)];
      ASSERT_EQ(ci.segment_count[l], ci.closed ? pts.size() : pts.size() - 1);
      for (std::uint32_t k = 0; k < ci.segment_count[l]; ++k) {
        Vec2 a, b;
        sc.segment({static_cast<int>(c), l, static_cast<int>(k)}, &a, &b);
        ASSERT_EQ(a, pts[k]);
        ASSERT_EQ(b, pts[(k + 1) % pts.size()]) << "curve " << c << " level " << l << " segment " << k;
        const NodeInfo in = sc.info(ci.box_offset[l] + k);
        ASSERT_EQ(in.curve, c);
        ASSERT_EQ(in.level, l);
        ASSERT_EQ(in.index, k);
      }
    }
  }
  EXPECT_GT(closed, 0);
}

// The memory target: every level's points, quantised boxes, tags and the tree above them in at
// most 64 bytes per level-0 segment (was 270 with whole double boxes, rectangles and links per node).
TEST(CollisionTree, AllLevelsFitSixtyFourBytesPerSegment) {
  std::mt19937 rng(15);
  const auto curves = random_scene(rng, 40, 40);
  const Scene sc = Scene::build(curves, 6);
  const double per_segment = static_cast<double>(sc.hot_bytes()) / static_cast<double>(sc.total_segments(0));
  EXPECT_LE(per_segment, 64.0);
  std::printf("scene storage: %.1f bytes per level-0 segment over %zu segments\n", per_segment, sc.total_segments(0));
}

TEST(CollisionTree, SceneHierarchyHoldsEveryCoarsestSegmentOnce) {
  std::mt19937 rng(12);
  const auto curves = random_scene(rng, 40, 40);
  const Scene sc = Scene::build(curves, 6);
  // Walk down from the scene root to the coarsest segments: each is reached exactly once, every
  // child box lies inside its parent's box, and no node fans out to more than a handful of children.
  std::vector<std::vector<int>> reached(sc.curve_count());
  for (std::size_t c = 0; c < sc.curve_count(); ++c)
    reached[c].assign(sc.curve(c).segment_count[sc.curve(c).levels - 1], 0);
  std::vector<std::uint32_t> stack{sc.scene_root()};
  while (!stack.empty()) {
    const std::uint32_t node = stack.back();
    stack.pop_back();
    if (sc.is_segment(node)) {
      const NodeInfo& in = sc.info(node);
      ASSERT_EQ(in.level, sc.curve(in.curve).levels - 1);
      ++reached[in.curve][in.index];
      continue;
    }
    std::uint32_t first = 0, count = 0;
    sc.children(node, &first, &count);
    ASSERT_GE(count, 1u);
    ASSERT_LE(count, 4u);
    for (std::uint32_t i = 0; i < count; ++i) {
      ASSERT_EQ(sc.parent(first + i), node);
      Vec2 corners[4];
      box_corners(sc.box(first + i), corners);
      for (const Vec2& q : corners) ASSERT_TRUE(box_contains(sc.box(node), q, 1e-12));
      stack.push_back(first + i);
    }
  }
  for (const auto& v : reached) {
    for (int r : v) EXPECT_EQ(r, 1);
  }
}

// aabb() is computed from a box's centre and half-extents, not its corners: it must still hold every corner as
// box_corners rounds it (the section's scan takes its distance as a lower bound on the box's, and the wide
// index's rectangles are built from it) and be no wider than the corners' rectangle by more than rounding.
TEST(CollisionTree, SegmentRectangleHoldsItsBoxCornersAndNoMore) {
  std::mt19937 rng(21);
  const auto curves = random_scene(rng, 30, 30);
  const Scene sc = Scene::build(curves, 6);
  std::size_t checked = 0;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    for (int l = 0; l < static_cast<int>(ci.levels); ++l) {
      for (std::int32_t k = 0; k < static_cast<std::int32_t>(ci.segment_count[l]); ++k) {
        const std::uint32_t node = sc.node_of(SegmentRef{static_cast<std::int32_t>(c), l, k});
        const Aabb r = sc.aabb(node);
        Vec2 corners[4];
        box_corners(sc.box(node), corners);
        Aabb tight{corners[0], corners[0]};
        for (const Vec2& q : corners) {
          ASSERT_LE(r.lo.x, q.x);
          ASSERT_LE(r.lo.y, q.y);
          ASSERT_GE(r.hi.x, q.x);
          ASSERT_GE(r.hi.y, q.y);
          tight.lo = {std::min(tight.lo.x, q.x), std::min(tight.lo.y, q.y)};
          tight.hi = {std::max(tight.hi.x, q.x), std::max(tight.hi.y, q.y)};
        }
        EXPECT_NEAR(r.lo.x, tight.lo.x, 1e-12);
        EXPECT_NEAR(r.lo.y, tight.lo.y, 1e-12);
        EXPECT_NEAR(r.hi.x, tight.hi.x, 1e-12);
        EXPECT_NEAR(r.hi.y, tight.hi.y, 1e-12);
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 1000u);
}

TEST(CollisionTree, ErrorGrowsWithLevelAndBoxesBoundIt) {
  std::mt19937 rng(11);
  const auto curves = random_scene(rng, 4, 4);
  const Scene sc = Scene::build(curves, 6);
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    for (int l = 0; l < ci.levels; ++l) {
      // The boxes' error bound bounds the measured deviation (plus the box padding), and is the
      // half-width combined with the reach past the segment ends, so never below the half-width.
      EXPECT_LE(ci.max_error_m[l], ci.max_error_bound_m[l] + 1e-8) << "curve " << c << " level " << l;
      EXPECT_GE(ci.max_error_bound_m[l], ci.max_box_half_width_m[l]);
    }
    EXPECT_GE(ci.max_error_m[ci.levels - 1] + 1e-12, ci.max_error_m[0]);
  }
}

TEST(CollisionTree, LevelMaximaAreThoseOfTheBoxesAsTheWalksRebuildThem) {
  // The build takes a level's widest box and largest error bound from the quantised extents; rebuilding
  // every box as the walks do (Scene::box) and taking the maxima here must give the same half-width, bit for
  // bit, and the same bound up to the rounding of the box's far end (length + u_over·q) [a few ulps].
  std::mt19937 rng(21);
  auto curves = random_scene(rng, 5, 5);
  curves.push_back(test::random_blob(rng, {0.02, -0.02}, 0.004, 24));  // a small closed curve, few levels
  const Scene sc = Scene::build(curves, 6);
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    for (int l = 0; l < ci.levels; ++l) {
      double widest = 0.0, bound = 0.0;
      for (std::uint32_t k = 0; k < ci.segment_count[l]; ++k) {
        Vec2 a, b;
        sc.segment(SegmentRef{static_cast<std::int32_t>(c), l, static_cast<std::int32_t>(k)}, &a, &b);
        const ErrorBox box = sc.box(ci.box_offset[l] + k);
        widest = std::max(widest, box_half_width(box));
        bound = std::max(bound, box_error_bound(box, distance(a, b)));
      }
      EXPECT_EQ(ci.max_box_half_width_m[l], widest) << "curve " << c << " level " << l;
      EXPECT_NEAR(ci.max_error_bound_m[l], bound, 1e-12 * bound + 1e-18) << "curve " << c << " level " << l;
      EXPECT_GT(bound, 0.0);
    }
  }
}

TEST(CollisionTree, SceneErrorBoundIsTheWidestBoxOfAnyCurveAtThatLevel) {
  // A short curve (few levels) and a long one: past the short curve's coarsest level, its coarsest boxes
  // still count.
  std::mt19937 rng(12);
  std::vector<Polyline> curves{test::random_blob(rng, {-0.03, 0}, 0.01, 16),
                               test::random_blob(rng, {0.03, 0}, 0.02, 400)};
  const Scene sc = Scene::build(curves, 6);
  ASSERT_LT(sc.curve(0).levels, sc.curve(1).levels);
  EXPECT_EQ(sc.max_curve_levels(), std::max(sc.curve(0).levels, sc.curve(1).levels));
  for (int l = 0; l < 8; ++l) {
    double widest = 0.0;
    for (std::size_t c = 0; c < 2; ++c) {
      const int top = std::min(l, sc.curve(c).levels - 1);
      widest = std::max(widest, sc.curve(c).max_box_half_width_m[top]);
    }
    EXPECT_EQ(sc.max_box_half_width_m(l), widest) << "level " << l;
  }
  EXPECT_EQ(Scene::build({}, 3).max_box_half_width_m(2), 0.0);
}

TEST(CollisionTree, SkipsDegenerateCurves) {
  std::vector<Polyline> curves(3);
  curves[0].points_m = {{0.01, 0.01}};                // one point
  curves[1].points_m = {{0.02, 0.02}, {0.02, 0.02}};  // zero length
  curves[2].points_m = {{0.0, 0.0}, {0.01, 0.0}};     // two points: a single short wall
  const Scene sc = Scene::build(curves, 6);
  EXPECT_EQ(sc.curve_count(), 1u);
  EXPECT_EQ(sc.skipped_curves(), 2u);
  EXPECT_EQ(sc.source_index(0), 2u);
}

class QueryVsBruteForce : public ::testing::TestWithParam<int> {};

TEST_P(QueryVsBruteForce, FirstHitEqualsBruteForce) {
  const int level = GetParam();
  std::mt19937 rng(20 + level);
  const auto curves = random_scene(rng, 8, 8);
  const Scene sc = Scene::build(curves, 6);
  BoundarySection section(sc);
  std::uniform_real_distribution<double> ux(-0.075, 0.075), uy(-0.05, 0.05), step(-0.0004, 0.0004);
  int hits = 0, checked = 0;
  auto check = [&](Vec2 a, Vec2 b) {
    QueryStats st;
    const SweepHit h = section.first_hit(a, b, level, nullptr, 0, QueryBudget{}, &st);
    double t_ref = 0.0;
    SegmentRef ref;
    const bool hit_ref = test::brute_first_hit(sc, a, b, level, &t_ref, &ref);
    ++checked;
    ASSERT_EQ(h.hit, hit_ref) << "a=(" << a.x << "," << a.y << ") b=(" << b.x << "," << b.y << ")";
    if (hit_ref) {
      ++hits;
      ASSERT_NEAR(h.t, t_ref, 1e-9);
      ASSERT_FALSE(st.budget_exhausted);
    }
  };
  // Coherent: a wandering handle, as the servo loop sees it (exercises splits and merges).
  Vec2 p{0.0, 0.0};
  for (int i = 0; i < 60000; ++i) {
    Vec2 q{std::clamp(p.x + step(rng), -0.075, 0.075), std::clamp(p.y + step(rng), -0.05, 0.05)};
    check(p, q);
    p = q;
  }
  // Random long sweeps across the scene.
  for (int i = 0; i < 45000; ++i) check({ux(rng), uy(rng)}, {ux(rng), uy(rng)});
  EXPECT_GE(checked, 100000);
  EXPECT_GT(hits, 5000);  // the stream really tests hits, not only misses
}

// Levels, and a tolerance step (each curve at its own level: hk/constants.hpp).
INSTANTIATE_TEST_SUITE_P(Levels, QueryVsBruteForce, ::testing::Values(0, 2, kToleranceLevelBase + 3));

// At tolerance steps the curves of one scene render at different levels; all three walks (first_hit through
// the boundary section, first_hit_wide and closest_point through the wide index) answer as brute force over
// each curve's own level does.
TEST(CollisionQuery, ToleranceStepsEqualBruteForceInEveryWalk) {
  std::mt19937 rng(118);
  const auto curves = random_scene(rng, 8, 8);
  const Scene sc = Scene::build(curves, 6);
  std::uniform_real_distribution<double> ux(-0.075, 0.075), uy(-0.05, 0.05), step(-0.0004, 0.0004);
  int mixed = 0, hits = 0, checked = 0;
  for (int t : {0, 3, 7}) {
    const int id = kToleranceLevelBase + t;
    int lo = 99, hi = -1;
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      lo = std::min(lo, sc.clamp_level(c, id));
      hi = std::max(hi, sc.clamp_level(c, id));
    }
    mixed += lo < hi;
    BoundarySection section(sc), wide(sc), closest(sc);
    auto check = [&](Vec2 a, Vec2 b) {
      const SweepHit h = section.first_hit(a, b, id, nullptr, 0, QueryBudget{});
      QueryBudget unlimited;
      const SweepHit hw = wide.first_hit_wide(a, b, id, nullptr, 0, unlimited);
      double t_ref = 0.0;
      SegmentRef ref;
      const bool hit_ref = test::brute_first_hit(sc, a, b, id, &t_ref, &ref);
      ++checked;
      ASSERT_EQ(h.hit, hit_ref) << "step " << t;
      ASSERT_EQ(hw.hit, hit_ref) << "step " << t;
      if (hit_ref) {
        ++hits;
        ASSERT_NEAR(h.t, t_ref, 1e-9);
        ASSERT_EQ(hw.t, h.t);
        ASSERT_EQ(h.segment.level, sc.clamp_level(static_cast<std::size_t>(h.segment.curve), id))
            << "a wall of the curve's own level";
      }
    };
    Vec2 p{0.0, 0.0};
    for (int i = 0; i < 25000; ++i) {
      const Vec2 q{std::clamp(p.x + step(rng), -0.075, 0.075), std::clamp(p.y + step(rng), -0.05, 0.05)};
      check(p, q);
      p = q;
    }
    for (int i = 0; i < 10000; ++i) check({ux(rng), uy(rng)}, {ux(rng), uy(rng)});
    for (int i = 0; i < 2000; ++i) {
      const Vec2 x{ux(rng), uy(rng)};
      const double best = test::brute_closest_distance(sc, x, id);
      Vec2 q;
      SegmentRef s;
      ASSERT_TRUE(closest.closest_point(x, id, 1.0, &q, &s));
      ASSERT_NEAR(distance(x, q), best, 1e-12) << "step " << t;
      ASSERT_EQ(s.level, sc.clamp_level(static_cast<std::size_t>(s.curve), id));
    }
  }
  EXPECT_GE(mixed, 2) << "the steps must put curves of the scene at different levels, or this tests nothing new";
  EXPECT_GE(checked, 100000);
  EXPECT_GT(hits, 5000);
}

// closest_point skipping the curves found so far lists every curve within the radius, nearest first, at a
// level, a tolerance step and a cut step (what level_change_is_safe gathers): the same set and distances as
// brute force over each curve's polyline for the id (test::polyline_at; the cut from tolerance_cut).
TEST(CollisionQuery, SkippingTheCurvesFoundListsEveryCurveWithinTheRadiusNearestFirst) {
  std::mt19937 rng(131);
  const auto curves = random_scene(rng, 10, 10);
  const Scene sc = Scene::build(curves, 6);
  BoundarySection section(sc);
  std::uniform_real_distribution<double> ux(-0.06, 0.06), uy(-0.035, 0.035);
  constexpr double kRadius_m = 0.004;
  int several = 0;
  for (const int id : {1, kToleranceLevelBase + 2, kCutLevelBase + 2}) {
    std::vector<std::vector<Vec2>> pl(sc.curve_count());
    for (std::size_t c = 0; c < sc.curve_count(); ++c) pl[c] = test::polyline_at(sc, c, id);
    for (int i = 0; i < 1500; ++i) {
      const Vec2 p{ux(rng), uy(rng)};
      std::vector<std::pair<double, int>> want;  // (distance, curve) of every curve within the radius
      for (std::size_t c = 0; c < sc.curve_count(); ++c) {
        const std::size_t n = pl[c].size(), pieces = sc.curve(c).closed ? n : n - 1;
        double d = 1e9;
        for (std::size_t k = 0; k < pieces; ++k) d = std::min(d, distance_to_segment(p, pl[c][k], pl[c][(k + 1) % n]));
        if (d <= kRadius_m) want.push_back({d, static_cast<int>(c)});
      }
      std::sort(want.begin(), want.end());
      int found[32];
      int n = 0;
      Vec2 q;
      SegmentRef s;
      while (n < 32 && section.closest_point(p, id, kRadius_m, &q, &s, -1, nullptr, found, n)) {
        ASSERT_LT(static_cast<std::size_t>(n), want.size())
            << "id " << id << ": a curve beyond the radius, or one already skipped";
        ASSERT_EQ(s.curve, want[static_cast<std::size_t>(n)].second) << "id " << id << ", the " << n << "th nearest";
        ASSERT_NEAR(distance(p, q), want[static_cast<std::size_t>(n)].first, 1e-12);
        found[n++] = s.curve;
      }
      ASSERT_EQ(static_cast<std::size_t>(n), want.size()) << "id " << id << ": every curve within the radius";
      several += n >= 3;
    }
  }
  EXPECT_GT(several, 100) << "points with three or more curves near, or the skipping is hardly tested";
}

TEST(CollisionQuery, BoundarySectionFollowsTheHandle) {
  std::vector<Polyline> curves{test::random_blob(*std::make_unique<std::mt19937>(5), {0, 0}, 0.02, 400)};
  const Scene sc = Scene::build(curves, 6);
  BoundarySection section(sc);
  ASSERT_EQ(section.section().size(), 1u);  // starts at the root
  // Sweeps that keep hitting the curve refine the section down to the target level near the hit...
  Vec2 a{-0.05, 0.0}, b{0.0, 0.0};
  for (int i = 0; i < 10; ++i) section.first_hit(a, b, 0, nullptr, 0, QueryBudget{});
  const std::size_t refined = section.section().size();
  EXPECT_GT(refined, 8u);
  // ... and far-away motion merges it back up: a hand circling the blob at 6 cm, 1 mm a tick (its full queries
  // owe the merge checks, the ticks the free-space ball answers pay them).
  Vec2 p{0.06, 0.0};
  for (int i = 1; i <= 400; ++i) {
    const double angle = i * 1e-3 / 0.06;
    const Vec2 q{0.06 * std::cos(angle), 0.06 * std::sin(angle)};
    ASSERT_FALSE(section.first_hit(p, q, 0, nullptr, 0, QueryBudget{}).hit);
    p = q;
  }
  EXPECT_LT(section.section().size(), refined);
}

// True when segment node `node` lies below the walls of level id `id` on its curve: finer than its level there,
// or at a cut step under a segment of the cut (read from the section's cut masks).
bool below_walls(const Scene& sc, const BoundarySection& section, std::uint32_t node, int id) {
  if (!is_cut_level(id)) return sc.tag_level(node) < sc.clamp_level(sc.tag_curve(node), id);
  for (std::uint32_t up = sc.parent(node); sc.is_segment(up); up = sc.parent(up)) {
    if (in_cut(section.cut_masks(), up, id - kCutLevelBase)) return true;
  }
  return false;
}

// A frontier: each node once, none below another, and no segment entry below the walls of any id in `ids`
// (its box then holds those walls).
void expect_frontier_serving(const Scene& sc, const BoundarySection& section, std::initializer_list<int> ids,
                             const char* where) {
  std::unordered_set<std::uint32_t> in(section.section().begin(), section.section().end());
  ASSERT_EQ(in.size(), section.section().size()) << "a node twice in the section " << where;
  for (std::uint32_t node : section.section()) {
    for (std::uint32_t up = section.entry_parent(node); up != 0xffffffffu; up = section.entry_parent(up)) {
      ASSERT_EQ(in.count(up), 0u) << "node " << node << " and its ancestor " << up << " both in the section " << where;
    }
    if (!sc.is_segment(node)) continue;
    for (int id : ids)
      ASSERT_FALSE(below_walls(sc, section, node, id)) << "an entry below the walls of id " << id << " " << where;
  }
}

// Brute-force first hit of a→b over polylines (test::polyline_at of each curve; test::cramer_sweep_hit per
// piece): the smallest sweep parameter, or false.
bool brute_first_hit_of(const Scene& sc, const std::vector<std::vector<Vec2>>& pl, Vec2 a, Vec2 b, double* t_out) {
  double best = 2.0;
  for (std::size_t c = 0; c < pl.size(); ++c) {
    const std::size_t n = pl[c].size(), pieces = sc.curve(c).closed ? n : n - 1;
    for (std::size_t k = 0; k < pieces; ++k) {
      double t = 0.0;
      if (test::cramer_sweep_hit(a, b, pl[c][k], pl[c][(k + 1) % n], &t)) best = std::min(best, t);
    }
  }
  *t_out = best;
  return best <= 1.0;
}

// The section's entries of segment nodes at level `level`.
int entries_at_level(const Scene& sc, const BoundarySection& section, int level) {
  int n = 0;
  for (std::uint32_t node : section.section()) n += sc.is_segment(node) && sc.tag_level(node) == level;
  return n;
}

// A change of level id keeps the boundary section (the contact solver changes level with hand speed, and
// renders both levels in turn until the proxy leaves the old one's walls): to a finer id the refined section
// stays as it is, to a coarser one (or a cut step) its entries below the new walls give way to their
// ancestors at them. Both with the wide frontier (ids at or below the items) and with the tree's (coarser ids, cut
// steps); a change between the two starts the section again from its root. Answers equal brute force throughout,
// over levels, tolerance steps and cut steps.
TEST(CollisionQuery, LevelChangesKeepTheSectionAndEqualBruteForce) {
  std::vector<Polyline> curves{test::random_blob(*std::make_unique<std::mt19937>(5), {0, 0}, 0.02, 400)};
  const Scene sc = Scene::build(curves, 6);
  ASSERT_GE(sc.curve_nodes(0).levels, 6u);
  ASSERT_EQ(wide_item_level(static_cast<int>(sc.curve_nodes(0).levels)), 3);
  BoundarySection section(sc);
  const Vec2 a{-0.05, 0.0}, b{0.0, 0.0};
  for (int i = 0; i < 10; ++i) section.first_hit(a, b, 2, nullptr, 0, QueryBudget{});
  EXPECT_TRUE(section.wide_frontier_active());
  const std::vector<std::uint32_t> refined = section.section();
  ASSERT_GT(refined.size(), 8u);
  // To a finer level: nothing to undo; the query descends below the section's level-2 entries without
  // splitting them while it also serves level 2 (the id before it).
  QueryStats st;
  section.first_hit(a, b, 0, nullptr, 0, QueryBudget{}, &st);
  EXPECT_EQ(st.splits, 0);
  EXPECT_EQ(section.section(), refined);
  ASSERT_NO_FATAL_FAILURE(expect_frontier_serving(sc, section, {0, 2}, "after a change to a finer level"));
  // To a coarser level the index still serves: the entries below level 3 are replaced by their level-3 ancestors
  // (the items), not by the root.
  section.first_hit(a, b, 3, nullptr, 0, QueryBudget{});
  EXPECT_TRUE(section.wide_frontier_active());
  ASSERT_NO_FATAL_FAILURE(expect_frontier_serving(sc, section, {0, 3}, "after a change to a coarser level"));
  EXPECT_GT(entries_at_level(sc, section, 3), 1) << "the refinement near the hit kept at the new level";
  EXPECT_EQ(entries_at_level(sc, section, 2), 0);
  // Past the items: the tree's frontier, from the scene root, and the same within it.
  section.first_hit(a, b, 4, nullptr, 0, QueryBudget{});
  EXPECT_FALSE(section.wide_frontier_active());
  for (int i = 0; i < 10; ++i) section.first_hit(a, b, 4, nullptr, 0, QueryBudget{});
  ASSERT_NO_FATAL_FAILURE(expect_frontier_serving(sc, section, {4}, "on the tree's frontier"));
  ASSERT_GT(entries_at_level(sc, section, 4), 1);
  section.first_hit(a, b, 5, nullptr, 0, QueryBudget{});
  ASSERT_NO_FATAL_FAILURE(
      expect_frontier_serving(sc, section, {4, 5}, "after a change to a coarser level past the items"));
  EXPECT_GT(entries_at_level(sc, section, 5), 1) << "the refinement near the hit kept at the new level";
  EXPECT_EQ(entries_at_level(sc, section, 4), 0);
  // To a cut step: entries under the cut give way to the cut's segments over them.
  section.first_hit(a, b, kCutLevelBase + 6, nullptr, 0, QueryBudget{});
  EXPECT_FALSE(section.wide_frontier_active());
  ASSERT_NO_FATAL_FAILURE(expect_frontier_serving(sc, section, {5, kCutLevelBase + 6}, "after a change to a cut step"));
  EXPECT_GT(section.section().size(), 4u);
  // Back to a level the index serves (twice: the two ids the section serves both): the wide frontier again.
  section.first_hit(a, b, 1, nullptr, 0, QueryBudget{});
  EXPECT_FALSE(section.wide_frontier_active()) << "it still serves the cut step";
  section.first_hit(a, b, 1, nullptr, 0, QueryBudget{});
  EXPECT_TRUE(section.wide_frontier_active());
  ASSERT_NO_FATAL_FAILURE(expect_frontier_serving(sc, section, {1}, "back on the wide frontier"));

  // A wandering hand whose level id changes as the servo's does: runs of one id, and runs of two ids in turn
  // (a level change's transition), over levels, tolerance steps and cut steps. Every answer against brute
  // force over the id's polylines; the section a frontier serving the id after every 97th query.
  std::mt19937 rng(41);
  const Scene big = Scene::build(random_scene(rng, 8, 8), 6);
  BoundarySection walk(big);
  const int ids[9] = {
      0, 1, 2, 3, 4, kToleranceLevelBase + 1, kToleranceLevelBase + 5, kCutLevelBase + 1, kCutLevelBase + 4};
  std::vector<std::vector<std::vector<Vec2>>> walls(9);
  for (int j = 0; j < 9; ++j) {
    for (std::size_t c = 0; c < big.curve_count(); ++c)
      walls[static_cast<std::size_t>(j)].push_back(test::polyline_at(big, c, ids[j]));
  }
  std::uniform_real_distribution<double> step(-0.0004, 0.0004);
  std::uniform_int_distribution<int> pick(0, 8), run(20, 400);
  Vec2 p{0.0, 0.0};
  int id = 0, other = 0, left = 0, hits = 0, checked = 0, changes = 0;
  bool alternate = false;
  for (int i = 0; i < 100000; ++i) {
    if (left-- == 0) {
      other = id;
      id = pick(rng);
      alternate = (rng() & 1) != 0;
      left = run(rng);
      changes += id != other;
    }
    const int now = alternate && (i & 1) ? other : id;
    const Vec2 q{std::clamp(p.x + step(rng), -0.075, 0.075), std::clamp(p.y + step(rng), -0.05, 0.05)};
    const SweepHit h = walk.first_hit(p, q, ids[now], nullptr, 0, QueryBudget{});
    double t_ref = 0.0;
    const bool hit_ref = brute_first_hit_of(big, walls[static_cast<std::size_t>(now)], p, q, &t_ref);
    ++checked;
    ASSERT_EQ(h.hit, hit_ref) << "tick " << i << ", id " << ids[now];
    if (hit_ref) {
      ++hits;
      ASSERT_NEAR(h.t, t_ref, 1e-9) << "tick " << i << ", id " << ids[now];
    }
    if (i % 97 == 0) {
      ASSERT_NO_FATAL_FAILURE(expect_frontier_serving(big, walk, {ids[now]}, "on the walk"));
    }
    p = q;
  }
  EXPECT_GT(changes, 100);
  EXPECT_GT(hits, 800);  // the walk really meets walls
  EXPECT_EQ(checked, 100000);
}

// Merges keep up with splits: on a long coherent walk over a dense scene (the hand passing through walls,
// as bench_first_hit's random walk does) the section stays bounded. With a fixed number of merge checks
// per tick, whatever the section's size, it grew to thousands of entries on this walk.
TEST(CollisionQuery, BoundarySectionStaysSmallOnALongWalk) {
  std::mt19937 rng(23);
  const Scene sc = Scene::build(random_scene(rng, 150, 150), 6);
  ASSERT_GT(sc.total_segments(0), 50000u);
  BoundarySection section(sc);
  std::normal_distribution<double> turn(0.0, 0.08), dv(0.0, 0.01);
  Vec2 p{0.0, 0.0};
  double heading = 0.3, speed = 0.1;  // [rad], [m/s]
  std::size_t largest = 0, total = 0;
  constexpr int kTicks = 200000;  // 200 s at 1 kHz
  for (int i = 0; i < kTicks; ++i) {
    heading += turn(rng);
    speed = std::clamp(speed + dv(rng), 0.02, 0.4);
    Vec2 q = p + (speed * 1e-3) * Vec2{std::cos(heading), std::sin(heading)};
    if (std::abs(q.x) > 0.06) heading = M_PI - heading;
    if (std::abs(q.y) > 0.035) heading = -heading;
    q = {std::clamp(q.x, -0.06, 0.06), std::clamp(q.y, -0.035, 0.035)};
    section.first_hit(p, q, 1, nullptr, 0, QueryBudget{});
    largest = std::max(largest, section.section().size());
    total += section.section().size();
    p = q;
    if (i % 997 == 0) {  // a frontier (splits and merges leave no stale entry), serving level 1
      ASSERT_NO_FATAL_FAILURE(expect_frontier_serving(sc, section, {1}, ("at tick " + std::to_string(i)).c_str()));
    }
  }
  std::printf("[ info ] section over %d ticks: mean %.1f, largest %zu entries\n", kTicks,
              static_cast<double>(total) / kTicks, largest);
  // This scene is dense (300 overlapping curves): ~120 entries near the hand on average are real work.
  // Merges that could not keep up let the section reach 9 000–18 000 entries on this walk.
  EXPECT_LE(static_cast<double>(total) / kTicks, 250.0);
  EXPECT_LE(largest, 1000u);
}

// The section's bound (kMaxSectionEntries): a sweep across 2 000 wavy strokes, repeated, splits every box it
// meets each tick and leaves none idle, so the section grows until it is full. Then splits are refused and the
// answers are still brute force's, the section still a frontier; a change to a coarser level at a full section
// starts again from the roots and answers the same. The section's storage stays within its bound whatever the
// scene's size.
TEST(CollisionQuery, AFullSectionRefusesSplitsAndStillAnswersAsBruteForce) {
  std::vector<Polyline> strokes;
  for (int k = 0; k < 2000; ++k) {  // vertical strokes 60 µm apart, each crossing y = 0 with a small wave
    Polyline s;
    const double x = -0.06 + 6e-5 * k;
    for (int i = 0; i < 64; ++i) {
      const double y = -0.005 + 0.01 * i / 63.0;
      s.points_m.push_back({x + 1e-5 * std::sin(400.0 * y + k), y});
    }
    strokes.push_back(s);
  }
  const Scene sc = Scene::build(strokes, 6);
  BoundarySection section(sc);
  std::vector<std::vector<Vec2>> walls0, walls3;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    walls0.push_back(test::polyline_at(sc, c, 0));
    walls3.push_back(test::polyline_at(sc, c, 3));
  }
  const auto expect_brute = [&](Vec2 a, Vec2 b, int level, const std::vector<std::vector<Vec2>>& walls,
                                const char* where) {
    const SweepHit h = section.first_hit(a, b, level, nullptr, 0, QueryBudget{});
    double t_ref = 0.0;
    const bool hit_ref = brute_first_hit_of(sc, walls, a, b, &t_ref);
    ASSERT_EQ(h.hit, hit_ref) << where;
    if (hit_ref) {
      ASSERT_NEAR(h.t, t_ref, 1e-9) << where;
    }
  };
  const Vec2 left{-0.061, 0.0}, right{0.061, 0.0};
  const std::size_t full = BoundarySection::kMaxSectionEntries - 16;  // within a node's children of the bound
  const auto fill = [&](const char* where) {
    for (int i = 0; i < 40; ++i)
      ASSERT_NO_FATAL_FAILURE(expect_brute(i % 2 ? right : left, i % 2 ? left : right, 0, walls0, where));
    ASSERT_GE(section.section().size(), full) << where;
    ASSERT_LE(section.section().size(), BoundarySection::kMaxSectionEntries + 16) << where;
    ASSERT_NO_FATAL_FAILURE(expect_frontier_serving(sc, section, {0}, where));
  };
  ASSERT_NO_FATAL_FAILURE(fill("filling the section"));
  // Sweeps across and along the strokes while the line keeps the section full (merges take idle entries back).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(-0.06, 0.06), y(-0.004, 0.004);
  int while_full = 0;
  for (int i = 0; i < 300; ++i) {
    ASSERT_NO_FATAL_FAILURE(
        expect_brute(i % 2 ? right : left, i % 2 ? left : right, 0, walls0, "the line, at the bound"));
    while_full += section.section().size() >= full;
    const Vec2 a{x(rng), y(rng)}, b{x(rng), y(rng)};
    ASSERT_NO_FATAL_FAILURE(expect_brute(a, b, 0, walls0, "a sweep at the bound"));
    ASSERT_LE(section.section().size(), BoundarySection::kMaxSectionEntries + 16);
  }
  EXPECT_GT(while_full, 150) << "sweeps made with the section full";
  ASSERT_NO_FATAL_FAILURE(expect_frontier_serving(sc, section, {0}, "after the sweeps at the bound"));
  // A coarser level at a full section: the entries' ancestors at it do not fit beside them, so the section starts
  // again from the roots (a few entries after one tick, where coarsening in place would keep thousands).
  ASSERT_NO_FATAL_FAILURE(fill("filling it again"));
  ASSERT_NO_FATAL_FAILURE(expect_brute(left, right, 3, walls3, "at the change to level 3"));
  EXPECT_LT(section.section().size(), 100u);
  for (int i = 0; i < 20; ++i) {
    ASSERT_NO_FATAL_FAILURE(
        expect_brute(i % 2 ? left : right, i % 2 ? right : left, 3, walls3, "after a change to level 3"));
  }
  ASSERT_NO_FATAL_FAILURE(expect_frontier_serving(sc, section, {0, 3}, "after the change"));
  // One byte a node, the wide frontier's parent links (4 B a wide node, with its byte, and 4 B an item) and the
  // bounded entries (~53 B each, 0.43 MB here; with 3 bytes a node this scene's 261 023 nodes made 1.2 MB).
  std::size_t items = 0;
  for (std::size_t c = 0; c < sc.curve_count(); ++c)
    items += sc.curve(c).segment_count[wide_item_level(static_cast<int>(sc.curve(c).levels))];
  EXPECT_LT(section.bytes(), sc.node_count() + 5 * sc.wide_index().nodes.size() + 4 * items + (std::size_t{1} << 19));
}

// What a sliding hand's walk did: its hits, its ticks within 1 mm of a wall, how many of those were answered
// without a full query, and the answers of the ball's walls.
struct SlideCounts {
  int hits = 0, near_walls = 0, near_walls_answered = 0, walls_answers = 0;
  int walls_merges = 0;  // merges made by the merge checks the walls' answers paid
};

// The ball's walls: a hand that meets walls and slides along them, the wall it rests on excluded (as the
// contact solver's edge contact does), 100 000 ticks over three level ids (levels and a tolerance step), with
// the scene and the hand moved by `offset` [m]. Every answer, hit or clear, and the segment hit, equals brute
// force over the level's polylines with the exclusion (asserted here); the counts go to *out, for the callers
// to say how many ticks near a wall were answered without a full query (the plain free-space ball there is
// only as large as the gap to the wall).
void slide_along_walls(Vec2 offset, SlideCounts* out) {
  std::mt19937 rng(61);
  std::vector<Polyline> curves = random_scene(rng, 8, 8);
  for (Polyline& c : curves) {
    for (Vec2& v : c.points_m) v = v + offset;
  }
  const Scene sc = Scene::build(curves, 6);
  BoundarySection section(sc);
  const int ids[3] = {0, 2, kToleranceLevelBase + 3};
  std::uniform_real_distribution<double> jitter(-0.0001, 0.0001), drift(-0.0004, 0.0004);
  std::uniform_int_distribution<int> slide(5, 60);
  int id = 0, hits = 0, near_walls = 0, near_walls_answered = 0, walls_answers = 0, walls_merges = 0;
  Vec2 p = offset, heading{0.0003, 0.0001};
  SegmentRef resting{};  // the wall slid along (excluded), while `sliding` ticks are left
  int sliding = 0;
  std::vector<SegmentRef> near_refs;
  for (int i = 0; i < 100000; ++i) {
    if (i % 5000 == 0) id = ids[(i / 5000) % 3];
    if (rng() % 50 == 0) heading = {drift(rng), drift(rng)};  // a new direction now and then
    Vec2 move = heading + Vec2{jitter(rng), jitter(rng)};
    if (sliding > 0) {  // along the wall, a little into it or away from it
      Vec2 w0, w1;
      sc.segment(resting, &w0, &w1);
      const Vec2 along = (w1 - w0) * (1.0 / std::max(distance(w0, w1), 1e-12));
      move = along * (dot(heading, along) >= 0 ? 0.0002 : -0.0002) + Vec2{jitter(rng), jitter(rng)};
    }
    const Vec2 q{std::clamp(p.x + move.x, offset.x - 0.07, offset.x + 0.07),
                 std::clamp(p.y + move.y, offset.y - 0.045, offset.y + 0.045)};
    const int n_excl = sliding > 0 ? 1 : 0;
    QueryStats st;
    const SweepHit h = section.first_hit(p, q, id, &resting, n_excl, QueryBudget{}, &st);
    double t_ref = 0.0;
    const bool hit_ref = test::brute_first_hit(sc, p, q, id, &t_ref, nullptr, &resting, n_excl, &near_refs);
    ASSERT_EQ(h.hit, hit_ref) << "tick " << i << ", id " << id;
    if (hit_ref) {
      ASSERT_NEAR(h.t, t_ref, 1e-9) << "tick " << i << ", id " << id;
      ASSERT_NE(std::find(near_refs.begin(), near_refs.end(), h.segment), near_refs.end())
          << "tick " << i << ": the segment hit";
    }
    if (st.ball_walls) {
      ++walls_answers;
      ASSERT_EQ(st.section_box_tests, 0) << "tick " << i << ": the walls answer without a section scan";
      ASSERT_LE(st.box_tests, 2) << "tick " << i
                                 << ": the walls answer without a box test but the merge checks it pays";
      walls_merges += st.merges;
    }
    if (test::brute_closest_distance(sc, q, id) < 0.001) {
      ++near_walls;
      near_walls_answered += st.section_box_tests == 0;  // no section scan: the ball or its walls answered
    }
    if (sliding > 0) --sliding;
    if (h.hit) {  // rest just before the wall and slide along it
      hits += 1;
      p = lerp(p, q, std::max(0.0, h.t - 1e-3));
      resting = h.segment;
      sliding = slide(rng);
      heading = Vec2{0.0, 0.0} - heading;  // and then back away from it
    } else {
      p = q;
    }
  }
  std::printf(
      "[ info ] sliding hand: %d hits, %d ticks within 1 mm of a wall, %.0f %% of them answered without a full query; "
      "%d answers by the ball's walls, which made %d merges\n",
      hits, near_walls, 100.0 * near_walls_answered / std::max(near_walls, 1), walls_answers, walls_merges);
  *out = SlideCounts{hits, near_walls, near_walls_answered, walls_answers, walls_merges};
}

// Near the origin, as the kiosk's scenes are: every answer as brute force, and most ticks near a wall answered by
// the ball or its walls.
TEST(CollisionQuery, BallWallsAnswerASlidingHandAsBruteForce) {
  SlideCounts n;
  ASSERT_NO_FATAL_FAILURE(slide_along_walls(Vec2{0.0, 0.0}, &n));
  EXPECT_GT(n.hits, 2000);
  EXPECT_GT(n.near_walls, 20000);
  EXPECT_GT(n.near_walls_answered, n.near_walls / 2);
  EXPECT_GT(n.walls_answers, n.near_walls / 4);
  EXPECT_GT(n.walls_merges, 0) << "the walls' answers pay the merge checks full queries left owed";
}

// Kilometres from the origin, where a float's step (0.5 mm at 4 km) is as large as the hand's step: the section's
// float rectangles and the scan's bounds must widen with the coordinates to stay conservative (without the
// widening and the scan's slack, a wall is missed within 150 ticks). Every answer as brute force; the balls are
// smaller there (the slack is 4 mm), so fewer ticks skip the full query, and that is not asserted.
TEST(CollisionQuery, BallWallsAnswerASlidingHandAsBruteForceFarFromTheOrigin) {
  SlideCounts n;
  ASSERT_NO_FATAL_FAILURE(slide_along_walls(Vec2{4000.0, -2500.0}, &n));
  EXPECT_GT(n.hits, 2000);
  EXPECT_GT(n.near_walls, 20000);
}

// The roundings of float_round.hpp, on doubles of every magnitude the scenes use and far past it, floats
// themselves and their neighbours, and zero: float_at_most and float_at_least on the right side of x and the
// nearest such floats (the next float out is past x); float_below and float_above on the right side of x and
// within 2^-19 of |x| (+ 2^-99) of it.
TEST(FloatRound, EachRoundingStaysOnItsSideOfX) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-40, 40);
  std::vector<double> xs = {0.0, -0.0, 1.0, -1.0, 0.1, -0.1, 1e-30, -1e-30, 1e30, -1e30};
  for (int i = 0; i < 200000; ++i) {
    const double x = std::ldexp(mantissa(rng), exponent(rng));
    xs.push_back(x);
    const auto f = static_cast<double>(static_cast<float>(x));  // a float itself, and a double just either side of it
    xs.push_back(f);
    xs.push_back(std::nextafter(f, 1e300));
    xs.push_back(std::nextafter(f, -1e300));
  }
  for (const double x : xs) {
    const float lo = float_at_most(x), hi = float_at_least(x);
    ASSERT_LE(static_cast<double>(lo), x) << x;
    ASSERT_GE(static_cast<double>(hi), x) << x;
    ASSERT_GT(static_cast<double>(std::nextafter(lo, std::numeric_limits<float>::infinity())), x) << x;
    ASSERT_LT(static_cast<double>(std::nextafter(hi, -std::numeric_limits<float>::infinity())), x) << x;
    const float below = float_below(x), above = float_above(x);
    ASSERT_LT(static_cast<double>(below), x) << x;
    ASSERT_GT(static_cast<double>(above), x) << x;
    const double loose = std::ldexp(std::abs(x), -19) + 0x1p-99;
    ASSERT_GE(static_cast<double>(below), x - loose) << x;
    ASSERT_LE(static_cast<double>(above), x + loose) << x;
  }
}

// The slab clip every box test of the query rests on (Liang–Barsky), checked against the segment's points
// themselves: 1 001 points along each of 20 000 random segments, each tested inside or outside the box in the
// box's own frame (dot and cross with its axis, not the clip). A clip that says "no" has no point well inside
// (1e-12 m in from every side); one that says [t0, t1] has every point well inside within it, and the points at
// t0 and t1 inside the box grown by 1e-12 m. Axis-aligned boxes with segments along an axis reach the
// parallel-slab case (a zero extent in the box's frame), inside the slab and outside it.
TEST(CollisionQuery, ClipSegmentBoxAgreesWithTheSegmentsPoints) {
  std::mt19937 rng(2027);
  std::uniform_real_distribution<double> u01(0.0, 1.0), pos(-0.03, 0.03), angle(0.0, 2.0 * M_PI);
  int hits = 0, misses = 0, parallel = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const bool aligned = trial % 4 == 0;
    const double phi = aligned ? 0.0 : angle(rng);
    ErrorBox box;
    box.origin_m = {pos(rng), pos(rng)};
    box.axis = {std::cos(phi), std::sin(phi)};
    box.u_min = -0.01 * u01(rng);
    box.u_max = 0.03 * u01(rng);
    box.n_min = -0.005 * u01(rng);
    box.n_max = 0.005 * u01(rng);
    const double margin = trial % 2 == 0 ? 0.0 : 3e-4;
    Vec2 a{pos(rng), pos(rng)}, b{pos(rng), pos(rng)};
    if (aligned && trial % 8 == 0) {  // along the axis: a zero extent across it
      b.y = a.y;
      ++parallel;
    } else if (aligned && trial % 8 == 4) {  // across the axis: a zero extent along it
      b.x = a.x;
      ++parallel;
    }
    // Inside the box grown by margin + grow (grow < 0: well inside), in the box's frame.
    auto inside = [&](Vec2 p, double grow) {
      const Vec2 r = p - box.origin_m;
      const double u = dot(r, box.axis), n = cross(box.axis, r), m = margin + grow;
      return u >= box.u_min - m && u <= box.u_max + m && n >= box.n_min - m && n <= box.n_max + m;
    };
    double t0 = -1.0, t1 = -1.0;
    const bool clipped = clip_segment_box(box, a, b, margin, &t0, &t1);
    clipped ? ++hits : ++misses;
    if (clipped) {
      ASSERT_LE(0.0, t0);
      ASSERT_LE(t0, t1);
      ASSERT_LE(t1, 1.0);
      ASSERT_TRUE(inside(lerp(a, b, t0), 1e-12)) << "trial " << trial;
      ASSERT_TRUE(inside(lerp(a, b, t1), 1e-12)) << "trial " << trial;
    }
    for (int k = 0; k <= 1000; ++k) {
      const double t = k / 1000.0;
      if (!inside(lerp(a, b, t), -1e-12)) continue;
      ASSERT_TRUE(clipped) << "trial " << trial << ": the point at t = " << t << " is inside";
      ASSERT_GE(t, t0 - 1e-9) << "trial " << trial;
      ASSERT_LE(t, t1 + 1e-9) << "trial " << trial;
    }
  }
  EXPECT_GT(hits, 2000);
  EXPECT_GT(misses, 2000);
  EXPECT_GT(parallel, 4000);
}

TEST(CollisionQuery, ExcludedSegmentIsIgnored) {
  Polyline wall;
  wall.points_m = {{-0.02, 0.0}, {0.02, 0.0}};
  const Scene sc = Scene::build({wall}, 6);
  BoundarySection section(sc);
  const SweepHit h = section.first_hit({0.001, 0.01}, {0.001, -0.01}, 0, nullptr, 0, QueryBudget{});
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.t, 0.5, 1e-12);
  const SweepHit h2 = section.first_hit({0.001, 0.01}, {0.001, -0.01}, 0, &h.segment, 1, QueryBudget{});
  EXPECT_FALSE(h2.hit);
}

TEST(CollisionQuery, AnytimeAnswerIsConservativeAndFromACoarserLevel) {
  int blocked = 0, exact = 0;
  starved_queries(
      6,
      [](BoundarySection& section, Vec2 a, Vec2 b, int level, QueryBudget& budget, QueryStats& st) {
        return section.first_hit(a, b, level, nullptr, 0, budget, &st);
      },
      [](int) { return 0; },
      [](const SweepHit& h, const QueryBudget&, const QueryStats& st, bool, double, const Scene&) {
        if (!h.blocked) return;
        // Never claims clear space past the true first wall (starved_queries); the answer comes from a coarser level.
        EXPECT_GT(h.segment.level, 0);
        EXPECT_TRUE(st.budget_exhausted);
      },
      &blocked, &exact);
  EXPECT_GT(blocked, 500);
  EXPECT_GT(exact, 50);  // budgets of 1–12 box tests from the root: a wide node opened is four of them
}

TEST(CollisionQuery, ClosestPointEqualsBruteForce) {
  std::mt19937 rng(7);
  const auto curves = random_scene(rng, 5, 5);
  const Scene sc = Scene::build(curves, 6);
  BoundarySection section(sc);
  std::uniform_real_distribution<double> ux(-0.07, 0.07), uy(-0.045, 0.045);
  for (int i = 0; i < 2000; ++i) {
    const Vec2 p{ux(rng), uy(rng)};
    const double best = test::brute_closest_distance(sc, p, 1);
    Vec2 q;
    SegmentRef s;
    ASSERT_TRUE(section.closest_point(p, 1, 1.0, &q, &s));
    EXPECT_NEAR(distance(p, q), best, 1e-12);
  }
}

// ── The wide index (wide_index.hpp) ──────────────────────────────────────────────────────────────────

namespace {

// The index's leaves: each item's segment node with its stored rectangle, found by walking every node.
struct WideLeaf {
  std::uint32_t node;
  float lo_x, lo_y, hi_x, hi_y;
};

std::vector<WideLeaf> wide_leaves(const Scene& sc) {
  std::vector<WideLeaf> out;
  for (const WideNode& n : sc.wide_index().nodes) {
    for (int i = 0; i < 4; ++i) {
      if (n.child[i] != kWideEmpty && (n.child[i] & kWideLeaf))
        out.push_back({n.child[i] & ~kWideLeaf, n.lo_x[i], n.lo_y[i], n.hi_x[i], n.hi_y[i]});
    }
  }
  return out;
}

}  // namespace

// A walk that opens every item rectangle a sweep or ball meets must meet every wall of every level the index
// holds (those at or below a curve's items): so every point of such a level's polyline lies in some item's
// rectangle. Checked here on points along each segment of each such level against all leaves, without the
// index's own item-to-segment arithmetic. The coarser levels are not held (their walks go through the tree).
TEST(WideIndex, EveryHeldLevelsPolylineLiesInSomeItemRectangle) {
  std::mt19937 rng(31);
  const auto curves = random_scene(rng, 8, 8);
  const Scene sc = Scene::build(curves, 6);
  const std::vector<WideLeaf> leaves = wide_leaves(sc);
  ASSERT_FALSE(leaves.empty());
  std::size_t points = 0;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    for (int l = 0; l <= wide_item_level(ci.levels); ++l) {
      for (std::uint32_t s = 0; s < ci.segment_count[l]; ++s) {
        Vec2 a, b;
        sc.segment({static_cast<int>(c), l, static_cast<int>(s)}, &a, &b);
        for (int k = 0; k <= 8; ++k) {
          const Vec2 p = lerp(a, b, k / 8.0);
          const bool held = std::any_of(leaves.begin(), leaves.end(), [p](const WideLeaf& r) {
            return r.lo_x <= p.x && p.x <= r.hi_x && r.lo_y <= p.y && p.y <= r.hi_y;
          });
          ASSERT_TRUE(held) << "curve " << c << " level " << l << " segment " << s << " at " << k << "/8";
          ++points;
        }
      }
    }
  }
  EXPECT_GT(points, 20000u);
}

// Each segment of the item level (a curve's coarsest when it has fewer levels) is a leaf exactly once, and
// every child slot's rectangle holds the rectangles of the node under it.
TEST(WideIndex, ItemsAppearOnceAndNodesHoldTheirChildren) {
  std::mt19937 rng(32);
  const auto curves = random_scene(rng, 12, 12);
  const Scene sc = Scene::build(curves, 6);
  std::vector<int> seen(sc.node_count(), 0);
  for (const WideLeaf& leaf : wide_leaves(sc)) ++seen[leaf.node];
  std::size_t items = 0;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    const int item = std::min(kWideItemLevel, ci.levels - 1);
    for (std::uint32_t s = 0; s < ci.segment_count[item]; ++s) {
      ASSERT_EQ(seen[ci.box_offset[item] + s], 1) << "curve " << c << " segment " << s;
      ++items;
    }
  }
  EXPECT_EQ(static_cast<std::size_t>(std::count(seen.begin(), seen.end(), 1)), items);
  const auto& nodes = sc.wide_index().nodes;
  for (const WideNode& n : nodes) {
    for (int i = 0; i < 4; ++i) {
      if (n.child[i] == kWideEmpty || (n.child[i] & kWideLeaf)) continue;
      ASSERT_LT(n.child[i], nodes.size());
      const WideNode& below = nodes[n.child[i]];
      for (int j = 0; j < 4; ++j) {
        if (below.child[j] == kWideEmpty) continue;
        ASSERT_TRUE(n.lo_x[i] <= below.lo_x[j] && n.lo_y[i] <= below.lo_y[j] && below.hi_x[j] <= n.hi_x[i] &&
                    below.hi_y[j] <= n.hi_y[i]);
      }
    }
  }
}

// The index's splits are rank splits along the longer axis of the item centres: with every item on one
// horizontal line (curves side by side, given in shuffled order so the items do not arrive sorted), each
// node's occupied slots must hold runs ordered along x, so a slot's rectangle ends where the next one
// begins, up to 10 µm: neighbouring items touch, and a rectangle also holds the pieces of the coarser
// levels' segments at its place, which reach about a micrometre past the item's own ends here. A split
// that left the items unsorted would interleave the slots by millimetres. A node of items only (at most
// four, the bottom of the tree) keeps them in the order they came (a walk orders a node's slots by
// distance itself), so its items are taken in x order; that they are a run of neighbours is checked one
// level up, where the node is a slot among its parent's, ordered and apart from the next.
TEST(WideIndex, SplitsByRankAlongTheLongerAxis) {
  std::mt19937 rng(41);
  std::vector<int> place(300);
  for (std::size_t i = 0; i < place.size(); ++i) place[i] = static_cast<int>(i);
  std::shuffle(place.begin(), place.end(), rng);
  std::vector<Polyline> curves;
  for (int at : place) {
    Polyline p;  // 8 points along x: 0.7 mm of line, 1 mm apart from the next curve's start
    for (int k = 0; k < 8; ++k) p.points_m.push_back({0.001 * at + 0.0001 * k, 0.05});
    curves.push_back(p);
  }
  const Scene sc = Scene::build(curves, 6);
  const auto& nodes = sc.wide_index().nodes;
  ASSERT_GT(nodes.size(), 20u);
  int pairs = 0, item_nodes = 0;
  for (const WideNode& n : nodes) {
    std::vector<int> order;  // occupied slots, in slot order, or by x for a node of items only
    bool items_only = true;
    for (int i = 0; i < 4; ++i) {
      if (n.child[i] == kWideEmpty) continue;
      order.push_back(i);
      items_only = items_only && (n.child[i] & kWideLeaf) != 0;
    }
    if (items_only) {
      std::sort(order.begin(), order.end(), [&](int a, int b) { return n.lo_x[a] < n.lo_x[b]; });
      ++item_nodes;
    }
    for (std::size_t j = 1; j < order.size(); ++j) {
      EXPECT_LE(n.hi_x[order[j - 1]], n.lo_x[order[j]] + 1e-5f)
          << "slots " << order[j - 1] << " and " << order[j] << " overlap along x";
      ++pairs;
    }
  }
  EXPECT_GT(pairs, 200);
  EXPECT_GT(item_nodes, 50);
}

// first_hit_wide under a starved budget: never claims clear space past the true first wall, says the
// budget ran out, and names no segment (no level is known above the items); with budget enough, exact.
TEST(WideIndex, AnytimeAnswerIsConservative) {
  int blocked = 0, exact = 0;
  starved_queries(
      33,
      [](BoundarySection& section, Vec2 a, Vec2 b, int level, QueryBudget& budget, QueryStats& st) {
        return section.first_hit_wide(a, b, level, nullptr, 0, budget, &st);
      },
      [](int i) { return i % 4 == 0 ? 2 : 0; },
      [](const SweepHit& h, const QueryBudget& budget, const QueryStats& st, bool hit_ref, double t_ref, const Scene&) {
        ASSERT_LE(budget.box_tests_used, budget.max_box_tests);  // no overrun: the wide walk has no section to scan
        if (!h.blocked) return;
        if (hit_ref) {
          ASSERT_LE(h.t, t_ref);
        }
        EXPECT_EQ(h.segment.level, Scene::kMaxLevels);
        EXPECT_TRUE(st.budget_exhausted);
      },
      &blocked, &exact);
  EXPECT_GT(blocked, 500);
  EXPECT_GT(exact, 50);  // budgets of 1–12 box tests from the root: a wide node opened is four of them
}

// Each item's rectangle is its error box's, grown only by the index's pad and the outward rounding to floats (a
// micrometre here, against the millimetres the coarser levels' chords added when the rectangles held them).
TEST(WideIndex, ItemRectanglesAreTheirErrorBoxes) {
  std::mt19937 rng(32);
  const Scene sc = Scene::build(random_scene(rng, 8, 8), 6);
  const std::vector<WideLeaf> leaves = wide_leaves(sc);
  ASSERT_FALSE(leaves.empty());
  constexpr double kSlack_m = 1e-6;  // pad (1 nm + 2^-18 of the largest coordinate, 0.1 m here) and float rounding
  for (const WideLeaf& leaf : leaves) {
    const Aabb box = sc.aabb(leaf.node);
    ASSERT_LE(leaf.lo_x, box.lo.x);
    ASSERT_LE(leaf.lo_y, box.lo.y);
    ASSERT_GE(leaf.hi_x, box.hi.x);
    ASSERT_GE(leaf.hi_y, box.hi.y);
    ASSERT_LE(box.lo.x - leaf.lo_x, kSlack_m);
    ASSERT_LE(box.lo.y - leaf.lo_y, kSlack_m);
    ASSERT_LE(leaf.hi_x - box.hi.x, kSlack_m);
    ASSERT_LE(leaf.hi_y - box.hi.y, kSlack_m);
  }
}

// The same at a level the wide index does not hold (coarser than its items): first_hit_wide descends the tree of
// error boxes, and a blocked answer names the box it stopped at, a segment at or above its curve's walls (or,
// above the curves, none), as first_hit's do.
TEST(WideIndex, AnytimeAnswerAboveTheItemsIsConservativeAndNamesABoxAtOrAboveTheWalls) {
  int blocked = 0, exact = 0, named = 0;
  static constexpr int kLevel = kWideItemLevel + 1;
  starved_queries(
      34,
      [](BoundarySection& section, Vec2 a, Vec2 b, int level, QueryBudget& budget, QueryStats& st) {
        return section.first_hit_wide(a, b, level, nullptr, 0, budget, &st);
      },
      [](int) { return kLevel; },
      [&named](const SweepHit& h, const QueryBudget& budget, const QueryStats& st, bool hit_ref, double t_ref,
               const Scene& sc) {
        ASSERT_LE(budget.box_tests_used, budget.max_box_tests);  // the descent's box tests are all optional
        if (!h.blocked) return;
        if (hit_ref) {
          ASSERT_LE(h.t, t_ref);
        }
        EXPECT_TRUE(st.budget_exhausted);
        if (h.segment.level == Scene::kMaxLevels) return;  // above the curves
        ++named;
        // A box at or above its curve's walls at this level: a segment of that level or coarser (a chunk is named
        // by its coarsest segments, which may be the walls themselves when the curve has no coarser level).
        EXPECT_GE(h.segment.level, sc.clamp_level(static_cast<std::size_t>(h.segment.curve), kLevel));
        EXPECT_LT(h.segment.level, sc.curve(static_cast<std::size_t>(h.segment.curve)).levels);
      },
      &blocked, &exact);
  EXPECT_GT(blocked, 500);
  EXPECT_GT(exact, 50);   // 98 here: a descent from the root needs more of the 1–12 box tests than a wide walk
  EXPECT_GT(named, 100);  // the descent got below the hierarchy before the budget ran out, often
}
