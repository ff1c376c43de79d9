// Tolerance cut through a curve's collision tree (see tolerance_cut.hpp; seed paper §3).
#include "haptics/tolerance_cut.hpp"

#include <algorithm>

namespace hk {
namespace {

double segment_bound(const Scene& sc, SegmentRef s) {
  Vec2 a, b;
  sc.segment(s, &a, &b);
  return box_error_bound(sc.box(sc.node_of(s)), distance(a, b));
}

// Depth-first, first child first, so the cut comes out in curve order.
void refine(const Scene& sc, SegmentRef s, double tol_m, std::vector<SegmentRef>* out, CutStats* st) {
  const double bound = segment_bound(sc, s);
  if (s.level == 0 || bound <= tol_m) {
    out->push_back(s);
    ++st->segments;
    st->max_bound_m = std::max(st->max_bound_m, bound);
    return;
  }
  refine(sc, SegmentRef{s.curve, s.level - 1, 2 * s.segment}, tol_m, out, st);
  refine(sc, SegmentRef{s.curve, s.level - 1, 2 * s.segment + 1}, tol_m, out, st);
}

// The vertex where segment `before` meets the next segment `after` of the cut: the end point of the finer
// (before's end when they are at one level, where both share it).
Vec2 junction(const Scene& sc, SegmentRef before, SegmentRef after) {
  Vec2 a, b;
  if (before.level <= after.level) {
    sc.segment(before, &a, &b);
    return b;
  }
  sc.segment(after, &a, &b);
  return a;
}

}  // namespace

CutStats tolerance_cut(const Scene& scene, std::size_t curve, double tol_m, std::vector<SegmentRef>* out) {
  CutStats st;
  const CurveInfo& ci = scene.curve(curve);
  const int top = ci.levels - 1;
  const std::size_t first = out->size();
  for (std::uint32_t k = 0; k < ci.segment_count[top]; ++k) refine(scene, SegmentRef{static_cast<std::int32_t>(curve), top, static_cast<std::int32_t>(k)}, tol_m, out, &st);
  // Junctions: consecutive segments (and, closed, the last and the first); a break where their ends differ,
  // joined at the finer one's end, which moves the coarser one's end by the distance between the two.
  const std::size_t n = out->size() - first;
  const std::size_t joins = ci.closed ? n : n - 1;
  for (std::size_t i = 0; i < joins; ++i) {
    Vec2 a0, b0, a1, b1;
    scene.segment((*out)[first + i], &a0, &b0);
    scene.segment((*out)[first + (i + 1) % n], &a1, &b1);
    if (b0 == a1) continue;
    ++st.breaks;
    st.max_join_shift_m = std::max(st.max_join_shift_m, distance(b0, a1));
  }
  st.vertices = st.segments + (ci.closed ? 0 : 1);
  return st;
}

std::vector<Vec2> joined_cut_points(const Scene& scene, std::size_t curve, const SegmentRef* cut, std::size_t count) {
  std::vector<Vec2> points;
  if (count == 0) return points;
  const bool closed = scene.curve(curve).closed;
  points.reserve(count + 1);
  if (closed) {
    points.push_back(junction(scene, cut[count - 1], cut[0]));
  } else {
    Vec2 a, b;
    scene.segment(cut[0], &a, &b);
    points.push_back(a);
  }
  for (std::size_t i = 0; i + 1 < count; ++i) points.push_back(junction(scene, cut[i], cut[i + 1]));
  if (!closed) {
    Vec2 a, b;
    scene.segment(cut[count - 1], &a, &b);
    points.push_back(b);
  }
  return points;
}

}  // namespace hk
