// Resolution level from hand speed: golden levels from the perceptual model, monotone in speed,
// hysteresis, and no flapping under hand tremor (8 Hz, 0.7 mm) where a naive policy flaps.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "haptics/level_policy.hpp"

namespace hk {
namespace {

// Error bounds per level [m]: doubling from 0.05 mm, as a pseudocoiflet pyramid roughly does.
const std::vector<double> kErr{0.05e-3, 0.1e-3, 0.2e-3, 0.4e-3, 0.8e-3, 1.6e-3, 3.2e-3};

int settle(LevelPolicy& p, double speed, double seconds) {
  for (int k = 0; k < static_cast<int>(seconds * 1000); ++k) p.update({speed, 0.0}, 0.001);
  return p.level();
}

TEST(LevelPolicy, GoldenLevelsFromThePerceptualModel) {
  LevelPolicyParams prm;  // e(v) = 0.1 mm + v · 10 ms, hysteresis 0.3
  LevelPolicy p(prm, kErr.data(), static_cast<int>(kErr.size()), 3);
  // At rest e = 0.1 mm: level 3 (0.4 mm) is too coarse; the coarsest within 0.1 mm is level 1.
  EXPECT_EQ(settle(p, 0.0, 2.0), 1);
  // At 0.1 m/s e = 1.1 mm; going coarser needs a bound ≤ 0.7 · 1.1 = 0.77 mm: level 3 (0.4), not 4 (0.8).
  EXPECT_EQ(settle(p, 0.1, 2.0), 3);
  // At 0.5 m/s e = 5.1 mm; ≤ 3.57 mm: level 6 (3.2 mm), the coarsest there is.
  EXPECT_EQ(settle(p, 0.5, 2.0), 6);
  // Slowing down again to rest: back to level 1.
  EXPECT_EQ(settle(p, 0.0, 3.0), 1);
  EXPECT_NEAR(p.tolerable_error_m(0.1), 1.1e-3, 1e-12);
}

TEST(LevelPolicy, LevelNeverGetsFinerWhenTheHandGetsFaster) {
  int last = -1;
  for (double v = 0.0; v <= 1.0; v += 0.01) {
    LevelPolicy p({}, kErr.data(), static_cast<int>(kErr.size()), 0);
    const int l = settle(p, v, 2.0);
    EXPECT_GE(l, last) << "speed " << v;
    last = l;
  }
}

TEST(LevelPolicy, HysteresisSwitchesAtDifferentSpeedsUpAndDown) {
  LevelPolicyParams prm;
  prm.speed_cutoff_hz = 50;  // follow the ramp closely
  LevelPolicy p(prm, kErr.data(), static_cast<int>(kErr.size()), 1);
  double up_at = -1, down_at = -1;
  for (int k = 0; k <= 4000; ++k) {  // 0 → 0.2 m/s in 4 s
    const double v = 0.2 * k / 4000;
    p.update({v, 0}, 0.001);
    if (up_at < 0 && p.level() >= 3) up_at = v;
  }
  for (int k = 4000; k >= 0; --k) {
    const double v = 0.2 * k / 4000;
    p.update({v, 0}, 0.001);
    if (down_at < 0 && p.level() < 3) down_at = v;
  }
  ASSERT_GT(up_at, 0);
  ASSERT_GT(down_at, 0);
  EXPECT_GT(up_at, down_at + 0.01) << "coarser at " << up_at << " m/s, finer again only below " << down_at << " m/s";
}

// A slow stroke (20 mm/s) with physiological tremor (8 Hz, 0.7 mm amplitude: up to 35 mm/s of extra
// velocity). After the first second the policy changes level at most once; a naive policy (no speed
// filter, no hysteresis, no dwell) flaps dozens of times on the same input.
TEST(LevelPolicy, TremorDoesNotMakeTheLevelFlap) {
  auto run = [](const LevelPolicyParams& prm) {
    LevelPolicy p(prm, kErr.data(), static_cast<int>(kErr.size()), 2);
    std::int64_t after_settle = 0;
    for (int k = 0; k < 10000; ++k) {
      const double t = k * 0.001;
      const Vec2 v{0.02 + 2 * M_PI * 8.0 * 0.0007 * std::cos(2 * M_PI * 8.0 * t), 0.0};
      p.update(v, 0.001);
      if (k == 999) after_settle = p.changes();
    }
    return p.changes() - after_settle;
  };
  EXPECT_LE(run({}), 1);
  LevelPolicyParams naive;
  naive.speed_cutoff_hz = 1000;
  naive.hysteresis = 0;
  naive.min_dwell_s = 0;
  EXPECT_GT(run(naive), 20) << "the test input must be one that makes a naive policy flap";
}

TEST(LevelPolicy, OperatorFixedLevelAndBadInput) {
  LevelPolicyParams fixed;
  fixed.fixed_level = 4;
  LevelPolicy f(fixed, kErr.data(), static_cast<int>(kErr.size()), 0);
  EXPECT_EQ(settle(f, 0.0, 1.0), 4);
  EXPECT_EQ(settle(f, 1.0, 1.0), 4);
  LevelPolicy p({}, kErr.data(), static_cast<int>(kErr.size()), 2);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(p.update({nan, 0}, 0.001), 2);
  EXPECT_EQ(p.update({0, 0}, 0.0), 2);
  EXPECT_TRUE(std::isfinite(p.filtered_speed_m_per_s()));
  // Bounds that are not non-decreasing are made so: a finer level never counts as coarser-and-better.
  const std::vector<double> odd{0.1e-3, 0.05e-3, 0.3e-3};
  LevelPolicy q({}, odd.data(), 3, 0);
  EXPECT_EQ(q.coarsest_within(0.08e-3), 0);
}

}  // namespace
}  // namespace hk
