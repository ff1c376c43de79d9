// Scene index and collision tree construction (seed paper §3; DESIGN.md "Collision tree").
// A level-0 box holds its segment and the original input vertices it stands for; a level-l box holds
// its segment, every finer level's points under it and those original vertices, so a miss on a box
// proves a miss on everything under it, down to the original curve.
#include "haptics/scene.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hk {
namespace {

// Boxes grow by this much on every side so that corners computed in another frame, which carry
// rounding of a few ulps, still test inside their parents.
constexpr double kBoxPad_m = 1e-9;

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
  const __m128i mixed = _mm_unpacklo_epi32(_mm_cvttpd_epi32(k.v), _mm_cvttpd_epi32(m.v));  // u_min, n_max, n_min, u_over
  const __m128i ordered = _mm_shuffle_epi32(mixed, _MM_SHUFFLE(1, 2, 3, 0));                // u_min, u_over, n_min, n_max
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
inline Lanes2 truncated(Lanes2 a) { return {static_cast<double>(static_cast<int>(a.a)), static_cast<double>(static_cast<int>(a.b))}; }
struct Mask2 {
  bool a, b;
};
inline Mask2 where_less(Lanes2 a, Lanes2 b) { return {a.a < b.a, a.b < b.b}; }
inline Mask2 where_less_equal(Lanes2 a, Lanes2 b) { return {a.a <= b.a, a.b <= b.b}; }
inline Mask2 operator|(Mask2 a, Mask2 b) { return {a.a || b.a, a.b || b.b}; }
inline bool any(Mask2 m) { return m.a || m.b; }
inline Lanes2 ones(Mask2 m) { return {m.a ? 1.0 : 0.0, m.b ? 1.0 : 0.0}; }
inline BoxExtent box_extent(Lanes2 k, Lanes2 m) {
  return BoxExtent{static_cast<std::int16_t>(k.a), static_cast<std::int16_t>(m.b), static_cast<std::int16_t>(k.b), static_cast<std::int16_t>(m.a)};
}
#endif

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
      : origin_(load(a)), axis_x_(lanes(axis.x, axis.x)), axis_y_(lanes(axis.y, -axis.y)), clamp_hi_(lanes(length_m, 0.0)) {}

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
  double half_width() const { return lane1(most_); }  // [quanta]
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
  const auto k_over = [&](Lanes2 t) { return where_less(below, t * lq); };                     // k·q > v
  const auto k_short = [&](Lanes2 t) { return where_less_equal((t + one) * lq, below); };       // (k + 1)·q ≤ v
  const auto m_short = [&](Lanes2 t) { return where_less(offset + t * lq, above); };           // short of v
  const auto m_over = [&](Lanes2 t) { return where_less_equal(above, offset + (t - one) * lq); };  // one less still reaches v
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
  SegmentExtent() {}  // not zeroed: level_frames and the box pass write every field of a level's entries before they are read
  Extent e;
  Vec2 axis;
  double length_m;
};

// The frames of segments k = 0 .. count−1 of a level, from points[k] to points[k + 1], into out[k].axis and
// out[k].length_m: bit for bit Scene::segment_frame's (the same operations per lane), two segments at a
// time, so that the square roots and divisions of neighbouring segments overlap instead of each box of the
// box pass waiting on its own.
void level_frames(const Vec2* points, std::size_t count, SegmentExtent* out) {
  const Lanes2 tiny = lanes(1e-300, 1e-300), one = lanes(1.0, 1.0), zero = lanes(0.0, 0.0);
  std::size_t k = 0;
  for (; k + 1 < count; k += 2) {
    const Lanes2 p1 = load(points[k + 1]);
    const Lanes2 d0 = p1 - load(points[k]), d1 = load(points[k + 2]) - p1;  // (dx, dy) of each
    const Lanes2 dx = low_lanes(d0, d1), dy = high_lanes(d0, d1);          // of both
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

// One node of the scene hierarchy while it is built: the chunk range it covers in leaf order and,
// for an inner node, the id of its first child (the second is first + 1).
struct HierarchyNode {
  std::size_t begin = 0, end = 0;
  std::size_t first_child = 0;
  bool leaf = true;
};

constexpr std::size_t kChunksPerLeaf = 4;

// Median split on the longer axis of the chunk centres. `order` is permuted in place into leaf order.
// Children of a node are allocated as a consecutive pair, so they have consecutive ids.
void build_hierarchy(std::vector<std::size_t>& order, const std::vector<Vec2>& centre, std::vector<HierarchyNode>& nodes) {
  nodes.clear();
  nodes.push_back({0, order.size(), 0, true});
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const std::size_t begin = nodes[i].begin, end = nodes[i].end;
    if (end - begin <= kChunksPerLeaf) continue;
    Vec2 lo = centre[order[begin]], hi = lo;
    for (std::size_t k = begin; k < end; ++k) {
      const Vec2 c = centre[order[k]];
      lo = {std::min(lo.x, c.x), std::min(lo.y, c.y)};
      hi = {std::max(hi.x, c.x), std::max(hi.y, c.y)};
    }
    const bool split_x = hi.x - lo.x >= hi.y - lo.y;
    const std::size_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + static_cast<long>(begin), order.begin() + static_cast<long>(mid), order.begin() + static_cast<long>(end),
                     [&](std::size_t a, std::size_t b) { return split_x ? centre[a].x < centre[b].x : centre[a].y < centre[b].y; });
    nodes[i].leaf = false;
    nodes[i].first_child = nodes.size();
    nodes.push_back({begin, mid, 0, true});
    nodes.push_back({mid, end, 0, true});
  }
}

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

bool box_contains(const ErrorBox& box, Vec2 p, double margin_m) {
  const Vec2 r = p - box.origin_m;
  const double u = dot(r, box.axis);
  const double n = cross(box.axis, r);
  return u >= box.u_min - margin_m && u <= box.u_max + margin_m && n >= box.n_min - margin_m && n <= box.n_max + margin_m;
}

void box_corners(const ErrorBox& box, Vec2 out[4]) {
  const Vec2 nrm = left_perp(box.axis);
  out[0] = box.origin_m + box.u_min * box.axis + box.n_min * nrm;
  out[1] = box.origin_m + box.u_max * box.axis + box.n_min * nrm;
  out[2] = box.origin_m + box.u_max * box.axis + box.n_max * nrm;
  out[3] = box.origin_m + box.u_min * box.axis + box.n_max * nrm;
}

double box_error_bound(const ErrorBox& box, double segment_length_m) {
  const double overhang = std::max(std::max(0.0, -box.u_min), box.u_max - segment_length_m);
  const double half_width = box_half_width(box);
  return std::sqrt(overhang * overhang + half_width * half_width);
}

std::size_t Scene::hot_bytes() const {
  return points_m_.size() * sizeof(Vec2) + extent_.size() * sizeof(BoxExtent) + tag_.size() * sizeof(std::uint32_t) +
         curve_nodes_.size() * sizeof(CurveNodes) + group_box_.size() * sizeof(Aabb) + group_info_.size() * sizeof(NodeInfo) +
         (group_parent_.size() + group_child_first_.size() + group_child_count_.size() + chunk_of_curve_.size()) * sizeof(std::uint32_t) +
         wide_.bytes();
}

Aabb Scene::aabb(std::uint32_t node) const {
  if (node >= segment_nodes_) return group_box_[node - segment_nodes_];
  // From the box's centre and half-extents rather than its four corners: half-width along x is
  // |axis.x| hu + |axis.y| hn (the normal is (−axis.y, axis.x)), along y |axis.y| hu + |axis.x| hn. Grown by
  // a few ulps of the largest coordinate, so it holds the corners as rounded by box_corners too.
  const ErrorBox b = segment_box(node);
  const double cu = 0.5 * (b.u_min + b.u_max), hu = 0.5 * (b.u_max - b.u_min);
  const double cn = 0.5 * (b.n_min + b.n_max), hn = 0.5 * (b.n_max - b.n_min);
  const Vec2 c{b.origin_m.x + cu * b.axis.x - cn * b.axis.y, b.origin_m.y + cu * b.axis.y + cn * b.axis.x};
  const double ax = std::abs(b.axis.x), ay = std::abs(b.axis.y);
  const double slack = 0x1p-48 * (std::abs(c.x) + std::abs(c.y) + hu + hn);
  const double hx = ax * hu + ay * hn + slack, hy = ay * hu + ax * hn + slack;
  return Aabb{{c.x - hx, c.y - hy}, {c.x + hx, c.y + hy}};
}

std::size_t Scene::total_segments(int level) const {
  std::size_t total = 0;
  for (std::size_t c = 0; c < curves_.size(); ++c) total += curves_[c].segment_count[clamp_level(c, level)];
  return total;
}

double Scene::max_box_half_width_m(int level) const {
  double widest = 0.0;
  for (std::size_t c = 0; c < curves_.size(); ++c) widest = std::max(widest, curves_[c].max_box_half_width_m[clamp_level(c, level)]);
  return widest;
}

double Scene::max_error_bound_m(int level) const {
  double bound = 0.0;
  for (std::size_t c = 0; c < curves_.size(); ++c) bound = std::max(bound, curves_[c].max_error_bound_m[clamp_level(c, level)]);
  return bound;
}

int Scene::coarsest_level_within(std::size_t c, double tol_m) const {
  // A curve's bounds need not grow with the level, so every level is looked at, not just the first that fails.
  const CurveInfo& ci = curves_[c];
  int level = 0;
  for (int l = 0; l < ci.levels; ++l) {
    if (ci.max_error_bound_m[l] <= tol_m) level = l;
  }
  return level;
}

int Scene::max_curve_levels() const {
  int levels = 1;
  for (const CurveInfo& ci : curves_) levels = std::max(levels, ci.levels);
  return levels;
}

// The phases of Scene::build, in order (DESIGN.md "Collision tree"). A friend of Scene: each phase
// fills some of its arrays from what the phases before it left.
class SceneBuild {
 public:
  // A run of at most kSegmentsPerChunk consecutive coarsest segments of one curve: a leaf of the hierarchy.
  struct Chunk {
    std::uint32_t curve, first_segment, count;
  };

  // Where each curve's original vertices' arc table starts in the build's flat table (arc_table).
  struct OriginalArcs {
    std::vector<double> cum;          // every kept curve's arc table, one after the other [m]
    std::vector<std::size_t> offset;  // per curve: its first entry in cum
  };

  // Each curve's level plan (plan_levels) and its original's arc table; curves without a model (fewer
  // than 2 points, non-finite, zero length: arc_table's CurveError) are skipped and counted.
  static void plan_curves(Scene& scene, const std::vector<Polyline>& input, int max_levels, OriginalArcs& arcs) {
    std::size_t arc_entries = 0;
    for (const Polyline& src : input) arc_entries += src.points_m.size() + 1;  // arc_table_size's most
    arcs.cum.reserve(arc_entries);
    arcs.offset.reserve(input.size());
    scene.curves_.reserve(input.size());
    scene.source_index_.reserve(input.size());
    for (std::size_t i = 0; i < input.size(); ++i) {
      const Polyline& src = input[i];
      const std::size_t at = arcs.cum.size();
      double length_m = 0.0;
      try {
        arcs.cum.resize(at + std::max<std::size_t>(arc_table_size(src), 1));
        length_m = arc_table(src, arcs.cum.data() + at);
      } catch (const CurveError&) {
        arcs.cum.resize(at);
        ++scene.skipped_;  // nothing to feel
        continue;
      }
      const LevelPlan plan = plan_levels(src.points_m.size(), src.closed, max_levels);
      CurveInfo ci;
      ci.closed = src.closed;
      ci.levels = plan.levels_above_0 + 1;
      ci.length_m = length_m;
      for (int l = 0; l < ci.levels; ++l) {
        ci.point_count[l] = static_cast<std::uint32_t>(level_point_count(plan.level0_points, src.closed, l));
        ci.segment_count[l] = src.closed ? ci.point_count[l] : ci.point_count[l] - 1;
      }
      scene.curves_.push_back(ci);
      scene.source_index_.push_back(i);
      arcs.offset.push_back(at);
    }
  }

  // Slots of every level, level by level within each curve (scene.hpp "Node numbering"): room for the
  // points and a closed curve's first point again, each slot tagged with its curve and level.
  static void lay_out_curves(Scene& scene) {
    std::size_t nslots = 0;
    scene.curve_nodes_.resize(scene.curves_.size());
    for (std::size_t c = 0; c < scene.curves_.size(); ++c) {
      CurveInfo& ci = scene.curves_[c];
      scene.curve_nodes_[c].levels = static_cast<std::uint32_t>(ci.levels);
      for (int l = 0; l < ci.levels; ++l) {
        ci.point_offset[l] = static_cast<std::uint32_t>(nslots);
        ci.box_offset[l] = static_cast<std::uint32_t>(nslots);
        scene.curve_nodes_[c].box_offset[l] = static_cast<std::uint32_t>(nslots);
        nslots += ci.segment_count[l] + 1;
      }
    }
    if (nslots >= std::numeric_limits<std::uint32_t>::max() / 2 || scene.curves_.size() >= (std::size_t{1} << (32 - Scene::kTagLevelBits))) {
      throw std::bad_alloc();  // ids would not fit: far beyond any memory this runs in
    }
    scene.segment_nodes_ = nslots;
    scene.points_m_.resize(nslots);
    scene.extent_.resize(nslots);
    scene.tag_.resize(nslots);
    for (std::size_t c = 0; c < scene.curves_.size(); ++c) {
      const CurveInfo& ci = scene.curves_[c];
      for (int l = 0; l < ci.levels; ++l) {
        const std::uint32_t tag = static_cast<std::uint32_t>(c) << Scene::kTagLevelBits | static_cast<std::uint32_t>(l);
        std::fill_n(scene.tag_.begin() + static_cast<std::ptrdiff_t>(ci.point_offset[l]), ci.segment_count[l] + 1, tag);
      }
    }
  }

  // The multiresolution model of every curve, in its slots (seed §2): level 0 resampled on the original,
  // each coarser level's scaling coefficients by the forward transform, a closed curve's first point
  // repeated after each level's last. The wavelet coefficients are not kept: every level's scaling
  // coefficients are, which is what the walks read (build_multires gives both, for analysis).
  static void transform_curves(Scene& scene, const std::vector<Polyline>& input, const OriginalArcs& arcs) {
    std::vector<Vec2> scratch;
    Vec2* level[kMaxLevels] = {};
    for (std::size_t c = 0; c < scene.curves_.size(); ++c) {
      const CurveInfo& ci = scene.curves_[c];
      const Polyline& src = input[scene.source_index_[c]];
      for (int l = 0; l < ci.levels; ++l) level[l] = scene.points_m_.data() + ci.point_offset[l];
      resample_arc_length(src, arcs.cum.data() + arcs.offset[c], ci.point_count[0], level[0]);
      scratch.resize(std::max(scratch.size(), forward_scratch_size(ci.point_count[0])));
      Vec2* const no_wavelets[kMaxLevels] = {};
      forward_levels(level, no_wavelets, ci.point_count[0], ci.closed, ci.levels, scratch.data());
      if (ci.closed) {
        for (int l = 0; l < ci.levels; ++l) level[l][ci.point_count[l]] = level[l][0];
      }
    }
  }

  // Chunks of every curve's coarsest level, with the centres of their points (for the median split).
  // They are the leaves of the scene hierarchy, so no node has more than a handful of children (a long
  // curve would otherwise fan out to hundreds of coarsest segments, and the boundary section with it).
  static void make_chunks(Scene& scene, std::vector<Chunk>& chunks, std::vector<Vec2>& centre) {
    for (std::size_t c = 0; c < scene.curves_.size(); ++c) {
      scene.curve_nodes_[c].chunk_offset = static_cast<std::uint32_t>(chunks.size());
      const int top = scene.curves_[c].levels - 1;
      const Vec2* pts = scene.points(c, top);  // k_top + 1 slots: a closed curve's first point repeats
      const std::uint32_t k_top = scene.curves_[c].segment_count[top];
      for (std::uint32_t k = 0; k < k_top; k += Scene::kSegmentsPerChunk) {
        const std::uint32_t n = std::min<std::uint32_t>(Scene::kSegmentsPerChunk, k_top - k);
        Vec2 lo = pts[k], hi = pts[k];
        for (std::uint32_t i = k; i <= k + n; ++i) {
          const Vec2 q = pts[i];
          lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
          hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
        }
        chunks.push_back({static_cast<std::uint32_t>(c), k, n});
        centre.push_back(0.5 * (lo + hi));
      }
    }
  }

  // The chunk and hierarchy nodes' arrays (the slots' were sized by lay_out_curves).
  static void allocate_groups(Scene& scene, std::size_t groups, std::size_t chunks) {
    scene.group_box_.resize(groups);
    scene.group_info_.resize(groups);
    scene.group_parent_.assign(groups, 0);
    scene.group_child_first_.assign(groups, 0);
    scene.group_child_count_.assign(groups, 0);
    scene.chunk_of_curve_.assign(chunks, 0);
  }

  // Per level-0 segment k of curve c: the original vertices strictly inside it are
  // [orig_first[k], orig_first[k+1]) (by arc length along the original: `cum` is its arc table, and the
  // level-0 points' arc lengths are their resampling parameters, level0_arc_m): orig_first[k] counts the
  // vertices j with cum[j] < step·k (the arc table never decreases), and orig_first[s0] is every vertex.
  // Counted per vertex rather than by walking j along k: vertex j counts toward every k from its key, the
  // least k with cum[j] < step·k, so orig_first is the running sum of how many vertices have each key. The
  // key's guess, cum[j]·(1/step) rounded down + 1, can be off by one where the product's rounding crosses an
  // integer; the steps after it (rarely taken, so predicted) make it the least k for which the comparison
  // holds, as the walk evaluated it. A walk's loop exit would follow the vertices' irregular spacing and be
  // mispredicted about once a segment.
  static void map_originals(const CurveInfo& ci, const Polyline& src, const double* cum, std::vector<std::uint32_t>& orig_first) {
    const std::size_t n = src.points_m.size();
    const std::size_t s0 = ci.segment_count[0], n0 = ci.point_count[0];
    const double step = resample_step_m(ci.length_m, n0, ci.closed);  // divided once per curve
    const double inverse_step = 1.0 / step;
    const auto start = [step](std::size_t k) { return step * static_cast<double>(k); };  // level0_arc_m for k < s0
    orig_first.assign(s0 + 1, 0);
    for (std::size_t j = 0; j < n; ++j) {
      const double x = cum[j];  // 0 ≤ x ≤ length_m
      auto key = std::min(static_cast<std::size_t>(x * inverse_step) + 1, s0);
      while (key > 1 && x < start(key - 1)) --key;   // cum[0] = 0 < step·k for every k ≥ 1, never for k = 0
      while (key < s0 && !(x < start(key))) ++key;  // keys past the last segment count only toward orig_first[s0]
      ++orig_first[key];
    }
    for (std::size_t k = 1; k <= s0; ++k) orig_first[k] += orig_first[k - 1];
    orig_first[s0] = static_cast<std::uint32_t>(n);
  }

  // Level-0 points k0 < i < k1 that the box pass must still see once it has point k0 and the original
  // vertices under level-0 segments [k0, k1): those from the returned index on. Level 0 is resampled on the
  // original polyline (resample_arc_length), so every level-0 point lies on the polyline p_k0, the original
  // vertices in order, p_k1, and the point is a convex combination of the two vertices of its piece. Frame
  // coordinates, and the distance from a segment, are convex along a piece: such a point adds nothing to
  // the extent or the measured error that the piece's ends do not (up to rounding of a few ulps, far inside
  // the box pad). The last piece ends at p_k1, which the segment's box holds but its error does not measure,
  // so the level-0 points on it, those after the last level-0 segment holding an original, are measured:
  // returns that segment + 1, or k0 + 1 when none holds one (then every level-0 point is measured).
  static std::size_t first_level0_after_originals(const std::vector<std::uint32_t>& orig_first, std::size_t k0, std::size_t k1) {
    for (std::size_t i = k1; i > k0; --i) {
      if (orig_first[i - 1] != orig_first[i]) return i;  // level-0 segment i − 1 holds originals
    }
    return k0 + 1;
  }

  // How many steps every level-l segment of the box pass takes its original vertices in (grow_measuring_slots):
  // the most under one segment of the level, or 0 (each takes its own count) when that is more than twice the
  // mean + 4, so that a curve whose vertices bunch up (a long straight edge beside a tight curl) does not
  // make every segment pay for the bunch. On pictures' edge chains it is 1.1–1.7x the mean.
  static std::size_t original_slots(const std::vector<std::uint32_t>& orig_first, int l, std::size_t segments) {
    std::size_t most = 0;
    for (std::size_t k = 0; k < segments; ++k) most = std::max<std::size_t>(most, orig_first[(k + 1) << l] - orig_first[k << l]);
    const std::size_t all = orig_first[segments << l] - orig_first[0];
    return most * segments <= 2 * all + 4 * segments ? most : 0;
  }

  // Error boxes of every segment of curve c, as tight as containment allows: the box of level-l
  // segment k is the extent, in the segment's frame, of its own end points, of every point of every
  // finer level j < l under it (points k·2^(l−j) .. (k+1)·2^(l−j)), and of the original vertices under
  // it. Convexity then puts every finer segment and the original sub-polyline inside, which is all a
  // miss must prove (seed §3); children's boxes need not fit inside (issue 18: boxes built from the
  // children's corners were 1.09–1.45x the true deviation). The same pass measures the level's error
  // (grow_measuring) from the frame coordinates it computes anyway, then quantises the extents
  // (quantise_level).
  static void build_segment_boxes(Scene& scene, std::size_t c, const Polyline& src, const std::vector<std::uint32_t>& orig_first,
                                  std::vector<SegmentExtent>& level) {
    CurveInfo& ci = scene.curves_[c];
    const Vec2* orig = src.points_m.data();
    for (int l = 0; l < ci.levels; ++l) {
      level.resize(ci.segment_count[l]);
      level_frames(scene.points(c, l), ci.segment_count[l], level.data());  // the frames Scene::segment_box() rebuilds
      double worst_sq = 0.0;  // largest squared distance of a level-0 point or original vertex from its level-l segment [m²]
      WidestExtent widest;
      const std::size_t orig_slots = original_slots(orig_first, l, ci.segment_count[l]);
      for (std::size_t k = 0; k < ci.segment_count[l]; ++k) {
        Vec2 a, b;
        scene.segment_points(ci.box_offset[l] + static_cast<std::uint32_t>(k), &a, &b);
        SegmentExtent& se = level[k];
        BoxGrower box(a, se.axis, se.length_m);
        const Vec2 ends[2] = {a, b};
        box.grow(ends, 2);
        for (int j = 1; j < l; ++j) {  // finer levels' points under this segment (level 0 below, with the errors)
          const std::size_t span = std::size_t{1} << (l - j);
          box.grow(scene.points(c, j) + k * span, span + 1);  // a closed curve's first point repeats at its end
        }
        const std::size_t k0 = k << l, k1 = (k + 1) << l;  // level-0 segments under it
        if (l > 0) {
          const Vec2* fine = scene.points(c, 0);
          const std::size_t tail = first_level0_after_originals(orig_first, k0, k1);
          box.grow_measuring_one(fine[k0]);
          box.grow_measuring(fine + tail, k1 - tail);
          box.grow(fine + k1, 1);  // the next segment's first point: in the box, measured with that segment
        }
        box.grow_measuring_slots(orig + orig_first[k0], orig_first[k1] - orig_first[k0], orig_slots, &ends[0]);
        se.e = box.extent(kBoxPad_m);
        widest.add(se.e, se.length_m);
        worst_sq = std::max(worst_sq, box.worst_sq());
      }
      ci.max_error_m[l] = std::sqrt(worst_sq);  // one root per level
      quantise_level(scene, c, l, level, widest.widest());
    }
    assign_tolerance_levels(scene, c);
  }

  // The largest |extent| of a level's boxes, what its quantum is chosen for [m]: the most any box reaches
  // before its start, past its end or to either side, grown box by box as the pass measures them.
  class WidestExtent {
   public:
    void add(const Extent& e, double length_m) {
      const Lanes2 zero = lanes(0.0, 0.0);
      before_right_ = max(before_right_, zero - e.lo);
      const Lanes2 d = e.hi - lanes(length_m, 0.0);  // (u_max − length, n_max)
      past_left_ = max(past_left_, max(d, zero - d));  // (|u_max − length|, n_max): n_max > 0, as the box holds its segment
    }
    double widest() const {
      const Lanes2 w = max(before_right_, past_left_);
      return std::max(lane0(w), lane1(w));
    }

   private:
    Lanes2 before_right_ = lanes(0.0, 0.0);  // (−u_min, −n_min): the most before the start, to the right
    Lanes2 past_left_ = lanes(0.0, 0.0);     // (|u_max − length|, n_max): the most past the end, to the left
  };

  // The curve's level at each tolerance step (CurveNodes::tolerance_level): the coarsest level whose error
  // bound is within the step's tolerance, 0 when none is.
  static void assign_tolerance_levels(Scene& scene, std::size_t c) {
    CurveNodes& cn = scene.curve_nodes_[c];
    for (int t = 0; t < kToleranceSteps; ++t) cn.tolerance_level[t] = static_cast<std::uint8_t>(scene.coarsest_level_within(c, kToleranceLadder_m[t]));
  }

  // Level l's quantum (its widest extent / kQuantumSteps) and every segment's extents in it, rounded
  // outward; the widest box of the level and its largest box error bound (ReachGrower).
  static void quantise_level(Scene& scene, std::size_t c, int l, const std::vector<SegmentExtent>& level, double widest) {
    CurveInfo& ci = scene.curves_[c];
    const float quantum = static_cast<float>(widest / kQuantumSteps);  // > 0: every extent holds the pad
    scene.curve_nodes_[c].quantum_m[l] = quantum;
    const double q = quantum, inverse_q = 1.0 / q;
    BoxExtent* out = scene.extent_.data() + ci.box_offset[l];
    ReachGrower reach;
    for (std::size_t k = 0; k < ci.segment_count[l]; ++k) out[k] = quantise_extent(level[k].e, level[k].length_m, q, inverse_q, reach);
    ci.max_box_half_width_m[l] = reach.half_width() * q;
    ci.max_error_bound_m[l] = std::sqrt(reach.bound_sq()) * q;
  }

  // Every curve's error boxes (build_segment_boxes) and the scene's bounds, those of the level-0 points.
  static void build_curves(Scene& scene, const std::vector<Polyline>& input, const OriginalArcs& arcs) {
    std::vector<std::uint32_t> orig_first;
    std::vector<SegmentExtent> level_extent;  // one level's measured extents, before quantising
    BoxGrower bounds(Vec2{0.0, 0.0}, Vec2{1.0, 0.0}, 0.0);  // the identity frame: (u, n) = (x, y)
    for (std::size_t c = 0; c < scene.curves_.size(); ++c) {
      const Polyline& src = input[scene.source_index_[c]];
      map_originals(scene.curves_[c], src, arcs.cum.data() + arcs.offset[c], orig_first);
      build_segment_boxes(scene, c, src, orig_first, level_extent);
      bounds.grow(scene.points(c, 0), scene.curves_[c].point_count[0]);
    }
    if (!scene.curves_.empty()) {
      const Extent e = bounds.extent(0.0);
      scene.bounds_min_ = Vec2{lane0(e.lo), lane1(e.lo)};
      scene.bounds_max_ = Vec2{lane0(e.hi), lane1(e.hi)};
    }
  }

  // An axis-aligned node around the rectangles of children [first, first + count) (Scene::aabb: a segment's
  // error box as Scene::box() rebuilds it, so the rounding of the stored extents is inside, or a group's own
  // rectangle), padded; links chunk and hierarchy children to it.
  static void make_aligned_node(Scene& scene, std::uint32_t node, std::uint32_t first, std::uint32_t count, NodeInfo info) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    Aabb r{{kInf, kInf}, {-kInf, -kInf}};
    for (std::uint32_t i = 0; i < count; ++i) {
      const Aabb a = scene.aabb(first + i);
      r.lo = {std::min(r.lo.x, a.lo.x), std::min(r.lo.y, a.lo.y)};
      r.hi = {std::max(r.hi.x, a.hi.x), std::max(r.hi.y, a.hi.y)};
      if (!scene.is_segment(first + i)) scene.group_parent_[first + i - scene.segment_nodes_] = node;
    }
    const std::size_t g = node - scene.segment_nodes_;
    scene.group_box_[g] = Aabb{{r.lo.x - kBoxPad_m, r.lo.y - kBoxPad_m}, {r.hi.x + kBoxPad_m, r.hi.y + kBoxPad_m}};
    scene.group_info_[g] = info;
    scene.group_child_first_[g] = first;
    scene.group_child_count_[g] = count;
  }

  // Chunk nodes, in the hierarchy's leaf order so that every leaf's chunks have consecutive ids.
  static void build_chunk_nodes(Scene& scene, const std::vector<Chunk>& chunks, const std::vector<std::size_t>& leaf_order) {
    for (std::size_t k = 0; k < chunks.size(); ++k) {
      const Chunk& ch = chunks[leaf_order[k]];
      const CurveInfo& ci = scene.curves_[ch.curve];
      const std::uint32_t first = ci.box_offset[ci.levels - 1] + ch.first_segment;
      const auto node = static_cast<std::uint32_t>(scene.segment_nodes_ + k);
      make_aligned_node(scene, node, first, ch.count, NodeInfo{ch.curve, ci.levels, ch.first_segment});
      scene.chunk_of_curve_[leaf_order[k]] = node;  // chunks were made curve by curve, in order
    }
  }

  // Hierarchy boxes bottom-up (children always have larger indices than their parent); the root is its own parent.
  static void build_hierarchy_nodes(Scene& scene, const std::vector<HierarchyNode>& hierarchy, const std::vector<Chunk>& chunks,
                                    const std::vector<std::size_t>& leaf_order, std::size_t hierarchy_base) {
    for (std::size_t i = hierarchy.size(); i-- > 0;) {
      const HierarchyNode& h = hierarchy[i];
      const std::uint32_t first = h.leaf ? static_cast<std::uint32_t>(scene.segment_nodes_ + h.begin) : static_cast<std::uint32_t>(hierarchy_base + h.first_child);
      const std::uint32_t count = h.leaf ? static_cast<std::uint32_t>(h.end - h.begin) : 2u;
      make_aligned_node(scene, static_cast<std::uint32_t>(hierarchy_base + i), first, count, NodeInfo{chunks[leaf_order[h.begin]].curve, Scene::kHierarchyLevel, 0});
    }
    scene.scene_root_ = static_cast<std::uint32_t>(hierarchy_base);
    scene.group_parent_[scene.scene_root_ - scene.segment_nodes_] = scene.scene_root_;
  }

};

Scene Scene::build(const std::vector<Polyline>& input, int max_levels) {
  Scene scene;
  max_levels = std::clamp(max_levels, 0, kMaxLevels - 1);
  const double t0 = now_ms();
  SceneBuild::OriginalArcs arcs;
  SceneBuild::plan_curves(scene, input, max_levels, arcs);
  SceneBuild::lay_out_curves(scene);
  SceneBuild::transform_curves(scene, input, arcs);
  const double t1 = now_ms();
  std::vector<SceneBuild::Chunk> chunks;
  std::vector<Vec2> chunk_centre;
  SceneBuild::make_chunks(scene, chunks, chunk_centre);
  std::vector<HierarchyNode> hierarchy;
  std::vector<std::size_t> leaf_order(chunks.size());
  for (std::size_t i = 0; i < leaf_order.size(); ++i) leaf_order[i] = i;
  build_hierarchy(leaf_order, chunk_centre, hierarchy);  // leaf_order becomes the hierarchy's leaf order
  scene.chunk_count_ = chunks.size();
  const std::size_t hierarchy_base = scene.segment_nodes_ + chunks.size();
  SceneBuild::allocate_groups(scene, chunks.size() + (chunks.empty() ? 0 : hierarchy.size()), chunks.size());
  SceneBuild::build_curves(scene, input, arcs);
  if (!chunks.empty()) {
    SceneBuild::build_chunk_nodes(scene, chunks, leaf_order);
    SceneBuild::build_hierarchy_nodes(scene, hierarchy, chunks, leaf_order, hierarchy_base);
  }
  scene.wide_ = WideIndex::build(scene);
  const double t2 = now_ms();
  scene.times_.multires_ms = t1 - t0;
  scene.times_.tree_ms = t2 - t1;
  return scene;
}

}  // namespace hk
