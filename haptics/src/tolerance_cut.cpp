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

// Cut membership below segment s for the steps in `active` (the steps for which no segment above s is cut).
// s is cut at the active steps whose tolerance its bound is within (every active step at level 0, which has
// nothing finer); its children carry on with the rest. The bound and its comparison are refine()'s.
void mark_cut(const Scene& sc, SegmentRef s, std::uint8_t active, std::uint8_t* masks) {
  const double bound = segment_bound(sc, s);
  std::uint8_t within = active;
  if (s.level > 0) {
    within = 0;
    for (int t = 0; t < kToleranceSteps; ++t) {
      if (bound <= kToleranceLadder_m[t]) within |= static_cast<std::uint8_t>(1u << t);
    }
    within &= active;
  }
  masks[sc.node_of(s)] = within;
  const auto rest = static_cast<std::uint8_t>(active & ~within);
  if (rest == 0) return;
  mark_cut(sc, SegmentRef{s.curve, s.level - 1, 2 * s.segment}, rest, masks);
  mark_cut(sc, SegmentRef{s.curve, s.level - 1, 2 * s.segment + 1}, rest, masks);
}

}  // namespace

std::vector<std::uint8_t> tolerance_cut_masks(const Scene& scene) {
  static_assert(kToleranceSteps <= 8, "a node's steps fit one byte");
  std::vector<std::uint8_t> masks(scene.node_count(), 0);
  constexpr auto kAllSteps = static_cast<std::uint8_t>((1u << kToleranceSteps) - 1);
  for (std::size_t c = 0; c < scene.curve_count(); ++c) {
    const CurveInfo& ci = scene.curve(c);
    const int top = static_cast<int>(ci.levels) - 1;
    for (std::uint32_t k = 0; k < ci.segment_count[top]; ++k) {
      mark_cut(scene, SegmentRef{static_cast<std::int32_t>(c), top, static_cast<std::int32_t>(k)}, kAllSteps,
               masks.data());
    }
  }
  return masks;
}

void joined_cut_segment(const Scene& scene, const std::uint8_t* masks, std::uint32_t node, int step, Vec2* a,
                        Vec2* b) noexcept {
  scene.segment_points(node, a, b);
  const std::uint32_t c = scene.tag_curve(node);
  const int l = scene.tag_level(node);
  const CurveInfo& ci = scene.curve(c);
  const CurveNodes& cn = scene.curve_nodes(c);
  const std::uint32_t i = node - cn.box_offset[l];
  // The cut segment before s covers the level-0 segment just before s's start; if it is finer than s, it is
  // the node of some level lev < l ending at s's start, level-lev point i·2^(l−lev). At most one is cut.
  if (i > 0 || ci.closed) {
    for (int lev = l - 1; lev >= 0; --lev) {
      const std::uint32_t start = i << (l - lev);
      const std::uint32_t before = (start == 0 ? ci.segment_count[lev] : start) - 1;
      if (in_cut(masks, cn.box_offset[lev] + before, step)) {
        *a = scene.points(c, lev)[start];
        break;
      }
    }
  }
  // Likewise after s's end, level-lev point (i + 1)·2^(l−lev) (a closed curve's last point repeats its first).
  if (i + 1 < ci.segment_count[l] || ci.closed) {
    for (int lev = l - 1; lev >= 0; --lev) {
      const std::uint32_t end = (i + 1) << (l - lev);
      const std::uint32_t after = end == ci.segment_count[lev] ? 0 : end;
      if (in_cut(masks, cn.box_offset[lev] + after, step)) {
        *b = scene.points(c, lev)[end];
        break;
      }
    }
  }
}

CutBounds cut_bounds(const Scene& scene, const std::uint8_t* masks) {
  CutBounds cb;
  double shift_m[kToleranceSteps] = {};
  for (std::uint32_t node = 0; node < scene.node_count(); ++node) {
    if (masks[node] == 0) continue;  // group nodes and segments in no cut
    const ErrorBox box = scene.box(node);
    Vec2 a, b;
    scene.segment_points(node, &a, &b);
    const double bound = box_error_bound(box, distance(a, b));  // segment_bound's, without rebuilding the box
    for (int t = 0; t < kToleranceSteps; ++t) {
      if (!in_cut(masks, node, t)) continue;
      Vec2 ja, jb;
      joined_cut_segment(scene, masks, node, t, &ja, &jb);
      cb.error_bound_m[t] = std::max(cb.error_bound_m[t], bound);
      cb.half_width_m[t] = std::max(cb.half_width_m[t], box_half_width(box));
      shift_m[t] = std::max({shift_m[t], distance(a, ja), distance(b, jb)});
    }
  }
  for (int t = 0; t < kToleranceSteps; ++t) cb.error_bound_m[t] += shift_m[t];
  return cb;
}

std::shared_ptr<const CutWalls> make_cut_walls(const Scene& scene) {
  auto walls = std::make_shared<CutWalls>();
  walls->scene = &scene;
  walls->masks = tolerance_cut_masks(scene);
  walls->bounds = cut_bounds(scene, walls->masks.data());
  return walls;
}

CutStats tolerance_cut(const Scene& scene, std::size_t curve, double tol_m, std::vector<SegmentRef>* out) {
  CutStats st;
  const CurveInfo& ci = scene.curve(curve);
  const int top = ci.levels - 1;
  const std::size_t first = out->size();
  for (std::uint32_t k = 0; k < ci.segment_count[top]; ++k)
    refine(scene, SegmentRef{static_cast<std::int32_t>(curve), top, static_cast<std::int32_t>(k)}, tol_m, out, &st);
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
