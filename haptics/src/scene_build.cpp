// Scene::build, phase by phase (seed paper §3; DESIGN.md "Collision tree"): the curves' levels, their boxes, the
// chunks and the hierarchy above them. A level-0 box holds its segment and the original input vertices it stands
// for; a level-l box holds its segment, every finer level's points under it and those original vertices, so a miss
// on a box proves a miss on everything under it, down to the original curve.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <string>

#include "haptics/scene.hpp"
#include "hk/error.hpp"
#include "scene_box_quantise.hpp"
#include "scene_hierarchy.hpp"
#include "scene_lanes.hpp"

namespace hk {
using namespace scene_detail;
namespace {

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

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
    if (nslots >= std::numeric_limits<std::uint32_t>::max() / 2 ||
        scene.curves_.size() >= (std::size_t{1} << (32 - Scene::kTagLevelBits))) {
      throw hk::ArgumentError("scene: " + std::to_string(scene.curves_.size()) + " curves and " +
                              std::to_string(nslots) +
                              " segment slots are over the 32-bit node ids' limit");  // far beyond any picture's budget
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
  static void map_originals(const CurveInfo& ci, const Polyline& src, const double* cum,
                            std::vector<std::uint32_t>& orig_first) {
    const std::size_t n = src.points_m.size();
    const std::size_t s0 = ci.segment_count[0], n0 = ci.point_count[0];
    const double step = resample_step_m(ci.length_m, n0, ci.closed);  // divided once per curve
    const double inverse_step = 1.0 / step;
    const auto start = [step](std::size_t k) { return step * static_cast<double>(k); };  // level0_arc_m for k < s0
    orig_first.assign(s0 + 1, 0);
    for (std::size_t j = 0; j < n; ++j) {
      const double x = cum[j];  // 0 ≤ x ≤ length_m
      auto key = std::min(static_cast<std::size_t>(x * inverse_step) + 1, s0);
      while (key > 1 && x < start(key - 1)) --key;  // cum[0] = 0 < step·k for every k ≥ 1, never for k = 0
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
  static std::size_t first_level0_after_originals(const std::vector<std::uint32_t>& orig_first, std::size_t k0,
                                                  std::size_t k1) {
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
    for (std::size_t k = 0; k < segments; ++k)
      most = std::max<std::size_t>(most, orig_first[(k + 1) << l] - orig_first[k << l]);
    const std::size_t all = orig_first[segments << l] - orig_first[0];
    return most * segments <= 2 * all + 4 * segments ? most : 0;
  }

  // Error boxes of every segment of curve c, as tight as containment allows: the box of level-l
  // segment k is the extent, in the segment's frame, of its own end points, of every point of every
  // finer level j < l under it (points k·2^(l−j) .. (k+1)·2^(l−j)), and of the original vertices under
  // it. Convexity then puts every finer segment and the original sub-polyline inside, which is all a
  // miss must prove (seed §3); children's boxes need not fit inside (boxes built from the
  // children's corners would be 1.09–1.45x the true deviation). The same pass measures the level's error
  // (grow_measuring) from the frame coordinates it computes anyway, then quantises the extents
  // (quantise_level).
  static void build_segment_boxes(Scene& scene, std::size_t c, const Polyline& src,
                                  const std::vector<std::uint32_t>& orig_first, std::vector<SegmentExtent>& level) {
    CurveInfo& ci = scene.curves_[c];
    const Vec2* orig = src.points_m.data();
    for (int l = 0; l < ci.levels; ++l) {
      level.resize(ci.segment_count[l]);
      level_frames(scene.points(c, l), ci.segment_count[l], level.data());  // the frames Scene::segment_box() rebuilds
      double worst_sq =
          0.0;  // largest squared distance of a level-0 point or original vertex from its level-l segment [m²]
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
      past_left_ =
          max(past_left_, max(d, zero - d));  // (|u_max − length|, n_max): n_max > 0, as the box holds its segment
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
    for (int t = 0; t < kToleranceSteps; ++t)
      cn.tolerance_level[t] = static_cast<std::uint8_t>(scene.coarsest_level_within(c, kToleranceLadder_m[t]));
  }

  // Level l's quantum (its widest extent / kQuantumSteps) and every segment's extents in it, rounded
  // outward; the widest box of the level and its largest box error bound (ReachGrower).
  static void quantise_level(Scene& scene, std::size_t c, int l, const std::vector<SegmentExtent>& level,
                             double widest) {
    CurveInfo& ci = scene.curves_[c];
    const float quantum = static_cast<float>(widest / kQuantumSteps);  // > 0: every extent holds the pad
    scene.curve_nodes_[c].quantum_m[l] = quantum;
    const double q = quantum, inverse_q = 1.0 / q;
    BoxExtent* out = scene.extent_.data() + ci.box_offset[l];
    ReachGrower reach;
    for (std::size_t k = 0; k < ci.segment_count[l]; ++k)
      out[k] = quantise_extent(level[k].e, level[k].length_m, q, inverse_q, reach);
    ci.max_box_half_width_m[l] = reach.half_width() * q;
    ci.max_error_bound_m[l] = std::sqrt(reach.bound_sq()) * q;
  }

  // Every curve's error boxes (build_segment_boxes) and the scene's bounds, those of the level-0 points.
  static void build_curves(Scene& scene, const std::vector<Polyline>& input, const OriginalArcs& arcs) {
    std::vector<std::uint32_t> orig_first;
    std::vector<SegmentExtent> level_extent;                // one level's measured extents, before quantising
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
  static void make_aligned_node(Scene& scene, std::uint32_t node, std::uint32_t first, std::uint32_t count,
                                NodeInfo info) {
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
  static void build_chunk_nodes(Scene& scene, const std::vector<Chunk>& chunks,
                                const std::vector<std::size_t>& leaf_order) {
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
  static void build_hierarchy_nodes(Scene& scene, const std::vector<HierarchyNode>& hierarchy,
                                    const std::vector<Chunk>& chunks, const std::vector<std::size_t>& leaf_order,
                                    std::size_t hierarchy_base) {
    for (std::size_t i = hierarchy.size(); i-- > 0;) {
      const HierarchyNode& h = hierarchy[i];
      const std::uint32_t first = h.leaf ? static_cast<std::uint32_t>(scene.segment_nodes_ + h.begin)
                                         : static_cast<std::uint32_t>(hierarchy_base + h.first_child);
      const std::uint32_t count = h.leaf ? static_cast<std::uint32_t>(h.end - h.begin) : 2u;
      make_aligned_node(scene, static_cast<std::uint32_t>(hierarchy_base + i), first, count,
                        NodeInfo{chunks[leaf_order[h.begin]].curve, Scene::kHierarchyLevel, 0});
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
