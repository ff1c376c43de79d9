#pragma once
/// @file multires.hpp
/// Wavelet multiresolution of plane curves with Reissell's pseudocoiflets (seed paper §2; DESIGN.md
/// "Wavelets"). The (4,4) interpolating biorthogonal pair is implemented by lifting:
///   predict  d_k = x_{2k+1} − (−x_{2k−2} + 9 x_{2k} + 9 x_{2k+2} − x_{2k+4}) / 16
///   update   s_k = x_{2k}   + (−d_{k−2} + 9 d_{k−1} + 9 d_k − d_{k+1}) / 32
/// which equals filtering with the analysis lowpass H = √2/512·[−1 0 18 −16 −63 144 348 144 −63 −16 18 0 −1]
/// and keeping every second sample, divided by √2 (the unnormalised form). x(t) and y(t) are transformed
/// separately. Closed curves are periodic. Open curves use one-sided cubic predictors at the ends
/// (weights (5, 15, −5, 1)/16 on e₀..e₃, mirrored at the far end); the update treats wavelet
/// coefficients outside the curve as zero and leaves the two end samples alone, so an open curve keeps
/// its end points at every level.

#include <cstddef>
#include <stdexcept>
#include <vector>
#include "hk/error.hpp"

#include "hk/vec2.hpp"

namespace hk {

/// An input polyline in workspace metres, as vision hands it over.
struct Polyline {
  std::vector<Vec2> points_m;  ///< ordered points [m]; a closed curve does not repeat its first point
  bool closed = false;         ///< true: the last point joins the first
};

/// Thrown at setup for a curve the multiresolution cannot be built from (too few points, non-finite).
class CurveError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// Resamples a polyline at `count` points equally spaced in arc length.
/// Open: the first and last output points are the polyline's ends (count ≥ 2).
/// Closed: the output starts at points_m[0] and walks the loop; it does not repeat it (count ≥ 3).
/// `arc_out`, if given, receives the arc-length parameter [m] of every output point (size count).
/// Throws CurveError for fewer than 2 points, zero total length, or non-finite coordinates.
std::vector<Vec2> resample_arc_length(const Polyline& curve, std::size_t count, std::vector<double>* arc_out = nullptr);

/// Entries of a polyline's arc table: its vertex count, + 1 for a closed curve (the loop back to its first vertex).
std::size_t arc_table_size(const Polyline& curve);

/// The arc table of a polyline: cum[i] = arc length from its first vertex to vertex i [m], and for a closed
/// curve cum[n] = the whole loop. `cum` holds arc_table_size(curve) entries. Returns the total length [m].
/// Throws CurveError for fewer than 2 points, non-finite coordinates or zero total length.
double arc_table(const Polyline& curve, double* cum);

/// resample_arc_length from the curve's arc table `cum` (as arc_table wrote it), into out[0..count).
/// Allocates nothing; throws CurveError for a count too small (as below).
void resample_arc_length(const Polyline& curve, const double* cum, std::size_t count, Vec2* out);

/// Arc length between consecutive resampled points, for a curve of total length total_m resampled at `count`
/// points [m]: total / count closed, total / (count − 1) open.
inline double resample_step_m(double total_m, std::size_t count, bool closed) {
  return closed ? total_m / static_cast<double>(count) : total_m / static_cast<double>(count - 1);
}

/// Arc-length parameter of resampled point i of `count` on a curve of total length total_m [m], with
/// step_m = resample_step_m(total_m, count, closed): step · i, exactly total_m for an open curve's last
/// point. resample_arc_length samples at these, so they are its points' arc lengths bit for bit.
inline double level0_arc_m(double total_m, double step_m, std::size_t count, bool closed, std::size_t i) {
  return !closed && i + 1 == count ? total_m : step_m * static_cast<double>(i);
}

/// The same, with the step computed here (one division a call).
inline double level0_arc_m(double total_m, std::size_t count, bool closed, std::size_t i) {
  return level0_arc_m(total_m, resample_step_m(total_m, count, closed), count, closed, i);
}

/// One forward lifting step on one coordinate. `x` has n samples: closed n even (≥ 8), open n odd (≥ 7):
/// four even samples for the cubic predictor. Throws CurveError for any other n. Writes s (scaling coefficients, n/2
/// closed, (n+1)/2 open) and d (wavelet coefficients, n/2 closed, (n−1)/2 open). Source: DESIGN.md "Wavelets".
void pseudocoiflet_forward(const std::vector<double>& x, bool closed, std::vector<double>& s, std::vector<double>& d);

/// Exact inverse of pseudocoiflet_forward: rebuilds x from s and d (sizes as above).
void pseudocoiflet_inverse(const std::vector<double>& s, const std::vector<double>& d, bool closed,
                           std::vector<double>& x);

/// The multiresolution model of one curve: scaling coefficients of every level and the wavelet
/// coefficients between them. Level 0 is the arc-length resampled curve; level l has
/// K·2^(L−l) points (closed) or K·2^(L−l)+1 points (open), L = finest_to_coarsest_levels.
struct CurveMultires {
  bool closed = false;
  int levels = 0;                          ///< number of levels, L + 1 (level 0 .. L)
  std::vector<std::vector<Vec2>> scaling;  ///< scaling[l]: scaling coefficients = level-l polyline [m]
  std::vector<std::vector<Vec2>> wavelet;  ///< wavelet[l] (l ≥ 1): coefficients lost going l−1 → l [m]
  std::vector<double> arc_m;               ///< arc length along the original of each level-0 point [m]

  /// Number of segments of level l's polyline (closed: points; open: points − 1).
  std::size_t segment_count(int level) const {
    const std::size_t n = scaling[static_cast<std::size_t>(level)].size();
    return closed ? n : n - 1;
  }
};

/// Chooses the level-0 sample count for a curve of `point_count` input points: K·2^L (closed) or
/// K·2^L + 1 (open), at least the input count, with L ≤ max_levels and the coarsest level still at
/// least 4 segments (closed) or 3 segments (open). Returns {K, L}.
struct LevelPlan {
  std::size_t k = 0;
  int levels_above_0 = 0;
  std::size_t level0_points = 0;
};
LevelPlan plan_levels(std::size_t point_count, bool closed, int max_levels);

/// Points of level `level` of a curve with level0_points points at level 0 (plan_levels' counts):
/// level0_points / 2^level closed, (level0_points − 1) / 2^level + 1 open.
std::size_t level_point_count(std::size_t level0_points, bool closed, int level);

/// Scratch entries forward_levels needs for a curve of level0_points points at level 0.
inline std::size_t forward_scratch_size(std::size_t level0_points) { return level0_points; }

/// The forward transform of a curve from level 0 up, both coordinates at once, into caller storage (seed
/// paper §2): scaling[0] holds level 0's level0_points points (a size plan_levels gives); writes level l's
/// scaling coefficients to scaling[l] (level_point_count of them) and its wavelet coefficients to wavelet[l]
/// (level0_points / 2^l of them), or only into `scratch` when wavelet[l] is null, for l = 1 .. levels − 1.
/// `scratch` holds forward_scratch_size(level0_points) points. Bit for bit build_multires' levels.
/// Allocates nothing; throws CurveError for a level size the lifting step does not take.
void forward_levels(Vec2* const* scaling, Vec2* const* wavelet, std::size_t level0_points, bool closed, int levels,
                    Vec2* scratch);

/// Builds the multiresolution of a curve: resample to plan_levels' count, then apply the forward
/// transform L times. Throws CurveError for a curve too short to resample (< 2 points or zero length).
CurveMultires build_multires(const Polyline& curve, int max_levels);

}  // namespace hk
