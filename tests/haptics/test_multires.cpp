// Pseudocoiflet multiresolution: exactness, polynomial reproduction, approximation order, and golden
// values from an independent filter-bank convolution with the analysis taps of DESIGN.md.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "curves.hpp"
#include "haptics/multires.hpp"

using namespace hk;

namespace {

std::vector<double> random_signal(std::mt19937& rng, std::size_t n) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> x(n);
  for (auto& v : x) v = u(rng);
  return x;
}

double max_abs_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

}  // namespace

TEST(Pseudocoiflet, PerfectReconstructionClosed) {
  std::mt19937 rng(1);
  for (std::size_t n : {8u, 10u, 16u, 38u, 64u, 250u, 1024u}) {
    const auto x = random_signal(rng, n);
    std::vector<double> s, d, y;
    pseudocoiflet_forward(x, true, s, d);
    ASSERT_EQ(s.size(), n / 2);
    ASSERT_EQ(d.size(), n / 2);
    pseudocoiflet_inverse(s, d, true, y);
    ASSERT_EQ(y.size(), n);
    EXPECT_LT(max_abs_diff(x, y), 1e-12) << "n=" << n;
  }
}

TEST(Pseudocoiflet, PerfectReconstructionOpen) {
  std::mt19937 rng(2);
  for (std::size_t n : {7u, 9u, 11u, 17u, 65u, 301u, 1025u}) {
    const auto x = random_signal(rng, n);
    std::vector<double> s, d, y;
    pseudocoiflet_forward(x, false, s, d);
    ASSERT_EQ(s.size(), (n + 1) / 2);
    ASSERT_EQ(d.size(), (n - 1) / 2);
    pseudocoiflet_inverse(s, d, false, y);
    EXPECT_LT(max_abs_diff(x, y), 1e-12) << "n=" << n;
    // The ends of an open curve stay put at every level.
    EXPECT_EQ(s.front(), x.front());
    EXPECT_EQ(s.back(), x.back());
  }
}

TEST(Pseudocoiflet, MultiLevelCurveReconstruction) {
  std::mt19937 rng(3);
  for (bool closed : {true, false}) {
    Polyline p = closed ? test::random_blob(rng, {0, 0}, 0.03, 300) : test::random_stroke(rng, {0, 0}, 0.0005, 300);
    const CurveMultires m = build_multires(p, 5);
    ASSERT_GE(m.levels, 4);
    // Rebuild level 0 from the coarsest scaling coefficients and all wavelet coefficients.
    std::vector<double> x, y, sx, sy, dx, dy;
    for (const Vec2& q : m.scaling.back()) {
      sx.push_back(q.x);
      sy.push_back(q.y);
    }
    for (int l = m.levels - 1; l >= 1; --l) {
      dx.clear();
      dy.clear();
      for (const Vec2& w : m.wavelet[l]) {
        dx.push_back(w.x);
        dy.push_back(w.y);
      }
      pseudocoiflet_inverse(sx, dx, closed, x);
      pseudocoiflet_inverse(sy, dy, closed, y);
      sx = x;
      sy = y;
    }
    ASSERT_EQ(sx.size(), m.scaling[0].size());
    double err = 0.0;
    for (std::size_t i = 0; i < sx.size(); ++i) err = std::max(err, distance({sx[i], sy[i]}, m.scaling[0][i]));
    EXPECT_LT(err, 1e-15) << (closed ? "closed" : "open");  // metres: 1e-12 of a 0.1 m curve
  }
}

// build_multires steps both coordinates at once; every level must be, bit for bit, the one-coordinate
// pseudocoiflet_forward (checked against the filter bank below) applied to x and to y. The sizes include
// the smallest curves the transform takes (8 closed and 7 open points at the coarsest level), where the
// lifting stencils reach an end at nearly every sample.
TEST(Pseudocoiflet, BothCoordinatesAtOnceAreBitForBitTheOneCoordinateStep) {
  std::mt19937 rng(11);
  for (bool closed : {true, false}) {
    for (int points : {8, 9, 17, 33, 300}) {
      const Polyline p =
          closed ? test::random_blob(rng, {0, 0}, 0.03, points) : test::random_stroke(rng, {0, 0}, 0.0005, points);
      const CurveMultires m = build_multires(p, 6);
      ASSERT_GE(m.levels, 2) << points;
      for (int l = 1; l < m.levels; ++l) {
        std::vector<double> x, y, sx, sy, dx, dy;
        for (const Vec2& q : m.scaling[l - 1]) {
          x.push_back(q.x);
          y.push_back(q.y);
        }
        pseudocoiflet_forward(x, closed, sx, dx);
        pseudocoiflet_forward(y, closed, sy, dy);
        ASSERT_EQ(m.scaling[l].size(), sx.size());
        ASSERT_EQ(m.wavelet[l].size(), dx.size());
        for (std::size_t i = 0; i < sx.size(); ++i) {
          EXPECT_EQ(m.scaling[l][i], (Vec2{sx[i], sy[i]}))
              << (closed ? "closed " : "open ") << points << " level " << l << " i " << i;
        }
        for (std::size_t i = 0; i < dx.size(); ++i) {
          EXPECT_EQ(m.wavelet[l][i], (Vec2{dx[i], dy[i]}))
              << (closed ? "closed " : "open ") << points << " level " << l << " i " << i;
        }
      }
    }
  }
}

TEST(Pseudocoiflet, CubicsGiveZeroWaveletCoefficientsIncludingEnds) {
  // Open: the one-sided end predictors are cubic too, so every coefficient vanishes.
  for (std::size_t n : {7u, 13u, 33u}) {
    std::vector<double> x(n), s, d;
    for (std::size_t i = 0; i < n; ++i) {
      const double t = static_cast<double>(i);
      x[i] = 0.3 - 1.1 * t + 0.07 * t * t - 0.004 * t * t * t;
    }
    pseudocoiflet_forward(x, false, s, d);
    double scale = 0.0;
    for (double v : x) scale = std::max(scale, std::abs(v));
    for (std::size_t k = 0; k < d.size(); ++k) EXPECT_NEAR(d[k], 0.0, 1e-12 * scale) << "n=" << n << " k=" << k;
  }
  // Closed: a cubic is not periodic, so only coefficients whose stencil does not wrap vanish.
  std::vector<double> x(32), s, d;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = static_cast<double>(i);
    x[i] = 2.0 + 0.5 * t - 0.02 * t * t + 0.001 * t * t * t;
  }
  pseudocoiflet_forward(x, true, s, d);
  for (std::size_t k = 1; k + 2 < d.size(); ++k) EXPECT_NEAR(d[k], 0.0, 1e-11) << "k=" << k;
  // A quartic does not vanish: the predictor is cubic, not better (guards against a trivially zero d).
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::pow(static_cast<double>(i), 4);
  pseudocoiflet_forward(x, true, s, d);
  EXPECT_GT(std::abs(d[8]), 1.0);
}

TEST(Pseudocoiflet, ScalingCoefficientsApproachSamplesAtOrderFour) {
  // Smooth closed curve x(θ) = cos θ + 0.3 cos 3θ sampled at n points; level-1 error vs samples.
  auto error_at = [](std::size_t n) {
    std::vector<double> x(n), s, d;
    for (std::size_t i = 0; i < n; ++i) {
      const double th = 2 * M_PI * static_cast<double>(i) / static_cast<double>(n);
      x[i] = std::cos(th) + 0.3 * std::cos(3 * th) + 0.1 * std::sin(2 * th);
    }
    pseudocoiflet_forward(x, true, s, d);
    double e = 0.0;
    for (std::size_t k = 0; k < s.size(); ++k) e = std::max(e, std::abs(s[k] - x[2 * k]));
    return e;
  };
  double prev = error_at(32);
  for (std::size_t n = 64; n <= 1024; n *= 2) {
    const double e = error_at(n);
    const double ratio = prev / e;
    EXPECT_GT(ratio, 13.0) << "n=" << n;
    EXPECT_LT(ratio, 19.0) << "n=" << n;
    prev = e;
  }
}

TEST(Pseudocoiflet, GoldenAgainstFilterBankConvolution) {
  // Independent derivation: s_k = (1/√2) Σ_j H_j x_{2k+j−6} with the analysis lowpass of DESIGN.md
  // (Reissell 1993), periodic. Taps written here, not taken from the library.
  const double H[13] = {-1, 0, 18, -16, -63, 144, 348, 144, -63, -16, 18, 0, -1};
  const double norm = std::sqrt(2.0) / 512.0;
  double sum = 0.0;
  for (double h : H) sum += h * norm;
  ASSERT_NEAR(sum, std::sqrt(2.0), 1e-15);  // lowpass gain √2 (DC preserved after the 1/√2)
  std::mt19937 rng(4);
  for (std::size_t n : {8u, 10u, 16u, 40u, 128u}) {
    const auto x = random_signal(rng, n);
    std::vector<double> s, d;
    pseudocoiflet_forward(x, true, s, d);
    for (std::size_t k = 0; k < n / 2; ++k) {
      double acc = 0.0;
      for (int j = 0; j < 13; ++j) {
        const long idx = (static_cast<long>(2 * k) + j - 6 + 10 * static_cast<long>(n)) % static_cast<long>(n);
        acc += H[j] * norm * x[static_cast<std::size_t>(idx)];
      }
      EXPECT_NEAR(s[k], acc / std::sqrt(2.0), 1e-13) << "n=" << n << " k=" << k;
    }
  }
  // One fully worked value: an impulse at sample 0 gives s_0 = 348/512, s_1 = −63/512, s_3 = −1/512.
  std::vector<double> x(16, 0.0), s, d;
  x[0] = 1.0;
  pseudocoiflet_forward(x, true, s, d);
  EXPECT_NEAR(s[0], 348.0 / 512.0, 1e-15);
  EXPECT_NEAR(s[7], -63.0 / 512.0, 1e-15);  // x_0 sits at offset +2 from s_7's centre 14: tap H[8] = −63
  EXPECT_NEAR(s[5], -1.0 / 512.0, 1e-15);   // offset +6 from centre 10: tap H[12] = −1
  EXPECT_NEAR(s[1], -63.0 / 512.0, 1e-15);  // offset −2: tap H[4] = −63
}

TEST(Resample, ArcLengthSpacingAndEnds) {
  Polyline p;
  p.points_m = {{0, 0}, {0.03, 0}, {0.03, 0.01}};
  const auto r = resample_arc_length(p, 9);
  ASSERT_EQ(r.size(), 9u);
  EXPECT_EQ(r.front(), p.points_m.front());
  EXPECT_NEAR(distance(r.back(), p.points_m.back()), 0.0, 1e-15);
  // Equal spacing along the curve: 0.04 m / 8.
  EXPECT_NEAR(r[1].x, 0.005, 1e-15);
  EXPECT_NEAR(r[7].y, 0.005, 1e-15);
  p.closed = true;  // closing segment adds sqrt(0.03²+0.01²)
  const auto c = resample_arc_length(p, 10);
  const double total = 0.04 + std::hypot(0.03, 0.01);
  EXPECT_NEAR(c[1].x, total / 10, 1e-15);
}

TEST(Resample, RejectsDegenerateCurves) {
  Polyline p;
  EXPECT_THROW(resample_arc_length(p, 8), CurveError);
  p.points_m = {{0.01, 0.01}, {0.01, 0.01}};
  EXPECT_THROW(resample_arc_length(p, 8), CurveError);
  p.points_m = {{0.0, 0.0}, {NAN, 0.0}};
  EXPECT_THROW(resample_arc_length(p, 8), CurveError);
}

TEST(LevelPlan, SizesFitTheTransform) {
  for (bool closed : {true, false}) {
    for (std::size_t n : {2u, 3u, 5u, 12u, 100u, 513u, 4000u}) {
      const LevelPlan plan = plan_levels(n, closed, 6);
      const std::size_t unit = std::size_t{1} << plan.levels_above_0;
      EXPECT_EQ(plan.level0_points, plan.k * unit + (closed ? 0 : 1));
      EXPECT_GE(plan.level0_points, n);
      EXPECT_GE(plan.k, closed ? 4u : 3u);
      EXPECT_LE(plan.levels_above_0, 6);
    }
  }
}
