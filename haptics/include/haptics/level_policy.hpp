#pragma once
/// @file level_policy.hpp
/// Resolution level from hand speed (seed §1 and §5: "finer levels only when the hand
/// moves slowly"). Each tick: filter the hand's speed, ask how large a deviation from the true curve the
/// hand cannot feel at that speed, and pick the coarsest level whose error bound is below it — with
/// hysteresis and a dwell time so the level does not flap.
///
/// Perceptual model (a design choice, stated so it can be argued with):
///   tolerable error  e(v) = e_rest + v · t_blur
/// - e_rest [m]: what a fingertip on a stiff probe resolves when moving slowly. Detection thresholds for
///   bumps explored with a finger or probe are ~0.1 mm in height for bumps a few mm wide (Louw, Kappers &
///   Koenderink 2000, "Haptic detection thresholds of Gaussian profiles over the whole range of spatial
///   scales", Exp. Brain Res. 132); default 0.1 mm.
/// - t_blur [s]: the hand cannot separate position changes within ~10–20 ms (vibrotactile/kinesthetic
///   temporal resolution; Loomis & Lederman 1986, "Tactual perception"), so a deviation shorter than the
///   path covered in that time blurs into the motion; default 10 ms (at 0.1 m/s: 1 mm more tolerance).
/// Real-time: update() allocates nothing and never throws.

#include <array>
#include <cstdint>
#include <string>

#include "hk/constants.hpp"
#include "hk/vec2.hpp"

namespace hk {

/// Policy parameters. Units in names.
struct LevelPolicyParams {
  double error_at_rest_m = 1e-4;  ///< e_rest: tolerable deviation at rest [m]
  double blur_time_s = 0.010;     ///< t_blur: tolerable deviation grows by speed × this [s]
  double speed_cutoff_hz = 2.0;   ///< low-pass on the hand speed [Hz]: slower than tremor (8–12 Hz)
  double hysteresis = 0.3;        ///< go coarser only when that level's bound ≤ (1 − hysteresis) · e(v)
  double min_dwell_s = 0.15;      ///< at least this long between two changes [s]
  int fixed_level = -1;           ///< ≥ 0: the operator fixed the level; the policy always returns it
};

/// Picks the level each tick. Level 0 is the finest.
class LevelPolicy {
 public:
  static constexpr int kMaxLevels = hk::kMaxLevels;  ///< see hk/constants.hpp

  /// `level_error_m[l]` is the scene's error bound at level l [m] (non-decreasing in l, e.g. the largest
  /// box half-width of the level), for l in [0, levels). `start_level` is used until the first change.
  LevelPolicy(const LevelPolicyParams& params, const double* level_error_m, int levels, int start_level);

  /// One tick: the handle velocity [m/s] over `dt_s` [s]. Returns the level to render.
  int update(Vec2 handle_velocity_m_per_s, double dt_s) noexcept;

  /// Tolerable error e(v) at speed v [m/s] → [m].
  double tolerable_error_m(double speed_m_per_s) const noexcept {
    return p_.error_at_rest_m + speed_m_per_s * p_.blur_time_s;
  }
  /// The coarsest level whose bound is ≤ `tolerance_m` (0 if none is).
  int coarsest_within(double tolerance_m) const noexcept;

  int level() const noexcept { return level_; }
  double filtered_speed_m_per_s() const noexcept { return speed_; }
  std::int64_t changes() const noexcept { return changes_; }

 private:
  LevelPolicyParams p_;
  std::array<double, kMaxLevels> error_{};
  int levels_ = 1;
  int level_ = 0;
  double speed_ = 0.0;           ///< filtered speed [m/s]
  double since_change_s_ = 1e9;  ///< time since the last change [s]
  std::int64_t changes_ = 0;
};

/// How a level id (hk/constants.hpp) reads on a screen: "level 3", "tolerance 0.25 mm" for a tolerance
/// step, "cut 0.25 mm" for a cut step. For display code (allocates).
std::string level_label(int id);

}  // namespace hk
