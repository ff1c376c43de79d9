// Equal results: our collision tree, brute force and a Boost.Geometry R-tree answer the same first-hit
// and closest-point queries identically (the benchmark's peers must be checked, not trusted).
#include <gtest/gtest.h>

#include <random>

#include "curves.hpp"
#include "haptics/collision_query.hpp"
#include "peers.hpp"

using namespace hk;

TEST(Peers, FirstHitAndClosestPointAgreeAcrossMethods) {
  std::mt19937 rng(40);
  std::vector<Polyline> curves;
  std::uniform_real_distribution<double> ux(-0.06, 0.06), uy(-0.035, 0.035);
  for (int i = 0; i < 12; ++i) curves.push_back(test::random_blob(rng, {ux(rng), uy(rng)}, 0.01, 200));
  for (int i = 0; i < 12; ++i) curves.push_back(test::random_stroke(rng, {ux(rng), uy(rng)}, 0.0003, 200));
  const Scene sc = Scene::build(curves, 6);
  for (int level : {0, 3}) {
    const auto segs = bench::flat_segments(sc, level);
    const bench::BruteForce brute(segs);
    const bench::RtreeIndex rtree(segs);
    BoundarySection ours(sc);
    std::uniform_real_distribution<double> step(-0.0005, 0.0005);
    Vec2 p{0, 0};
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
      const Vec2 q = (i % 4 == 3) ? Vec2{ux(rng), uy(rng)} : Vec2{std::clamp(p.x + step(rng), -0.07, 0.07), std::clamp(p.y + step(rng), -0.045, 0.045)};
      const SweepHit h = ours.first_hit(p, q, level, nullptr, 0, QueryBudget{});
      const bench::PeerHit hb = brute.first_hit(p, q);
      const bench::PeerHit hr = rtree.first_hit(p, q);
      ASSERT_EQ(h.hit, hb.hit);
      ASSERT_EQ(hr.hit, hb.hit);
      if (hb.hit) {
        ++hits;
        ASSERT_EQ(h.t, hb.t);  // same segment, same formula: bit-identical
        ASSERT_EQ(hr.t, hb.t);
      }
      if (i % 10 == 0) {
        Vec2 cp;
        SegmentRef s;
        ASSERT_TRUE(ours.closest_point(q, level, 1.0, &cp, &s));
        ASSERT_NEAR(distance(q, cp), brute.closest_distance(q), 1e-15);
        ASSERT_NEAR(rtree.closest_distance(q), brute.closest_distance(q), 1e-15);
      }
      p = q;
    }
    EXPECT_GT(hits, 1000);
  }
}
