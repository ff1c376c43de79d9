// Pseudocoiflet multiresolution of plane curves (seed paper §2, DESIGN.md "Wavelets").
// The lifting form is used because it is exactly invertible in floating point (each step is undone by
// subtracting the same rounded value) and needs no boundary-extended filter banks.
#include "haptics/multires.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace hk {
namespace {

// Periodic index into a sequence of length n, for k within one period of it (−n ≤ k < 2n: the lifting
// steps reach at most two samples past either end, and n ≥ 4). No division: this runs for every sample.
inline std::size_t wrap(long k, std::size_t n) {
  const long m = static_cast<long>(n);
  return static_cast<std::size_t>(k < 0 ? k + m : (k >= m ? k - m : k));
}

// Samples are double (one coordinate) or Vec2 (both at once): every component gets the same operations in
// the same order, so a Vec2 step is bit for bit two double steps. The divisions by 16 and 32 are products
// by 1/16 and 1/32, exact in binary floating point.
constexpr double kSixteenth = 1.0 / 16.0, kThirtySecond = 1.0 / 32.0;

// Prediction of odd sample k from the even samples e (size ne), cubic interpolation (DESIGN.md).
template <class T>
inline T predict(const T* e, std::size_t ne, std::size_t k, bool closed) {
  if (closed) {
    const long kk = static_cast<long>(k);
    return (-e[wrap(kk - 1, ne)] + 9.0 * e[k] + 9.0 * e[wrap(kk + 1, ne)] - e[wrap(kk + 2, ne)]) * kSixteenth;
  }
  const std::size_t no = ne - 1;
  if (k == 0) return (5.0 * e[0] + 15.0 * e[1] - 5.0 * e[2] + e[3]) * kSixteenth;
  if (k == no - 1) return (5.0 * e[ne - 1] + 15.0 * e[ne - 2] - 5.0 * e[ne - 3] + e[ne - 4]) * kSixteenth;
  return (-e[k - 1] + 9.0 * e[k] + 9.0 * e[k + 1] - e[k + 2]) * kSixteenth;
}

// Update of even sample k from the wavelet coefficients d (size nd). Open curves: outside d are zero
// and the two end samples are not updated, so the curve keeps its ends at every level.
template <class T>
inline T update(const T* d, std::size_t nd, std::size_t ne, std::size_t k, bool closed) {
  const long kk = static_cast<long>(k);
  if (closed) {
    return (-d[wrap(kk - 2, nd)] + 9.0 * d[wrap(kk - 1, nd)] + 9.0 * d[k] - d[wrap(kk + 1, nd)]) * kThirtySecond;
  }
  if (k == 0 || k == ne - 1) return T{};
  auto at = [&](long i) { return (i >= 0 && i < static_cast<long>(nd)) ? d[i] : T{}; };
  return (-at(kk - 2) + 9.0 * at(kk - 1) + 9.0 * at(kk) - at(kk + 1)) * kThirtySecond;
}

void check_forward_size(std::size_t n, bool closed) {
  if (closed ? (n < 8 || n % 2 != 0) : (n < 7 || n % 2 == 0)) {
    throw CurveError("pseudocoiflet transform: " + std::to_string(n) + " samples is not a valid " +
                     (closed ? "closed length (even, >= 8)" : "open length (odd, >= 7)"));
  }
}

// One forward lifting step: x[0..n) (a size check_forward_size accepts) to s[0..ne) and d[0..no), with e
// (size ne) as the even samples' scratch. The interior samples, whose stencils reach no end, run without
// wraps or end cases (the same expressions as predict() and update(), so the same bits); the few at each
// end go through predict() and update().
template <class T>
void forward_step(const T* x, std::size_t n, bool closed, T* e, T* s, T* d) {
  const std::size_t ne = closed ? n / 2 : (n + 1) / 2;
  const std::size_t no = n / 2;
  for (std::size_t k = 0; k < ne; ++k) e[k] = x[2 * k];
  // Predict: the stencil e[k − 1 .. k + 2] reaches no end for 1 ≤ k < ne − 2.
  const std::size_t p_end = std::min(ne - 2, no);
  d[0] = x[1] - predict(e, ne, 0, closed);
  std::size_t k = 1;
  for (; k < p_end; ++k) d[k] = x[2 * k + 1] - (-e[k - 1] + 9.0 * e[k] + 9.0 * e[k + 1] - e[k + 2]) * kSixteenth;
  for (; k < no; ++k) d[k] = x[2 * k + 1] - predict(e, ne, k, closed);
  // Update: the stencil d[k − 2 .. k + 1] reaches no end for 2 ≤ k < no − 1.
  const std::size_t u_end = no - 1;
  s[0] = e[0] + update(d, no, ne, 0, closed);
  s[1] = e[1] + update(d, no, ne, 1, closed);
  for (k = 2; k < u_end; ++k) s[k] = e[k] + (-d[k - 2] + 9.0 * d[k - 1] + 9.0 * d[k] - d[k + 1]) * kThirtySecond;
  for (; k < ne; ++k) s[k] = e[k] + update(d, no, ne, k, closed);
}

}  // namespace

void pseudocoiflet_forward(const std::vector<double>& x, bool closed, std::vector<double>& s, std::vector<double>& d) {
  const std::size_t n = x.size();
  check_forward_size(n, closed);
  std::vector<double> e(closed ? n / 2 : (n + 1) / 2);
  s.assign(e.size(), 0.0);
  d.assign(n / 2, 0.0);
  forward_step(x.data(), n, closed, e.data(), s.data(), d.data());
}

void pseudocoiflet_inverse(const std::vector<double>& s, const std::vector<double>& d, bool closed,
                           std::vector<double>& x) {
  const std::size_t ne = s.size();
  const std::size_t no = d.size();
  if (closed ? (no != ne || ne < 4) : (no + 1 != ne || ne < 4)) {
    throw CurveError("pseudocoiflet inverse: " + std::to_string(ne) + " scaling and " + std::to_string(no) +
                     " wavelet coefficients do not fit a " + (closed ? "closed" : "open") + " curve");
  }
  std::vector<double> e(ne);
  for (std::size_t k = 0; k < ne; ++k) e[k] = s[k] - update(d.data(), no, ne, k, closed);
  x.assign(ne + no, 0.0);
  for (std::size_t k = 0; k < ne; ++k) x[2 * k] = e[k];
  for (std::size_t k = 0; k < no; ++k) x[2 * k + 1] = d[k] + predict(e.data(), ne, k, closed);
}

std::size_t arc_table_size(const Polyline& curve) {
  return curve.closed ? curve.points_m.size() + 1 : curve.points_m.size();
}

double arc_table(const Polyline& curve, double* cum) {
  const auto& p = curve.points_m;
  if (p.size() < 2) throw CurveError("curve has " + std::to_string(p.size()) + " points; at least 2 are needed");
  for (const Vec2& q : p) {
    if (!is_finite(q)) throw CurveError("curve has a non-finite coordinate");
  }
  const auto next = [n = p.size()](std::size_t i) { return i + 1 < n ? i + 1 : 0; };  // (i + 1) mod n, no division
  const std::size_t nseg = arc_table_size(curve) - 1;  // a closed curve adds its closing segment
  cum[0] = 0.0;
  for (std::size_t i = 0; i < nseg; ++i) cum[i + 1] = cum[i] + distance(p[i], p[next(i)]);
  const double total = cum[nseg];
  if (!(total > 0.0)) throw CurveError("curve has zero length");
  return total;
}

void resample_arc_length(const Polyline& curve, const double* cum, std::size_t count, Vec2* out) {
  const auto& p = curve.points_m;
  if (count < (curve.closed ? 3u : 2u)) throw CurveError("resampling count " + std::to_string(count) + " is too small");
  const auto next = [n = p.size()](std::size_t i) { return i + 1 < n ? i + 1 : 0; };
  const std::size_t nseg = arc_table_size(curve) - 1;
  const double total = cum[nseg];
  const double step = resample_step_m(total, count, curve.closed);
  std::size_t seg = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const double s =
        level0_arc_m(total, step, count, curve.closed, i);  // an open curve lands exactly on its last point
    while (seg + 1 < nseg && cum[seg + 1] < s) ++seg;
    const double len = cum[seg + 1] - cum[seg];
    const double t = len > 0.0 ? std::clamp((s - cum[seg]) / len, 0.0, 1.0) : 0.0;
    out[i] = lerp(p[seg], p[next(seg)], t);
  }
}

std::vector<Vec2> resample_arc_length(const Polyline& curve, std::size_t count, std::vector<double>* arc_out) {
  std::vector<double> cum(curve.points_m.size() < 2 ? 1 : arc_table_size(curve));
  const double total = arc_table(curve, cum.data());
  std::vector<Vec2> out(count);
  resample_arc_length(curve, cum.data(), count, out.data());
  if (arc_out) {
    arc_out->resize(count);
    for (std::size_t i = 0; i < count; ++i) (*arc_out)[i] = level0_arc_m(total, count, curve.closed, i);
  }
  return out;
}

std::size_t level_point_count(std::size_t level0_points, bool closed, int level) {
  return closed ? level0_points >> level : ((level0_points - 1) >> level) + 1;
}

void forward_levels(Vec2* const* scaling, Vec2* const* wavelet, std::size_t level0_points, bool closed, int levels,
                    Vec2* scratch) {
  for (int l = 1; l < levels; ++l) {  // both coordinates in one pass (bit for bit the per-coordinate step)
    const std::size_t n = level_point_count(level0_points, closed, l - 1);
    check_forward_size(n, closed);
    forward_step(scaling[l - 1], n, closed, scratch, scaling[l], wavelet[l] ? wavelet[l] : scratch + (n + 1) / 2);
  }
}

LevelPlan plan_levels(std::size_t point_count, bool closed, int max_levels) {
  // Coarsest level keeps at least 4 segments (closed) or 3 (open): the cubic predictor needs 4 even samples.
  const std::size_t min_k = closed ? 4 : 3;
  const std::size_t segments = closed ? point_count : (point_count > 0 ? point_count - 1 : 0);
  int levels = std::max(0, max_levels);
  while (levels > 0 && (segments >> levels) < min_k) --levels;
  const std::size_t unit = std::size_t{1} << levels;
  const std::size_t k = std::max(min_k, (segments + unit - 1) / unit);
  LevelPlan plan;
  plan.k = k;
  plan.levels_above_0 = levels;
  plan.level0_points = k * unit + (closed ? 0 : 1);
  return plan;
}

CurveMultires build_multires(const Polyline& curve, int max_levels) {
  const LevelPlan plan = plan_levels(curve.points_m.size(), curve.closed, max_levels);
  CurveMultires m;
  m.closed = curve.closed;
  m.levels = plan.levels_above_0 + 1;
  m.scaling.resize(static_cast<std::size_t>(m.levels));
  m.wavelet.resize(static_cast<std::size_t>(m.levels));
  m.scaling[0] = resample_arc_length(curve, plan.level0_points, &m.arc_m);
  std::vector<Vec2*> s(static_cast<std::size_t>(m.levels)), w(static_cast<std::size_t>(m.levels));
  for (int l = 1; l < m.levels; ++l) {
    const auto i = static_cast<std::size_t>(l);
    m.scaling[i].resize(level_point_count(plan.level0_points, curve.closed, l));
    m.wavelet[i].resize(plan.level0_points >> l);  // closed: as many as the level's points; open: one fewer
    s[i] = m.scaling[i].data();
    w[i] = m.wavelet[i].data();
  }
  s[0] = m.scaling[0].data();
  std::vector<Vec2> scratch(forward_scratch_size(plan.level0_points));
  forward_levels(s.data(), w.data(), plan.level0_points, curve.closed, m.levels, scratch.data());
  return m;
}

}  // namespace hk
