#pragma once
// The box pass of the scene build: a segment's frame and the extent of the points under it grown in that frame,
// then quantised to the BoxExtent a Scene stores (Scene::segment_box), with the reach every box has (seed paper §3).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "haptics/scene.hpp"
#include "scene_lanes.hpp"

namespace hk {
namespace scene_detail {

// Boxes grow by this much on every side so that corners computed in another frame, which carry
// rounding of a few ulps, still test inside their parents.
constexpr double kBoxPad_m = 1e-9;

// An extent in a segment's frame, as the box pass keeps it: lo = (u_min, n_min), hi = (u_max, n_max) [m].
struct Extent {
  Lanes2 lo, hi;
};

// A segment's frame for the box pass and what the pass grows in it: the extent of the points seen,
// as (u_min, n_min) and (u_max, n_max) [m], and the largest squared distance from the segment of the
// points measured [m²]. Two accumulators of each, for consecutive points, so that the min/max chains
// of the next point need not wait for the last (they are merged by result()).
class BoxGrower {
 public:
  BoxGrower(Vec2 a, Vec2 axis, double length_m)
      : origin_(load(a)),
        axis_x_(lanes(axis.x, axis.x)),
        axis_y_(lanes(axis.y, -axis.y)),
        clamp_hi_(lanes(length_m, 0.0)) {}

  // q's frame coordinates (u, n) = (r·axis, axis×r), r = q − a: r·(ax, ax) + swap(r)·(ay, −ay), bit for bit
  // what dot() and cross() give.
  Lanes2 coords(Vec2 q) const {
    const Lanes2 r = load(q) - origin_;
    return r * axis_x_ + swapped(r) * axis_y_;
  }
  // Grows the extent by the points q[0..count).
  void grow(const Vec2* q, std::size_t count) {
    std::size_t i = 0;
    for (; i + 1 < count; i += 2) {
      const Lanes2 w0 = coords(q[i]), w1 = coords(q[i + 1]);
      lo_[0] = min(lo_[0], w0);
      hi_[0] = max(hi_[0], w0);
      lo_[1] = min(lo_[1], w1);
      hi_[1] = max(hi_[1], w1);
    }
    if (i < count) add(0, coords(q[i]));
  }
  // Grows the extent by the points q[0..count) and measures their squared distances from the segment
  // a + u·axis, 0 ≤ u ≤ length_m: (u − clamp(u, 0, length), n)², from the frame coordinates.
  void grow_measuring(const Vec2* q, std::size_t count) {
    std::size_t i = 0;
    for (; i + 1 < count; i += 2) {
      measure(0, coords(q[i]));
      measure(1, coords(q[i + 1]));
    }
    if (i < count) measure(0, coords(q[i]));
  }
  // Grows the extent by, and measures, the one point q.
  void grow_measuring_one(Vec2 q) { measure(0, coords(q)); }
  // Grows the extent by, and measures, the points q[0..count) in exactly `slots` steps (slots ≥ count;
  // slots = 0: count steps): the steps past the last point take the last again, and with no points at all
  // they take `fallback`, a point the box already holds at distance 0 from the segment. A repeated point
  // changes neither the extent nor the largest distance, and a trip count that is the same for every
  // segment of a level is predicted, where one that follows each segment's count of points is mispredicted
  // at its exit.
  void grow_measuring_slots(const Vec2* q, std::size_t count, std::size_t slots, const Vec2* fallback) {
    const Vec2* base = count > 0 ? q : fallback;
    const std::size_t last = count > 0 ? count - 1 : 0;
    const std::size_t steps = slots > 0 ? slots : count;
    std::size_t i = 0;
    for (; i + 1 < steps; i += 2) {
      measure(0, coords(base[std::min(i, last)]));
      measure(1, coords(base[std::min(i + 1, last)]));
    }
    if (i < steps) measure(0, coords(base[std::min(i, last)]));
  }
  // The extent grown so far, padded by pad_m on every side [m].
  Extent extent(double pad_m) const {
    const Lanes2 pad = lanes(pad_m, pad_m);
    return Extent{min(lo_[0], lo_[1]) - pad, max(hi_[0], hi_[1]) + pad};
  }
  // The largest squared distance measured [m²] (0 when none was).
  double worst_sq() const { return lane0(max(worst_sq_[0], worst_sq_[1])); }

 private:
  void add(int k, Lanes2 w) {
    lo_[k] = min(lo_[k], w);
    hi_[k] = max(hi_[k], w);
  }
  void measure(int k, Lanes2 w) {
    add(k, w);
    const Lanes2 d = w - min(max(w, lanes(0.0, 0.0)), clamp_hi_);  // (distance past an end along the axis, n)
    const Lanes2 d2 = d * d;
    worst_sq_[k] = max(worst_sq_[k], d2 + swapped(d2));
  }

  static constexpr double kInf = std::numeric_limits<double>::infinity();
  Lanes2 origin_, axis_x_, axis_y_, clamp_hi_;
  Lanes2 lo_[2] = {lanes(kInf, kInf), lanes(kInf, kInf)};
  Lanes2 hi_[2] = {lanes(-kInf, -kInf), lanes(-kInf, -kInf)};
  Lanes2 worst_sq_[2] = {lanes(0.0, 0.0), lanes(0.0, 0.0)};
};

// Largest |quantised extent| a level's quantum is chosen for (int16 holds ±32767: room for the outward steps).
constexpr double kQuantumSteps = 32000.0;

// The most a level's quantised boxes reach, in quanta, grown box by box from the quantised lanes
// (quantise_extent) rather than from the stored int16s in a second pass: the widest half-width,
// max(−n_min, n_max) (n_min < 0 < n_max, as every box holds its segment, padded), and the largest
// overhang² + half-width² of one box, overhang = max(0, −u_min, u_over), how far it reaches past either end
// of its segment. Both exact (integers below 2^16, squares summed below 2^31, in doubles). Times the
// quantum, these are the widest box as Scene::segment_box() rebuilds it, bit for bit (k·q is monotone in
// k), and its largest box_error_bound but for the rounding of the end's sum length_m + u_over·q there (a
// few ulps).
class ReachGrower {
 public:
  // One box's quantised lanes: k = (u_min, n_min), m = (n_max, u_over).
  void add(Lanes2 k, Lanes2 m) {
    const Lanes2 zero = lanes(0.0, 0.0);
    const Lanes2 r = max(max(zero - k, swapped(m)), zero);  // (overhang, half-width)
    const Lanes2 r2 = r * r;
    most_ = max(most_, r);
    bound_sq_ = max(bound_sq_, r2 + swapped(r2));
  }
  double half_width() const { return lane1(most_); }    // [quanta]
  double bound_sq() const { return lane0(bound_sq_); }  // [quanta²]

 private:
  Lanes2 most_ = lanes(0.0, 0.0), bound_sq_ = lanes(0.0, 0.0);
};

// A segment's extents in quanta of q (inverse_q = 1/q), rounded outward so that the stored box only grows,
// by less than one quantum on each side: u_min and n_min to the largest k with k·q ≤ v, n_max to the
// smallest k with k·q ≥ v, u_over to the smallest with length_m + k·q ≥ u_max, each product as
// Scene::segment_box computes it. Two lanes at a time: (u_min, n_min) from below, (n_max, u_max) from above
// with offsets (0, length_m). The guess is a product instead of a division: v·(1/q) − 1 truncated from
// below and v·(1/q) + 1 truncated from above, which is v/q rounded down and up where, as in every box the
// pass makes, the lanes from below are < 0 (the box holds the segment's start, padded) and those from above
// > 0 (it holds the end), and v/q is not an integer. Where the product's rounding crosses an integer, v/q
// is one, or a lane has the other sign, the guess is off by a step; the steps that follow (rarely taken, so
// their branches are predicted) make each k the last on the right side of v, so the guess can neither
// undercut v nor add a quantum. |v/q| ≤ kQuantumSteps + a few (an int holds it). Grows `reach` by the box.
inline BoxExtent quantise_extent(const Extent& e, double length_m, double q, double inverse_q, ReachGrower& reach) {
  const Lanes2 lq = lanes(q, q), one = lanes(1.0, 1.0);
  // Adds `step` (±1) to the lanes of k where too(k) holds, until it holds in none.
  const auto step_while = [](Lanes2 k, double step, auto too) {
    for (Mask2 s = too(k); any(s); s = too(k)) k = k + ones(s) * lanes(step, step);
    return k;
  };
  const Lanes2 below = e.lo;
  const Lanes2 above = swapped(e.hi), offset = lanes(0.0, length_m);
  const auto k_over = [&](Lanes2 t) { return where_less(below, t * lq); };                 // k·q > v
  const auto k_short = [&](Lanes2 t) { return where_less_equal((t + one) * lq, below); };  // (k + 1)·q ≤ v
  const auto m_short = [&](Lanes2 t) { return where_less(offset + t * lq, above); };       // short of v
  const auto m_over = [&](Lanes2 t) {
    return where_less_equal(above, offset + (t - one) * lq);
  };  // one less still reaches v
  Lanes2 k = truncated(below * lanes(inverse_q, inverse_q) - one);
  Lanes2 m = truncated((above - offset) * lanes(inverse_q, inverse_q) + one);
  // One test of all four conditions (the guesses are almost always right); the steps only when one holds.
  if (any(k_over(k) | k_short(k) | m_short(m) | m_over(m))) {
    k = step_while(step_while(k, -1.0, k_over), +1.0, k_short);
    m = step_while(step_while(m, +1.0, m_short), -1.0, m_over);
  }
  reach.add(k, m);
  return box_extent(k, m);
}

// A segment's frame (Scene::segment_frame: its unit axis and length [m]) and its measured extents in it,
// padded [m].
struct SegmentExtent {
  SegmentExtent() {
  }  // not zeroed: level_frames and the box pass write every field of a level's entries before they are read
  Extent e;
  Vec2 axis;
  double length_m;
};

// The frames of segments k = 0 .. count−1 of a level, from points[k] to points[k + 1], into out[k].axis and
// out[k].length_m: bit for bit Scene::segment_frame's (the same operations per lane), two segments at a
// time, so that the square roots and divisions of neighbouring segments overlap instead of each box of the
// box pass waiting on its own.
inline void level_frames(const Vec2* points, std::size_t count, SegmentExtent* out) {
  const Lanes2 tiny = lanes(1e-300, 1e-300), one = lanes(1.0, 1.0), zero = lanes(0.0, 0.0);
  std::size_t k = 0;
  for (; k + 1 < count; k += 2) {
    const Lanes2 p1 = load(points[k + 1]);
    const Lanes2 d0 = p1 - load(points[k]), d1 = load(points[k + 2]) - p1;  // (dx, dy) of each
    const Lanes2 dx = low_lanes(d0, d1), dy = high_lanes(d0, d1);           // of both
    const Lanes2 len = sqrt(dx * dx + dy * dy);
    const Lanes2 inverse = one / len;
    const Lanes2 ax = where_greater(len, tiny, dx * inverse, one), ay = where_greater(len, tiny, dy * inverse, zero);
    const Lanes2 axis0 = low_lanes(ax, ay), axis1 = high_lanes(ax, ay);
    out[k].axis = Vec2{lane0(axis0), lane1(axis0)};
    out[k + 1].axis = Vec2{lane0(axis1), lane1(axis1)};
    out[k].length_m = lane0(len);
    out[k + 1].length_m = lane1(len);
  }
  if (k < count) out[k].axis = Scene::segment_frame(points[k], points[k + 1], &out[k].length_m);
}

}  // namespace scene_detail
}  // namespace hk
