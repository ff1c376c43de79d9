#pragma once
// The segment budget's old ranking of curves, kept as the baseline the shape budget's tests compare with
// (vision/scene_chains.hpp shape_salience ranks them now).

#include <algorithm>
#include <cmath>

namespace hk::test {

/// Salience of a curve as the segment budget used to rank curves, before shape_salience replaced it; kept
/// as the baseline the shape budget's test compares with.
///
///   salience = length_m · clamp(strength / canny_high, 0, 1)
///
/// Long boundaries are the shapes a visitor explores (a fingertip finds a long wall and can follow
/// it; a short one is a bump), so length counts linearly. Strength says how sure the boundary is:
/// Canny accepts an edge pixel above canny_high outright and one between canny_low and canny_high
/// only when it is linked to a sure one, so a curve whose mean magnitude is below canny_high is
/// mostly hysteresis-linked shading or texture and is discounted in proportion; above canny_high
/// every curve is equally sure (a wall is felt the same whatever its grey-level contrast), hence the
/// clip at 1. Returns 0 for a non-positive canny_high or a non-finite input.
inline double curve_salience(double length_m, double strength, double canny_high) {
  if (!std::isfinite(length_m) || !std::isfinite(strength) || !std::isfinite(canny_high) || canny_high <= 0.0)
    return 0.0;
  return length_m * std::clamp(strength / canny_high, 0.0, 1.0);
}

}  // namespace hk::test
