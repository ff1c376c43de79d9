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

}  // namespace

CutStats tolerance_cut(const Scene& scene, std::size_t curve, double tol_m, std::vector<SegmentRef>* out) {
  CutStats st;
  const CurveInfo& ci = scene.curve(curve);
  const int top = ci.levels - 1;
  const std::size_t first = out->size();
  for (std::uint32_t k = 0; k < ci.segment_count[top]; ++k) refine(scene, SegmentRef{static_cast<std::int32_t>(curve), top, static_cast<std::int32_t>(k)}, tol_m, out, &st);
  // Breaks: consecutive segments (and, closed, the last and the first) whose ends differ.
  const std::size_t n = out->size() - first;
  const std::size_t joins = ci.closed ? n : n - 1;
  for (std::size_t i = 0; i < joins; ++i) {
    Vec2 a0, b0, a1, b1;
    scene.segment((*out)[first + i], &a0, &b0);
    scene.segment((*out)[first + (i + 1) % n], &a1, &b1);
    if (!(b0 == a1)) ++st.breaks;
  }
  st.vertices = st.segments + st.breaks + (ci.closed ? 0 : 1);
  return st;
}

}  // namespace hk
