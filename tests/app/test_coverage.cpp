// Coverage of a run: the fraction of the level-0 curves' length the proxy came within
// 1 mm of, and the curves it touched. Golden values from the geometry of hand-made scenes and paths.
#include <gtest/gtest.h>

#include <cmath>

#include "curves.hpp"
#include "haptics/multires.hpp"
#include "runtime/coverage.hpp"

namespace hk::app {
namespace {

Polyline line_x(double x0, double x1, double y, double step) {
  Polyline p;
  for (double x = x0; x <= x1 + 1e-12; x += step) p.points_m.push_back({x, y});
  return p;
}

}  // namespace

TEST(Coverage, HalfALineFollowedHalfAMillimetreAwayCoversHalfPlusTheRadiusReach) {
  const Scene sc = Scene::build({line_x(-0.02, 0.02, 0.0, 0.001)}, 4);
  CoverageMeter m(0.001);
  for (int i = 0; i <= 200; ++i) m.add({-0.02 + 0.0001 * i, 0.0005});  // ends exactly at x = 0 (a kept position)
  const Coverage c = m.measure(sc);
  // Reached: x ≤ 0 + √(1² − 0.5²) mm = 0.866 mm; of 40 mm: (20 + 0.866) / 40. The length is judged in
  // pieces of radius/4 = 0.25 mm by their midpoints, so each end of the reached stretch is right to within
  // 0.125 mm: 0.003 of 40 mm.
  EXPECT_NEAR(c.length_fraction, (0.020 + std::sqrt(0.001 * 0.001 - 0.0005 * 0.0005)) / 0.040, 0.0035);
  EXPECT_EQ(c.curves, 1u);
  EXPECT_EQ(c.curves_touched, 0u) << "near is not touched: no contact was reported";
}

TEST(Coverage, APathTwoMillimetresAwayCoversNothing) {
  const Scene sc = Scene::build({line_x(-0.02, 0.02, 0.0, 0.001)}, 4);
  CoverageMeter m(0.001);
  for (double x = -0.03; x <= 0.03; x += 0.0001) m.add({x, 0.002});
  EXPECT_EQ(m.measure(sc).length_fraction, 0.0);
}

TEST(Coverage, TracingAClosedSquareInsideCoversAllOfItAndTouchesIt) {
  const Scene sc = Scene::build({test::sampled_square(0.01, 0.001), line_x(-0.02, 0.02, 0.03, 0.001)}, 4);
  CoverageMeter m(0.001);
  const double h = 0.0095;  // half a millimetre inside each side
  for (int side = 0; side < 4; ++side)
    for (double t = 0; t < 1.0; t += 0.005) {
      const Vec2 corners[5] = {{-h, -h}, {h, -h}, {h, h}, {-h, h}, {-h, -h}};
      m.add(lerp(corners[side], corners[side + 1], t), 0);
    }
  const Coverage c = m.measure(sc);
  // The square is 80 mm of the 120 mm of curves; the far line is never reached.
  EXPECT_NEAR(c.length_fraction, 80.0 / 120.0, 0.002);
  EXPECT_EQ(c.curves_touched, 1u);
  EXPECT_EQ(c.curves, 2u);
}

TEST(Coverage, ARestingProxyAndAnEmptySceneAreHandled) {
  CoverageMeter m(0.001);
  for (int i = 0; i < 1000; ++i) m.add({0.0, 0.0}, 3, 5);
  const Scene empty = Scene::build({}, 4);
  const Coverage c = m.measure(empty);
  EXPECT_EQ(c.length_fraction, 0.0);
  EXPECT_EQ(c.curves, 0u);
  EXPECT_EQ(c.curves_touched, 0u) << "touched curves beyond the scene are not counted";
}

}  // namespace hk::app
