#include "haptics/level_policy.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hk {

LevelPolicy::LevelPolicy(const LevelPolicyParams& params, const double* level_error_m, int levels, int start_level)
    : p_(params), levels_(std::clamp(levels, 1, kMaxLevels)) {
  double running = 0.0;
  for (int l = 0; l < levels_; ++l) {
    // Keep the bounds non-decreasing, so "coarsest within" is a clean threshold.
    running = std::max(running, level_error_m ? level_error_m[l] : 0.0);
    error_[static_cast<std::size_t>(l)] = running;
  }
  level_ = p_.fixed_level >= 0 ? std::min(p_.fixed_level, levels_ - 1) : std::clamp(start_level, 0, levels_ - 1);
}

int LevelPolicy::coarsest_within(double tol) const noexcept {
  int best = 0;
  for (int l = 0; l < levels_; ++l) {
    if (error_[static_cast<std::size_t>(l)] <= tol) best = l;
  }
  return best;
}

int LevelPolicy::update(Vec2 v, double dt) noexcept {
  if (p_.fixed_level >= 0) return level_;
  if (!(dt > 0.0) || !std::isfinite(v.x) || !std::isfinite(v.y)) return level_;
  const double alpha = 1.0 - std::exp(-2.0 * M_PI * p_.speed_cutoff_hz * dt);
  speed_ += alpha * (length(v) - speed_);
  since_change_s_ += dt;
  const double tol = tolerable_error_m(speed_);
  int want = level_;
  if (error_[static_cast<std::size_t>(level_)] > tol) {
    want = coarsest_within(tol);  // too coarse for this speed: finer now (no hysteresis on the safe side)
  } else {
    const int coarser = coarsest_within((1.0 - p_.hysteresis) * tol);
    if (coarser > level_) want = coarser;
  }
  if (want != level_ && since_change_s_ >= p_.min_dwell_s) {
    level_ = want;
    since_change_s_ = 0.0;
    ++changes_;
  }
  return level_;
}

std::string level_label(int id) {
  const int step = tolerance_step_of(id);
  if (step < 0) return "level " + std::to_string(id);
  char text[40];
  std::snprintf(text, sizeof text, is_cut_level(id) ? "cut %.2f mm" : "tolerance %.2f mm",
                kToleranceLadder_m[step] * 1e3);
  return text;
}

}  // namespace hk
