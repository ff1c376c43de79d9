// Equal results: our collision tree, brute force, a Boost.Geometry R-tree and Embree answer the same
// first-hit and closest-point queries identically (the benchmark's peers must be checked, not trusted).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "curves.hpp"
#include "embree_peer.hpp"
#include "haptics/collision_query.hpp"
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
    const Vec2 c{-half + kCell * (static_cast<double>(i % side) + 0.5) + jitter(rng), -half + kCell * (static_cast<double>(i / side) + 0.5) + jitter(rng)};
    curves.push_back(i % 2 == 0 ? test::random_blob(rng, c, 0.01, kPerCurve) : test::random_stroke(rng, c, 0.0003, kPerCurve));
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

// The original small scene, two levels, every query also against brute force and closest points.
TEST(Peers, FirstHitAndClosestPointAgreeAcrossMethods) {
  std::mt19937 rng(40);
  Vec2 half;
  const Scene sc = Scene::build(scene_curves(rng, 24 * 200, &half), 6);
  for (int level : {0, 3}) {
    const auto segs = bench::flat_segments(sc, level);
    const bench::BruteForce brute(segs);
    const bench::RtreeIndex rtree(segs);
    const bench::EmbreeIndex embree(segs);
    BoundarySection ours(sc);
    Walk walk{std::mt19937(41 + level), 0.0005, half};
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
      const Vec2 q = walk.next();
      const Vec2 p = walk.p;
      const SweepHit h = ours.first_hit(p, q, level, nullptr, 0, QueryBudget{});
      const bench::PeerHit hb = brute.first_hit(p, q);
      const bench::PeerHit hr = rtree.first_hit(p, q);
      const bench::PeerHit he = embree.first_hit(p, q);
      ASSERT_EQ(h.hit, hb.hit) << "query " << i;
      ASSERT_EQ(hr.hit, hb.hit) << "query " << i;
      ASSERT_EQ(he.hit, hb.hit) << "query " << i;
      if (hb.hit) {
        ++hits;
        ASSERT_EQ(h.t, hb.t);  // same segment, same formula: bit-identical
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
  }
}

// Issue 18: 100 000 queries per size, ours against the R-tree and Embree on every one, and against brute
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
  BoundarySection ours(sc);
  Walk walk{std::mt19937(7), 0.001, half};
  const std::size_t brute_every = target <= 1000 ? 1 : 50;
  int hits = 0, brute_checked = 0, closest_checked = 0;
  for (int i = 0; i < 100000; ++i) {
    const Vec2 p = walk.p, q = walk.next();
    const SweepHit h = ours.first_hit(p, q, 0, nullptr, 0, QueryBudget{});
    const bench::PeerHit hr = rtree.first_hit(p, q);
    const bench::PeerHit he = embree.first_hit(p, q);
    ASSERT_EQ(h.hit, hr.hit) << "query " << i;
    ASSERT_EQ(he.hit, hr.hit) << "query " << i;
    if (hr.hit) {
      ++hits;
      ASSERT_EQ(h.t, hr.t) << "query " << i;
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

INSTANTIATE_TEST_SUITE_P(Sizes, PeersAtSize, ::testing::Values(std::size_t{1000}, std::size_t{10000}, std::size_t{100000}));
