// Tolerance cut: the cut covers the curve once, in order; every original vertex is within the
// tolerance of the cut segment standing for it (distances computed here, from arc positions, not from the
// tree); it never needs more segments than the coarsest single level that meets the same tolerance. The
// tolerance steps the level policy may pick (each curve at the coarsest of its levels within the step):
// the level each curve gets, checked against the boxes and the original vertices.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "curves.hpp"
#include "haptics/collision_query.hpp"
#include "haptics/level_policy.hpp"
#include "haptics/scene.hpp"
#include "haptics/servo.hpp"
#include "haptics/tolerance_cut.hpp"
#include "hk/error.hpp"

using namespace hk;

namespace {

std::vector<Polyline> curves_for(std::mt19937& rng) {
  std::vector<Polyline> curves;
  for (int i = 0; i < 4; ++i) curves.push_back(test::random_blob(rng, {0.03 * i, 0.0}, 0.012, 300));
  for (int i = 0; i < 3; ++i) curves.push_back(test::random_stroke(rng, {0.03 * i, 0.03}, 0.0003, 250));
  curves.push_back(test::staircase_circle({0.0, -0.04}, 0.02, 0.0004));
  curves.push_back(test::sampled_square(0.015, 0.0005));
  return curves;
}

// Level-0 segment of every original vertex, by arc length (as the containment test finds it).
std::vector<std::size_t> level0_of_vertices(const Scene& sc, std::size_t c, const Polyline& src) {
  std::vector<std::size_t> seg(src.points_m.size());
  const CurveMultires m = build_multires(src, sc.curve(c).levels - 1);  // the model on its own, outside the scene
  const std::size_t s0 = sc.curve(c).segment_count[0];
  double arc = 0.0;
  std::size_t k = 0;
  for (std::size_t j = 0; j < src.points_m.size(); ++j) {
    if (j > 0) arc += distance(src.points_m[j - 1], src.points_m[j]);
    while (k + 1 < s0 && m.arc_m[k + 1] <= arc) ++k;
    seg[j] = k;
  }
  return seg;
}

}  // namespace

TEST(ToleranceCut, CoversTheCurveOnceAndKeepsEveryVertexWithinTheTolerance) {
  std::mt19937 rng(18);
  const auto curves = curves_for(rng);
  const Scene sc = Scene::build(curves, 6);
  for (double tol_mm : {0.05, 0.1, 0.2, 0.5, 1.0, 2.0}) {
    const double tol = tol_mm * 1e-3;
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      const CurveInfo& ci = sc.curve(c);
      std::vector<SegmentRef> cut;
      const CutStats st = tolerance_cut(sc, c, tol, &cut);
      ASSERT_EQ(st.segments, cut.size());
      // In order, each level-0 segment exactly once: the cut's level-0 ranges tile [0, s0).
      std::vector<std::size_t> owner(ci.segment_count[0]);
      std::size_t next = 0;
      for (std::size_t i = 0; i < cut.size(); ++i) {
        const SegmentRef s = cut[i];
        ASSERT_EQ(s.curve, static_cast<int>(c));
        const std::size_t k0 = static_cast<std::size_t>(s.segment) << s.level,
                          k1 = (static_cast<std::size_t>(s.segment) + 1) << s.level;
        ASSERT_EQ(k0, next) << "curve " << c << " tol " << tol_mm;
        for (std::size_t k = k0; k < k1; ++k) owner[k] = i;
        next = k1;
      }
      ASSERT_EQ(next, ci.segment_count[0]);
      // Every original vertex and level-0 point within the tolerance of its cut segment, or, where the cut
      // had to stop at level 0, within that level's own error.
      const double allowed = std::max(tol, ci.max_error_bound_m[0]) + 1e-9;
      const auto vseg = level0_of_vertices(sc, c, curves[sc.source_index(c)]);
      const auto& orig = curves[sc.source_index(c)].points_m;
      double worst = 0.0;
      for (std::size_t j = 0; j < orig.size(); ++j) {
        Vec2 a, b;
        sc.segment(cut[owner[vseg[j]]], &a, &b);
        worst = std::max(worst, distance_to_segment(orig[j], a, b));
      }
      for (std::size_t k = 0; k < ci.segment_count[0]; ++k) {
        Vec2 a, b;
        sc.segment(cut[owner[k]], &a, &b);
        worst = std::max(worst, distance_to_segment(sc.points(c, 0)[k], a, b));
      }
      EXPECT_LE(worst, allowed) << "curve " << c << " tol " << tol_mm << " mm";
      // No more segments than the coarsest single level that meets the tolerance everywhere.
      int single = 0;
      while (single + 1 < ci.levels && ci.max_error_bound_m[single + 1] <= tol) ++single;
      if (ci.max_error_bound_m[single] <= tol) {
        EXPECT_LE(st.segments, ci.segment_count[single]) << "curve " << c << " tol " << tol_mm;
      }
      EXPECT_EQ(st.vertices, st.segments + (ci.closed ? 0 : 1));
    }
  }
}

// The joined polyline (joined_cut_points): one vertex per junction; each piece inside its own segment's error
// box (so the tree's miss proofs still hold for it); every original vertex within its segment's box error
// bound plus how far the join moved that segment's ends, and the largest move is CutStats::max_join_shift_m.
TEST(ToleranceCut, JoinedPiecesLieInTheirBoxesAndKeepVerticesWithinBoundPlusShift) {
  std::mt19937 rng(21);
  const auto curves = curves_for(rng);
  const Scene sc = Scene::build(curves, 6);
  std::size_t breaks = 0;
  for (double tol_mm : {0.05, 0.1, 0.2, 0.5, 1.0, 2.0}) {
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      const CurveInfo& ci = sc.curve(c);
      std::vector<SegmentRef> cut;
      const CutStats st = tolerance_cut(sc, c, tol_mm * 1e-3, &cut);
      breaks += st.breaks;
      const std::vector<Vec2> pts = joined_cut_points(sc, c, cut.data(), cut.size());
      ASSERT_EQ(pts.size(), st.vertices);
      std::vector<double> shift(cut.size());
      double largest_shift = 0.0;
      for (std::size_t i = 0; i < cut.size(); ++i) {
        const Vec2 p0 = pts[i], p1 = pts[(i + 1) % pts.size()];
        const ErrorBox box = sc.box(sc.node_of(cut[i]));
        EXPECT_TRUE(box_contains(box, p0, 1e-9) && box_contains(box, p1, 1e-9))
            << "curve " << c << " piece " << i << " tol " << tol_mm;
        Vec2 a, b;
        sc.segment(cut[i], &a, &b);
        shift[i] = std::max(distance(p0, a), distance(p1, b));
        largest_shift = std::max(largest_shift, shift[i]);
      }
      EXPECT_DOUBLE_EQ(largest_shift, st.max_join_shift_m) << "curve " << c << " tol " << tol_mm;
      if (st.breaks == 0) {
        EXPECT_EQ(st.max_join_shift_m, 0.0);
      }
      // Original vertices, each against the piece of the cut segment over its level-0 segment.
      std::vector<std::size_t> owner(ci.segment_count[0]);
      for (std::size_t i = 0; i < cut.size(); ++i) {
        for (std::size_t k = std::size_t(cut[i].segment) << cut[i].level;
             k < (std::size_t(cut[i].segment) + 1) << cut[i].level; ++k)
          owner[k] = i;
      }
      const auto vseg = level0_of_vertices(sc, c, curves[sc.source_index(c)]);
      const auto& orig = curves[sc.source_index(c)].points_m;
      for (std::size_t j = 0; j < orig.size(); ++j) {
        const std::size_t i = owner[vseg[j]];
        Vec2 a, b;
        sc.segment(cut[i], &a, &b);
        const double bound = box_error_bound(sc.box(sc.node_of(cut[i])), distance(a, b));
        EXPECT_LE(distance_to_segment(orig[j], pts[i], pts[(i + 1) % pts.size()]), bound + shift[i] + 1e-9)
            << "curve " << c << " vertex " << j << " tol " << tol_mm;
      }
    }
  }
  EXPECT_GT(breaks, 20u);  // the scene mixes levels, so the joins were exercised
}

// The masks first_hit walks with at a cut step mark exactly the segments of each step's cut, and joined_cut_segment
// gives each cut segment the two vertices joined_cut_points gives its piece (bit for bit), on curves whose
// cuts change level (counted).
TEST(ToleranceCut, MasksMarkTheCutAndJoinedSegmentsAreThePiecesOfTheJoinedPolyline) {
  std::mt19937 rng(19);
  const auto curves = curves_for(rng);
  const Scene sc = Scene::build(curves, 6);
  const std::vector<std::uint8_t> masks = tolerance_cut_masks(sc);
  ASSERT_EQ(masks.size(), sc.node_count());
  std::size_t joins = 0;
  for (int step = 0; step < kToleranceSteps; ++step) {
    std::size_t marked = 0, in_cuts = 0;
    for (std::uint32_t n = 0; n < sc.node_count(); ++n) marked += (masks[n] >> step) & 1u;
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      std::vector<SegmentRef> cut;
      tolerance_cut(sc, c, kToleranceLadder_m[step], &cut);
      in_cuts += cut.size();
      const std::vector<Vec2> pts = joined_cut_points(sc, c, cut.data(), cut.size());
      for (std::size_t i = 0; i < cut.size(); ++i) {
        const std::uint32_t node = sc.node_of(cut[i]);
        ASSERT_EQ((masks[node] >> step) & 1u, 1u) << "step " << step << " curve " << c << " piece " << i;
        Vec2 a, b;
        joined_cut_segment(sc, masks.data(), node, step, &a, &b);
        const Vec2 want_b = pts[(i + 1) % pts.size()];
        ASSERT_EQ(a.x, pts[i].x) << "step " << step << " curve " << c << " piece " << i;
        ASSERT_EQ(a.y, pts[i].y) << "step " << step << " curve " << c << " piece " << i;
        ASSERT_EQ(b.x, want_b.x) << "step " << step << " curve " << c << " piece " << i;
        ASSERT_EQ(b.y, want_b.y) << "step " << step << " curve " << c << " piece " << i;
        if (i + 1 < cut.size()) joins += cut[i].level != cut[i + 1].level;
      }
    }
    EXPECT_EQ(marked, in_cuts) << "step " << step << ": a node marked that is not in the cut";
  }
  EXPECT_GT(joins, 20u);
}

// What the contact solver reads of a cut step (BoundarySection): every cut segment is a wall of it, with the
// joined polyline's end points, and its neighbours across each end are the cut's next and previous segments
// in curve order (none past an open curve's ends); first_hit_wide, which does not walk cuts, proves nothing
// clear there.
TEST(ToleranceCut, TheSectionGivesEachCutSegmentItsJoinedEndsAndItsNeighboursAlongTheCut) {
  std::mt19937 rng(21);
  const auto curves = curves_for(rng);
  const Scene sc = Scene::build(curves, 6);
  const BoundarySection section(sc);
  BoundarySection wide(sc);
  for (int step = 0; step < kToleranceSteps; ++step) {
    const int id = kCutLevelBase + step;
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      std::vector<SegmentRef> cut;
      tolerance_cut(sc, c, kToleranceLadder_m[step], &cut);
      const std::vector<Vec2> pts = joined_cut_points(sc, c, cut.data(), cut.size());
      const std::size_t n = cut.size();
      const bool closed = sc.curve(c).closed;
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_TRUE(section.is_wall(cut[i], id));
        Vec2 a, b;
        section.wall_points(cut[i], id, &a, &b);
        ASSERT_TRUE(a == pts[i] && b == pts[(i + 1) % pts.size()])
            << "step " << step << " curve " << c << " piece " << i;
        SegmentRef next, prev;
        const bool has_next = section.wall_neighbour(cut[i], id, +1, &next);
        const bool has_prev = section.wall_neighbour(cut[i], id, -1, &prev);
        ASSERT_EQ(has_next, closed || i + 1 < n) << "step " << step << " curve " << c << " piece " << i;
        ASSERT_EQ(has_prev, closed || i > 0) << "step " << step << " curve " << c << " piece " << i;
        if (has_next) {
          ASSERT_TRUE(next == cut[(i + 1) % n]) << "step " << step << " curve " << c << " piece " << i;
        }
        if (has_prev) {
          ASSERT_TRUE(prev == cut[(i + n - 1) % n]) << "step " << step << " curve " << c << " piece " << i;
        }
      }
    }
    QueryBudget unlimited;
    const SweepHit h = wide.first_hit_wide({-0.05, 0.0}, {0.05, 0.0}, id, nullptr, 0, unlimited);
    EXPECT_TRUE(h.blocked && !h.hit && h.t == 0.0) << "step " << step;
  }
}

// What the contact solver and the policy take from cut_bounds, checked by measuring: every original vertex
// lies within the step's error bound of its curve's joined cut, and every joined piece's ends lie within the
// step's widest half-width of their own box's axis (a joined piece stays in its box).
TEST(ToleranceCut, CutBoundsHoldTheOriginalAndThePieces) {
  std::mt19937 rng(20);
  const auto curves = curves_for(rng);
  const Scene sc = Scene::build(curves, 6);
  const std::vector<std::uint8_t> masks = tolerance_cut_masks(sc);
  const CutBounds cb = cut_bounds(sc, masks.data());
  for (int step = 0; step < kToleranceSteps; ++step) {
    double worst_vertex = 0.0, worst_side = 0.0;
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      std::vector<SegmentRef> cut;
      tolerance_cut(sc, c, kToleranceLadder_m[step], &cut);
      const std::vector<Vec2> pts = joined_cut_points(sc, c, cut.data(), cut.size());
      for (const Vec2& p : curves[sc.source_index(c)].points_m) {
        double d = 1e9;
        for (std::size_t i = 0; i < cut.size(); ++i)
          d = std::min(d, distance_to_segment(p, pts[i], pts[(i + 1) % pts.size()]));
        worst_vertex = std::max(worst_vertex, d);
      }
      for (std::size_t i = 0; i < cut.size(); ++i) {
        const ErrorBox box = sc.box(sc.node_of(cut[i]));
        for (const Vec2& e : {pts[i], pts[(i + 1) % pts.size()]})
          worst_side = std::max(worst_side, std::abs(cross(box.axis, e - box.origin_m)));
      }
    }
    EXPECT_LE(worst_vertex, cb.error_bound_m[step]) << "step " << step;
    EXPECT_LE(worst_side, cb.half_width_m[step] * (1.0 + 1e-9) + 1e-15) << "step " << step;
    EXPECT_GT(worst_vertex, 0.0);  // the measurement is not vacuous
  }
}

// A section built without the cut masks (what SceneStep builds outside level_mode = "cut") renders a cut
// step as the tolerance step of the same tolerance, and says so: first hits and closest points equal the
// tolerance step's, bit for bit.
TEST(ToleranceCut, ASectionWithoutCutsRendersACutStepAsItsToleranceStep) {
  std::mt19937 rng(22);
  const auto curves = curves_for(rng);
  const Scene sc = Scene::build(curves, 6);
  BoundarySection plain(sc, 3e-4, false), steps(sc, 3e-4, false), cuts(sc);
  EXPECT_FALSE(plain.has_cuts());
  EXPECT_TRUE(cuts.has_cuts());
  std::uniform_real_distribution<double> u(-0.03, 0.07);
  int hits = 0, differs = 0;
  for (int i = 0; i < 4000; ++i) {
    const int step = i % kToleranceSteps;
    const Vec2 a{u(rng), u(rng)}, b{u(rng), u(rng)};
    QueryBudget b1, b2, b3;
    const SweepHit h_cut = plain.first_hit(a, b, kCutLevelBase + step, nullptr, 0, b1);
    const SweepHit h_step = steps.first_hit(a, b, kToleranceLevelBase + step, nullptr, 0, b2);
    ASSERT_EQ(h_cut.hit, h_step.hit) << "query " << i;
    if (h_step.hit) {
      ++hits;
      ASSERT_EQ(h_cut.t, h_step.t) << "query " << i;
    }
    const SweepHit h_real = cuts.first_hit(a, b, kCutLevelBase + step, nullptr, 0, b3);
    differs += h_real.hit != h_step.hit || (h_step.hit && h_real.t != h_step.t);
    Vec2 p1, p2;
    SegmentRef s1, s2;
    const bool f1 = plain.closest_point_cut(b, step, 0.01, &p1, &s1);
    const bool f2 = steps.closest_point(b, kToleranceLevelBase + step, 0.01, &p2, &s2);
    ASSERT_EQ(f1, f2) << "query " << i;
    if (f1) {
      ASSERT_TRUE(p1 == p2 && s1 == s2) << "query " << i;
    }
  }
  EXPECT_GT(hits, 500);
  EXPECT_GT(differs, 0);  // the real cut is another set of walls: the fallback is not what cut mode renders
}

// In level_mode = "cut" the servo loop computes the cut masks once and both its solvers read that one copy
// (they were computed twice, a tenth of a second each at 10^6 segments); outside it neither has any. The
// shared copy is the scene's masks and bounds, and a section refuses another scene's.
TEST(ToleranceCut, TheServoLoopSharesOneCopyOfTheCutWallsBetweenItsSolvers) {
  std::mt19937 rng(23);
  const Scene sc = Scene::build(curves_for(rng), 6);
  ServoParams p;
  p.auto_level = true;
  p.steps = LevelSteps::Cuts;
  const SceneStep cut(sc, p);
  const std::shared_ptr<const CutWalls>& walls = cut.solver().section().cut_walls();
  ASSERT_NE(walls, nullptr);
  EXPECT_EQ(walls.get(), cut.groove().section().cut_walls().get()) << "one copy for both solvers";
  EXPECT_EQ(walls->masks, tolerance_cut_masks(sc));
  const CutBounds cb = cut_bounds(sc, walls->masks.data());
  for (int t = 0; t < kToleranceSteps; ++t) {
    EXPECT_EQ(cut.solver().section().cut_bounds().error_bound_m[t], cb.error_bound_m[t]);
    EXPECT_EQ(cut.solver().section().cut_bounds().half_width_m[t], cb.half_width_m[t]);
    EXPECT_GT(cb.error_bound_m[t], 0.0);
  }
  p.steps = LevelSteps::Levels;
  const SceneStep levels(sc, p);
  EXPECT_FALSE(levels.solver().section().has_cuts());
  EXPECT_FALSE(levels.groove().section().has_cuts());
  EXPECT_EQ(levels.solver().section().cut_bounds().error_bound_m[0], 0.0);

  std::mt19937 rng2(24);
  const Scene other = Scene::build(curves_for(rng2), 6);
  EXPECT_THROW(BoundarySection(other, 3e-4, walls), hk::ArgumentError);
  EXPECT_NO_THROW(BoundarySection(sc, 3e-4, walls));
}

TEST(ToleranceCut, EndsAreTheCoarsestLevelAndLevelZero) {
  std::mt19937 rng(19);
  const Scene sc = Scene::build(curves_for(rng), 6);
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    std::vector<SegmentRef> coarse, fine;
    const CutStats loose = tolerance_cut(sc, c, 1.0, &coarse);  // a metre: nothing is refined
    EXPECT_EQ(loose.segments, ci.segment_count[ci.levels - 1]);
    EXPECT_EQ(loose.breaks, 0u);                              // one level: the polyline is unbroken
    const CutStats tight = tolerance_cut(sc, c, 0.0, &fine);  // zero: everything down to level 0
    EXPECT_EQ(tight.segments, ci.segment_count[0]);
    EXPECT_EQ(tight.breaks, 0u);
    for (const SegmentRef& s : fine) EXPECT_EQ(s.level, 0);
    // Unbroken: the joined polyline is level 0's own points, the first repeated at the end of a closed curve.
    const std::vector<Vec2> pts = joined_cut_points(sc, c, fine.data(), fine.size());
    ASSERT_EQ(pts.size(), ci.point_count[0]);
    for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(pts[i], sc.points(c, 0)[i]);
  }
}

TEST(ToleranceCut, TighterToleranceNeverTakesFewerSegments) {
  std::mt19937 rng(20);
  const Scene sc = Scene::build(curves_for(rng), 6);
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    std::size_t last = 0;
    for (double tol_mm : {5.0, 2.0, 1.0, 0.5, 0.2, 0.1, 0.05}) {
      std::vector<SegmentRef> cut;
      const std::size_t n = tolerance_cut(sc, c, tol_mm * 1e-3, &cut).segments;
      EXPECT_GE(n, last) << "curve " << c << " tol " << tol_mm;
      last = n;
    }
  }
}

// ── Tolerance steps (level ids kToleranceLevelBase + t, hk/constants.hpp): each curve at its own level ──

namespace {

// The largest box_error_bound of level l of curve c, from the boxes themselves (not CurveInfo's record).
double level_bound_from_boxes(const Scene& sc, std::size_t c, int l) {
  double worst = 0.0;
  for (std::uint32_t k = 0; k < sc.curve(c).segment_count[l]; ++k) {
    const SegmentRef s{static_cast<int>(c), l, static_cast<int>(k)};
    Vec2 a, b;
    sc.segment(s, &a, &b);
    worst = std::max(worst, box_error_bound(sc.box(sc.node_of(s)), distance(a, b)));
  }
  return worst;
}

// The test scene with a straight line added: its every level is the line itself.
std::vector<Polyline> curves_with_a_line(std::mt19937& rng) {
  auto curves = curves_for(rng);
  Polyline line;
  for (int i = 0; i <= 200; ++i) line.points_m.push_back({-0.05 + 0.0004 * i, 0.06 + 0.0001 * i});
  curves.push_back(line);
  return curves;
}

}  // namespace

TEST(ToleranceSteps, EachCurveTakesTheCoarsestOfItsLevelsWithinTheStep) {
  std::mt19937 rng(21);
  const auto curves = curves_with_a_line(rng);
  const Scene sc = Scene::build(curves, 6);
  ASSERT_EQ(sc.curve_count(), curves.size());
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    std::vector<double> bound(static_cast<std::size_t>(ci.levels));
    for (int l = 0; l < ci.levels; ++l) bound[static_cast<std::size_t>(l)] = level_bound_from_boxes(sc, c, l);
    const auto vseg = level0_of_vertices(sc, c, curves[sc.source_index(c)]);
    const auto& orig = curves[sc.source_index(c)].points_m;
    int last = 0;
    for (int t = 0; t < kToleranceSteps; ++t) {
      const double tol = kToleranceLadder_m[t];
      const int l = sc.clamp_level(c, kToleranceLevelBase + t);
      ASSERT_GE(l, 0);
      ASSERT_LT(l, ci.levels);
      EXPECT_GE(l, last) << "a looser step never takes a finer level (curve " << c << ")";
      last = l;
      if (l > 0) {
        EXPECT_LE(bound[static_cast<std::size_t>(l)], tol) << "curve " << c << " step " << t;
      }
      for (int coarser = l + 1; coarser < ci.levels; ++coarser) {
        EXPECT_GT(bound[static_cast<std::size_t>(coarser)], tol)
            << "curve " << c << " step " << t << ": level " << coarser << " is within it too";
      }
      // What the bound promises, measured: every original vertex within the step's tolerance (or, at level
      // 0, that level's own error) of the level-l segment standing for it.
      const double allowed = (l > 0 ? tol : std::max(tol, bound[0])) + 1e-9;
      for (std::size_t j = 0; j < orig.size(); ++j) {
        Vec2 a, b;
        sc.segment({static_cast<int>(c), l, static_cast<int>(vseg[j] >> l)}, &a, &b);
        ASSERT_LE(distance_to_segment(orig[j], a, b), allowed) << "curve " << c << " step " << t << " vertex " << j;
      }
    }
  }
  // The straight line is exact at every level: its coarsest at every step.
  const std::size_t line = sc.curve_count() - 1;
  for (int t = 0; t < kToleranceSteps; ++t)
    EXPECT_EQ(sc.clamp_level(line, kToleranceLevelBase + t), sc.curve(line).levels - 1);
}

TEST(ToleranceSteps, NeverMoreSegmentsThanTheOneLevelWithinTheSameToleranceAndFewerOnAMixedScene) {
  std::mt19937 rng(22);
  const Scene sc = Scene::build(curves_with_a_line(rng), 6);
  int fewer = 0;
  for (int t = 0; t < kToleranceSteps; ++t) {
    const double tol = kToleranceLadder_m[t];
    int single = 0;  // the coarsest level, the same for every curve, within the tolerance everywhere
    for (int l = 0; l < sc.max_curve_levels(); ++l) {
      if (sc.max_error_bound_m(l) <= tol) single = l;
    }
    const std::size_t per_curve = sc.total_segments(kToleranceLevelBase + t), one_level = sc.total_segments(single);
    EXPECT_LE(per_curve, one_level) << "step " << t;
    fewer += per_curve < one_level;
    EXPECT_LE(sc.max_error_bound_m(kToleranceLevelBase + t), std::max(tol, sc.max_error_bound_m(0))) << "step " << t;
  }
  EXPECT_GE(fewer, kToleranceSteps / 2) << "on a scene of blobs, strokes and a line, per-curve levels save segments";
}

TEST(ToleranceSteps, LabelsReadAsATolerance) {
  EXPECT_EQ(level_label(3), "level 3");
  EXPECT_EQ(level_label(kToleranceLevelBase + 2), "tolerance 0.25 mm");
  EXPECT_EQ(level_label(kToleranceLevelBase + kToleranceSteps - 1), "tolerance 2.50 mm");
}
