#pragma once
// The SIMD kernels of the collision query's walks (SSE, four float rectangles per instruction): a sweep's entry
// into a wide node's four rectangles, a point's distances to them, the nearest of many distances, and the sweep's
// slab reciprocals.
#include <cmath>
#include <cstddef>
#include <limits>

#include "haptics/wide_index.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#include <xmmintrin.h>
#endif

namespace hk {
namespace collision_detail {

#if defined(__SSE2__)
using F4 = __m128;
inline F4 load4(const float* p) { return _mm_load_ps(p); }
inline F4 splat(float x) { return _mm_set1_ps(x); }
#endif

// Entry parameters of the sweep into a node's four rectangles: bit i of the result is set when the
// sweep meets rectangle i at a parameter ≤ horizon, and t_enter[i] is where it enters. The sweep is
// given as its start and the reciprocals of its extent (±1e20 for a zero extent: a start inside the
// slab spans every parameter, one outside it none).
inline int sweep_node(const WideNode& n, float ax, float ay, float ix, float iy, float horizon, float t_enter[4]) {
#if defined(__SSE2__)
  const F4 vax = splat(ax), vay = splat(ay), vix = splat(ix), viy = splat(iy);
  const F4 tx0 = _mm_mul_ps(_mm_sub_ps(load4(n.lo_x), vax), vix), tx1 = _mm_mul_ps(_mm_sub_ps(load4(n.hi_x), vax), vix);
  const F4 ty0 = _mm_mul_ps(_mm_sub_ps(load4(n.lo_y), vay), viy), ty1 = _mm_mul_ps(_mm_sub_ps(load4(n.hi_y), vay), viy);
  const F4 t_in = _mm_max_ps(_mm_max_ps(_mm_min_ps(tx0, tx1), _mm_min_ps(ty0, ty1)), _mm_setzero_ps());
  const F4 t_out = _mm_min_ps(_mm_min_ps(_mm_max_ps(tx0, tx1), _mm_max_ps(ty0, ty1)), splat(1.0f));
  _mm_storeu_ps(t_enter, t_in);
  return _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(t_in, t_out), _mm_cmple_ps(t_in, splat(horizon))));
#else
  int mask = 0;
  for (int i = 0; i < 4; ++i) {
    const float tx0 = (n.lo_x[i] - ax) * ix, tx1 = (n.hi_x[i] - ax) * ix;
    const float ty0 = (n.lo_y[i] - ay) * iy, ty1 = (n.hi_y[i] - ay) * iy;
    const float t_in = std::max(std::max(std::min(tx0, tx1), std::min(ty0, ty1)), 0.0f);
    const float t_out = std::min(std::min(std::max(tx0, tx1), std::max(ty0, ty1)), 1.0f);
    t_enter[i] = t_in;
    if (t_in <= t_out && t_in <= horizon) mask |= 1 << i;
  }
  return mask;
#endif
}

// Squared distances from (px, py) to a node's four rectangles [m²] (0 inside); bit i of the result is
// set when rectangle i is within bound_sq.
inline int near_node(const WideNode& n, float px, float py, float bound_sq, float d_sq[4]) {
#if defined(__SSE2__)
  const F4 vpx = splat(px), vpy = splat(py), zero = _mm_setzero_ps();
  const F4 dx = _mm_max_ps(_mm_max_ps(_mm_sub_ps(load4(n.lo_x), vpx), _mm_sub_ps(vpx, load4(n.hi_x))), zero);
  const F4 dy = _mm_max_ps(_mm_max_ps(_mm_sub_ps(load4(n.lo_y), vpy), _mm_sub_ps(vpy, load4(n.hi_y))), zero);
  const F4 d2 = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy));
  _mm_storeu_ps(d_sq, d2);
  return _mm_movemask_ps(_mm_cmple_ps(d2, splat(bound_sq)));
#else
  int mask = 0;
  for (int i = 0; i < 4; ++i) {
    const float dx = std::max(std::max(n.lo_x[i] - px, px - n.hi_x[i]), 0.0f);
    const float dy = std::max(std::max(n.lo_y[i] - py, py - n.hi_y[i]), 0.0f);
    d_sq[i] = dx * dx + dy * dy;
    if (d_sq[i] <= bound_sq) mask |= 1 << i;
  }
  return mask;
#endif
}

#if defined(__SSE2__)
// The entry of the smallest of n squared distances taken four at a time (entries 0–3, then 4–7, ...), kept without a
// branch: its place among the entries is a coin toss to the branch predictor. Each lane keeps its smallest distance
// and that one's entry (as a float, exact below 2^24); nearest() then gives the nearest lane's entry, of equals the
// smallest entry (the smallest distance over the lanes, then the smallest entry of the lanes at it, each a minimum
// of four by two shuffles), or n when every distance is +inf.
class NearestOfFours {
 public:
  explicit NearestOfFours(std::size_t n) : n_(n), entry_(_mm_set1_ps(static_cast<float>(n))) {}
  void take(__m128 d) noexcept {  // the next four entries' distances
    const __m128 nearer = _mm_cmplt_ps(d, d_);
    d_ = _mm_min_ps(d, d_);
    entry_ = _mm_or_ps(_mm_and_ps(nearer, i_), _mm_andnot_ps(nearer, entry_));
    i_ = _mm_add_ps(i_, _mm_set1_ps(4.0f));
  }
  std::size_t nearest() const noexcept {
    const auto min4 = [](__m128 v) {
      v = _mm_min_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(1, 0, 3, 2)));
      return _mm_min_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 3, 0, 1)));
    };
    const __m128 at_min = _mm_cmpeq_ps(d_, min4(d_));
    const __m128 none = _mm_set1_ps(static_cast<float>(n_));
    return static_cast<std::size_t>(
        _mm_cvtss_f32(min4(_mm_or_ps(_mm_and_ps(at_min, entry_), _mm_andnot_ps(at_min, none)))));
  }

 private:
  std::size_t n_;
  __m128 d_ = _mm_set1_ps(std::numeric_limits<float>::infinity());
  __m128 entry_;
  __m128 i_ = _mm_set_ps(3.0f, 2.0f, 1.0f, 0.0f);
};
#endif

// Reciprocal of a sweep extent for sweep_node: ±1e20 in place of 1/0 or of an overflow.
inline float slab_reciprocal(double d) {
  const float f = static_cast<float>(d);
  if (std::abs(f) < 1e-20f) return d < 0.0 ? -1e20f : 1e20f;
  return 1.0f / f;
}

}  // namespace collision_detail
}  // namespace hk
