#pragma once
// Two doubles side by side (SSE2, or two scalars computing the same numbers bit for bit): the arithmetic of the
// scene build's box pass, and the packing of a box's quantised extents (scene_box_quantise.hpp).
#include <bit>
#include <cmath>
#include <cstdint>

#include "haptics/scene.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hk {
namespace scene_detail {

// Two doubles side by side, (lane 0, lane 1): the box pass keeps a point's frame coordinates (u, n) in
// one, so a point costs one subtraction, two products, one sum and a min and max of pairs (SSE2 where
// the target has it, two scalars elsewhere; both compute the same numbers bit for bit).
#if defined(__SSE2__)
struct Lanes2 {
  __m128d v;
};
inline Lanes2 lanes(double lane0, double lane1) { return {_mm_set_pd(lane1, lane0)}; }
inline Lanes2 load(const Vec2& q) { return {_mm_loadu_pd(&q.x)}; }
inline Lanes2 operator+(Lanes2 a, Lanes2 b) { return {_mm_add_pd(a.v, b.v)}; }
inline Lanes2 operator-(Lanes2 a, Lanes2 b) { return {_mm_sub_pd(a.v, b.v)}; }
inline Lanes2 operator*(Lanes2 a, Lanes2 b) { return {_mm_mul_pd(a.v, b.v)}; }
inline Lanes2 min(Lanes2 a, Lanes2 b) { return {_mm_min_pd(a.v, b.v)}; }
inline Lanes2 max(Lanes2 a, Lanes2 b) { return {_mm_max_pd(a.v, b.v)}; }
inline Lanes2 operator/(Lanes2 a, Lanes2 b) { return {_mm_div_pd(a.v, b.v)}; }
inline Lanes2 sqrt(Lanes2 a) { return {_mm_sqrt_pd(a.v)}; }
inline Lanes2 swapped(Lanes2 a) { return {_mm_shuffle_pd(a.v, a.v, 1)}; }
// (a's lane 0, b's lane 0) and (a's lane 1, b's lane 1).
inline Lanes2 low_lanes(Lanes2 a, Lanes2 b) { return {_mm_unpacklo_pd(a.v, b.v)}; }
inline Lanes2 high_lanes(Lanes2 a, Lanes2 b) { return {_mm_unpackhi_pd(a.v, b.v)}; }
// Each lane of `if_true` where that lane of x > y (false for a NaN), else that of `otherwise`.
inline Lanes2 where_greater(Lanes2 x, Lanes2 y, Lanes2 if_true, Lanes2 otherwise) {
  const __m128d keep = _mm_cmpgt_pd(x.v, y.v);
  return {_mm_or_pd(_mm_and_pd(keep, if_true.v), _mm_andnot_pd(keep, otherwise.v))};
}
inline double lane0(Lanes2 a) { return _mm_cvtsd_f64(a.v); }
inline double lane1(Lanes2 a) { return _mm_cvtsd_f64(_mm_unpackhi_pd(a.v, a.v)); }
// Each lane rounded toward zero (|lane| < 2^31).
inline Lanes2 truncated(Lanes2 a) { return {_mm_cvtepi32_pd(_mm_cvttpd_epi32(a.v))}; }
// Which lanes of a comparison hold: a < b (where_less) or a ≤ b (where_less_equal); `|` joins two.
struct Mask2 {
  __m128d v;
};
inline Mask2 where_less(Lanes2 a, Lanes2 b) { return {_mm_cmplt_pd(a.v, b.v)}; }
inline Mask2 where_less_equal(Lanes2 a, Lanes2 b) { return {_mm_cmple_pd(a.v, b.v)}; }
inline Mask2 operator|(Mask2 a, Mask2 b) { return {_mm_or_pd(a.v, b.v)}; }
// Whether it holds in some lane.
inline bool any(Mask2 m) { return _mm_movemask_pd(m.v) != 0; }
// 1 in each lane where it holds, else 0.
inline Lanes2 ones(Mask2 m) { return {_mm_and_pd(m.v, _mm_set1_pd(1.0))}; }
// A box's quantised extents, k = (u_min, n_min) and m = (n_max, u_over) (integers of |value| < 2^15 held in
// doubles), as its BoxExtent: two conversions to int32 pairs, one interleave and shuffle into the struct's
// order, one pack to int16 and a single 8-byte store, instead of a conversion and store per field.
inline BoxExtent box_extent(Lanes2 k, Lanes2 m) {
  const __m128i mixed =
      _mm_unpacklo_epi32(_mm_cvttpd_epi32(k.v), _mm_cvttpd_epi32(m.v));       // u_min, n_max, n_min, u_over
  const __m128i ordered = _mm_shuffle_epi32(mixed, _MM_SHUFFLE(1, 2, 3, 0));  // u_min, u_over, n_min, n_max
  std::int64_t bits = 0;
  _mm_storel_epi64(reinterpret_cast<__m128i*>(&bits), _mm_packs_epi32(ordered, ordered));
  return std::bit_cast<BoxExtent>(bits);
}
#else
struct Lanes2 {
  double a, b;
};
inline Lanes2 lanes(double lane0, double lane1) { return {lane0, lane1}; }
inline Lanes2 load(const Vec2& q) { return {q.x, q.y}; }
inline Lanes2 operator+(Lanes2 a, Lanes2 b) { return {a.a + b.a, a.b + b.b}; }
inline Lanes2 operator-(Lanes2 a, Lanes2 b) { return {a.a - b.a, a.b - b.b}; }
inline Lanes2 operator*(Lanes2 a, Lanes2 b) { return {a.a * b.a, a.b * b.b}; }
inline Lanes2 min(Lanes2 a, Lanes2 b) { return {a.a < b.a ? a.a : b.a, a.b < b.b ? a.b : b.b}; }
inline Lanes2 max(Lanes2 a, Lanes2 b) { return {a.a > b.a ? a.a : b.a, a.b > b.b ? a.b : b.b}; }
inline Lanes2 operator/(Lanes2 a, Lanes2 b) { return {a.a / b.a, a.b / b.b}; }
inline Lanes2 sqrt(Lanes2 a) { return {std::sqrt(a.a), std::sqrt(a.b)}; }
inline Lanes2 swapped(Lanes2 a) { return {a.b, a.a}; }
inline Lanes2 low_lanes(Lanes2 a, Lanes2 b) { return {a.a, b.a}; }
inline Lanes2 high_lanes(Lanes2 a, Lanes2 b) { return {a.b, b.b}; }
inline Lanes2 where_greater(Lanes2 x, Lanes2 y, Lanes2 if_true, Lanes2 otherwise) {
  return {x.a > y.a ? if_true.a : otherwise.a, x.b > y.b ? if_true.b : otherwise.b};
}
inline double lane0(Lanes2 a) { return a.a; }
inline double lane1(Lanes2 a) { return a.b; }
inline Lanes2 truncated(Lanes2 a) {
  return {static_cast<double>(static_cast<int>(a.a)), static_cast<double>(static_cast<int>(a.b))};
}
struct Mask2 {
  bool a, b;
};
inline Mask2 where_less(Lanes2 a, Lanes2 b) { return {a.a < b.a, a.b < b.b}; }
inline Mask2 where_less_equal(Lanes2 a, Lanes2 b) { return {a.a <= b.a, a.b <= b.b}; }
inline Mask2 operator|(Mask2 a, Mask2 b) { return {a.a || b.a, a.b || b.b}; }
inline bool any(Mask2 m) { return m.a || m.b; }
inline Lanes2 ones(Mask2 m) { return {m.a ? 1.0 : 0.0, m.b ? 1.0 : 0.0}; }
inline BoxExtent box_extent(Lanes2 k, Lanes2 m) {
  return BoxExtent{static_cast<std::int16_t>(k.a), static_cast<std::int16_t>(m.b), static_cast<std::int16_t>(k.b),
                   static_cast<std::int16_t>(m.a)};
}
#endif

}  // namespace scene_detail
}  // namespace hk
