// Scene index and collision tree construction (seed paper §3; DESIGN.md "Collision tree").
// Boxes are built bottom-up: a level-0 box holds its segment and the original input vertices it
// stands for; a level-l box holds its segment and the corners of its two children's boxes, so a miss
// on a box proves a miss on everything under it, down to the original curve.
#include "haptics/scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace hk {
namespace {

// Boxes grow by this much on every side so that corners computed in another frame, which carry
// rounding of a few ulps, still test inside their parents.
constexpr double kBoxPad_m = 1e-9;

struct Extent {
  double u_min = std::numeric_limits<double>::infinity();
  double u_max = -std::numeric_limits<double>::infinity();
  double n_min = std::numeric_limits<double>::infinity();
  double n_max = -std::numeric_limits<double>::infinity();
};

inline void grow(Extent& e, Vec2 origin, Vec2 axis, Vec2 q) {
  const Vec2 r = q - origin;
  const double u = dot(r, axis);
  const double n = cross(axis, r);
  e.u_min = std::min(e.u_min, u);
  e.u_max = std::max(e.u_max, u);
  e.n_min = std::min(e.n_min, n);
  e.n_max = std::max(e.n_max, n);
}

inline ErrorBox make_box(Vec2 origin, Vec2 axis, const Extent& e) {
  return ErrorBox{origin, axis, e.u_min - kBoxPad_m, e.u_max + kBoxPad_m, e.n_min - kBoxPad_m, e.n_max + kBoxPad_m};
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

double box_half_width(const ErrorBox& box) { return std::max(std::abs(box.n_min), std::abs(box.n_max)); }

std::size_t Scene::hot_bytes() const {
  return boxes_.size() * sizeof(ErrorBox) + aabbs_.size() * sizeof(Aabb) + info_.size() * sizeof(NodeInfo) +
         (parent_.size() + child_first_.size() + child_count_.size()) * sizeof(std::uint32_t) + points_m_.size() * sizeof(Vec2);
}

void Scene::segment(SegmentRef s, Vec2* a, Vec2* b) const {
  const CurveInfo& c = curves_[static_cast<std::size_t>(s.curve)];
  const Vec2* p = points_m_.data() + c.point_offset[s.level];
  const std::uint32_t n = c.point_count[s.level];
  const std::uint32_t k = static_cast<std::uint32_t>(s.segment);
  *a = p[k];
  *b = p[k + 1 == n ? 0 : k + 1];
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

int Scene::max_curve_levels() const {
  int levels = 1;
  for (const CurveInfo& ci : curves_) levels = std::max(levels, ci.levels);
  return levels;
}

Scene Scene::build(const std::vector<Polyline>& input, int max_levels) {
  Scene scene;
  max_levels = std::clamp(max_levels, 0, kMaxLevels - 1);
  const double t0 = now_ms();

  // Multiresolution models first (they fix every array size).
  for (std::size_t i = 0; i < input.size(); ++i) {
    try {
      scene.models_.push_back(build_multires(input[i], max_levels));
      scene.source_index_.push_back(i);
    } catch (const CurveError&) {
      ++scene.skipped_;  // fewer than 2 points or zero length: nothing to feel
    }
  }
  const double t1 = now_ms();

  // Lay out points and segment nodes, level by level within each curve.
  std::size_t npoints = 0, nnodes = 0;
  scene.curves_.resize(scene.models_.size());
  for (std::size_t c = 0; c < scene.models_.size(); ++c) {
    const CurveMultires& m = scene.models_[c];
    CurveInfo& ci = scene.curves_[c];
    ci.closed = m.closed;
    ci.levels = m.levels;
    for (int l = 0; l < m.levels; ++l) {
      ci.point_offset[l] = static_cast<std::uint32_t>(npoints);
      ci.point_count[l] = static_cast<std::uint32_t>(m.scaling[l].size());
      ci.box_offset[l] = static_cast<std::uint32_t>(nnodes);
      ci.segment_count[l] = static_cast<std::uint32_t>(m.segment_count(l));
      npoints += m.scaling[l].size();
      nnodes += m.segment_count(l);
    }
  }
  scene.segment_nodes_ = nnodes;
  scene.points_m_.resize(npoints);

  // Chunks: runs of at most kSegmentsPerChunk consecutive coarsest segments of one curve. They are the
  // leaves of the scene hierarchy, so no node has more than a handful of children (a long curve would
  // otherwise fan out to hundreds of coarsest segments, and the boundary section with it).
  struct Chunk {
    std::uint32_t curve, first_segment, count;
  };
  std::vector<Chunk> chunks;
  std::vector<Vec2> chunk_centre;
  for (std::size_t c = 0; c < scene.models_.size(); ++c) {
    const int top = scene.models_[c].levels - 1;
    const auto& pts = scene.models_[c].scaling[static_cast<std::size_t>(top)];
    const std::uint32_t k_top = scene.curves_[c].segment_count[top];
    for (std::uint32_t k = 0; k < k_top; k += kSegmentsPerChunk) {
      const std::uint32_t n = std::min<std::uint32_t>(kSegmentsPerChunk, k_top - k);
      Vec2 lo = pts[k], hi = pts[k];
      for (std::uint32_t i = k; i <= k + n; ++i) {
        const Vec2 q = pts[i % pts.size()];
        lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
        hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
      }
      chunks.push_back({static_cast<std::uint32_t>(c), k, n});
      chunk_centre.push_back(0.5 * (lo + hi));
    }
  }
  std::vector<HierarchyNode> hierarchy;
  std::vector<std::size_t> chunk_order(chunks.size());
  for (std::size_t i = 0; i < chunk_order.size(); ++i) chunk_order[i] = i;
  build_hierarchy(chunk_order, chunk_centre, hierarchy);  // chunk_order becomes leaf order
  scene.chunk_count_ = chunks.size();
  const std::size_t hierarchy_base = nnodes + chunks.size();
  const std::size_t total_nodes = hierarchy_base + (chunks.empty() ? 0 : hierarchy.size());
  scene.boxes_.resize(total_nodes);
  scene.info_.resize(total_nodes);
  scene.parent_.assign(total_nodes, 0);
  scene.child_first_.assign(total_nodes, 0);
  scene.child_count_.assign(total_nodes, 0);

  Vec2 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Vec2 hi{-lo.x, -lo.y};
  std::vector<double> orig_arc;
  std::vector<std::uint32_t> orig_first;  // per level-0 segment: first original vertex strictly inside it
  for (std::size_t c = 0; c < scene.models_.size(); ++c) {
    const CurveMultires& m = scene.models_[c];
    const CurveInfo& ci = scene.curves_[c];
    const Polyline& src = input[scene.source_index_[c]];
    for (int l = 0; l < m.levels; ++l) {
      std::copy(m.scaling[l].begin(), m.scaling[l].end(), scene.points_m_.begin() + ci.point_offset[l]);
    }

    // Arc length of every original vertex, to know which level-0 segment each one belongs to.
    const auto& p = src.points_m;
    orig_arc.assign(p.size() + 1, 0.0);
    for (std::size_t i = 1; i < p.size(); ++i) orig_arc[i] = orig_arc[i - 1] + distance(p[i - 1], p[i]);
    const double total = src.closed ? orig_arc[p.size() - 1] + distance(p.back(), p.front()) : orig_arc[p.size() - 1];
    const std::size_t n0 = m.scaling[0].size();
    const std::size_t s0 = ci.segment_count[0];
    // Original vertex range [orig_first[k], orig_first[k+1]) lies within level-0 segment k.
    orig_first.assign(s0 + 1, 0);
    {
      std::size_t j = 0;
      for (std::size_t k = 0; k <= s0; ++k) {
        const double start = k < n0 ? m.arc_m[k] : total;
        while (j < p.size() && orig_arc[j] < start) ++j;
        orig_first[k] = static_cast<std::uint32_t>(j);
      }
      orig_first[s0] = static_cast<std::uint32_t>(p.size());
    }
    auto level0_end = [&](std::size_t k) { return m.scaling[0][k + 1 == n0 ? 0 : k + 1]; };

    // Level 0: segment + original vertices it stands for.
    for (std::size_t k = 0; k < s0; ++k) {
      const Vec2 a = m.scaling[0][k], b = level0_end(k);
      const Vec2 axis = normalized_or(b - a, Vec2{1.0, 0.0});
      Extent e;
      grow(e, a, axis, a);
      grow(e, a, axis, b);
      for (std::uint32_t j = orig_first[k]; j < orig_first[k + 1]; ++j) grow(e, a, axis, p[j]);
      const std::uint32_t node = ci.box_offset[0] + static_cast<std::uint32_t>(k);
      scene.boxes_[node] = make_box(a, axis, e);
      scene.info_[node] = NodeInfo{static_cast<std::uint32_t>(c), 0, static_cast<std::uint32_t>(k)};
      scene.parent_[node] = m.levels > 1 ? ci.box_offset[1] + static_cast<std::uint32_t>(k / 2) : 0;  // coarsest: set with its chunk
    }
    // Coarser levels: segment + children's box corners.
    for (int l = 1; l < m.levels; ++l) {
      const auto& pts = m.scaling[l];
      for (std::size_t k = 0; k < ci.segment_count[l]; ++k) {
        const Vec2 a = pts[k], b = pts[k + 1 == pts.size() ? 0 : k + 1];
        const Vec2 axis = normalized_or(b - a, Vec2{1.0, 0.0});
        Extent e;
        grow(e, a, axis, a);
        grow(e, a, axis, b);
        for (std::uint32_t ch = 0; ch < 2; ++ch) {
          Vec2 corners[4];
          box_corners(scene.boxes_[ci.box_offset[l - 1] + 2 * k + ch], corners);
          for (const Vec2& q : corners) grow(e, a, axis, q);
        }
        const std::uint32_t node = ci.box_offset[l] + static_cast<std::uint32_t>(k);
        scene.boxes_[node] = make_box(a, axis, e);
        scene.info_[node] = NodeInfo{static_cast<std::uint32_t>(c), l, static_cast<std::uint32_t>(k)};
        scene.parent_[node] = l + 1 < m.levels ? ci.box_offset[l + 1] + static_cast<std::uint32_t>(k / 2) : 0;  // coarsest: set with its chunk
        scene.child_first_[node] = ci.box_offset[l - 1] + 2 * static_cast<std::uint32_t>(k);
        scene.child_count_[node] = 2;
      }
    }
    // Error of each level: distance of every original vertex and level-0 point to the segment that stands for it.
    CurveInfo& cw = scene.curves_[c];
    for (int l = 0; l < m.levels; ++l) {
      const auto& pts = m.scaling[l];
      double worst = 0.0, widest = 0.0;
      for (std::size_t k = 0; k < s0; ++k) {
        const std::size_t seg = k >> l;
        const Vec2 a = pts[seg], b = pts[seg + 1 == pts.size() ? 0 : seg + 1];
        worst = std::max(worst, distance_sq_to_segment(m.scaling[0][k], a, b));
        for (std::uint32_t j = orig_first[k]; j < orig_first[k + 1]; ++j) worst = std::max(worst, distance_sq_to_segment(p[j], a, b));
      }
      worst = std::sqrt(worst);  // squared above: one root per level
      for (std::size_t k = 0; k < cw.segment_count[l]; ++k) widest = std::max(widest, box_half_width(scene.boxes_[cw.box_offset[l] + k]));
      cw.max_error_m[l] = worst;
      cw.max_box_half_width_m[l] = widest;
    }
    for (const Vec2& q : m.scaling[0]) {
      lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
      hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
    }
  }
  if (!scene.curves_.empty()) {
    scene.bounds_min_ = lo;
    scene.bounds_max_ = hi;
    // Chunk nodes, in the hierarchy's leaf order so that every leaf's chunks have consecutive ids.
    for (std::size_t k = 0; k < chunks.size(); ++k) {
      const Chunk& ch = chunks[chunk_order[k]];
      const CurveInfo& ci = scene.curves_[ch.curve];
      const int top = ci.levels - 1;
      const std::uint32_t node = static_cast<std::uint32_t>(scene.segment_nodes_ + k);
      const std::uint32_t first = ci.box_offset[top] + ch.first_segment;
      Extent e;
      for (std::uint32_t i = 0; i < ch.count; ++i) {
        Vec2 corners[4];
        box_corners(scene.boxes_[first + i], corners);
        for (const Vec2& q : corners) grow(e, Vec2{0, 0}, Vec2{1, 0}, q);
        scene.parent_[first + i] = node;
      }
      scene.boxes_[node] = make_box(Vec2{0, 0}, Vec2{1, 0}, e);
      scene.info_[node] = NodeInfo{ch.curve, ci.levels, ch.first_segment};
      scene.child_first_[node] = first;
      scene.child_count_[node] = ch.count;
    }
    // Hierarchy boxes bottom-up (children always have larger indices than their parent).
    for (std::size_t i = hierarchy.size(); i-- > 0;) {
      const HierarchyNode& h = hierarchy[i];
      const std::uint32_t node = static_cast<std::uint32_t>(hierarchy_base + i);
      const std::uint32_t first = h.leaf ? static_cast<std::uint32_t>(scene.segment_nodes_ + h.begin) : static_cast<std::uint32_t>(hierarchy_base + h.first_child);
      const std::uint32_t count = h.leaf ? static_cast<std::uint32_t>(h.end - h.begin) : 2u;
      Extent e;
      for (std::uint32_t k = 0; k < count; ++k) {
        Vec2 corners[4];
        box_corners(scene.boxes_[first + k], corners);
        for (const Vec2& q : corners) grow(e, Vec2{0, 0}, Vec2{1, 0}, q);
        scene.parent_[first + k] = node;
      }
      scene.boxes_[node] = make_box(Vec2{0, 0}, Vec2{1, 0}, e);
      scene.info_[node] = NodeInfo{chunks[chunk_order[h.begin]].curve, kHierarchyLevel, 0};
      scene.child_first_[node] = first;
      scene.child_count_[node] = count;
    }
    scene.scene_root_ = static_cast<std::uint32_t>(hierarchy_base);
    scene.parent_[scene.scene_root_] = scene.scene_root_;
  }
  // Rectangles around every box, for the cheap reject in the queries.
  scene.aabbs_.resize(scene.boxes_.size());
  for (std::size_t i = 0; i < scene.boxes_.size(); ++i) {
    Vec2 corners[4];
    box_corners(scene.boxes_[i], corners);
    Aabb r{corners[0], corners[0]};
    for (const Vec2& q : corners) {
      r.lo = {std::min(r.lo.x, q.x), std::min(r.lo.y, q.y)};
      r.hi = {std::max(r.hi.x, q.x), std::max(r.hi.y, q.y)};
    }
    scene.aabbs_[i] = r;
  }
  const double t2 = now_ms();
  scene.times_.multires_ms = t1 - t0;
  scene.times_.tree_ms = t2 - t1;
  return scene;
}

}  // namespace hk
