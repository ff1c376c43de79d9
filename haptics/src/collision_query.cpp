// Anytime swept-point query over the collision trees (seed paper §3).
#include "haptics/collision_query.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#include <xmmintrin.h>
#endif

namespace hk {
namespace {

// Writes the section scan's masks four bits at a time: the bits of entries i .. i + 3 (i a multiple of 4, in
// increasing order) go to bits i % 64 .. i % 64 + 3 of words[i / 64]; finish(end) stores the last, partial word.
struct QuadBitWriter {
  std::uint64_t* words;
  std::uint64_t word = 0;
  void put(std::size_t i, unsigned four_bits) noexcept {
    word |= static_cast<std::uint64_t>(four_bits) << (i % 64);
    if (i % 64 == 60) {
      words[i / 64] = word;
      word = 0;
    }
  }
  void finish(std::size_t end) noexcept {
    if (end % 64 != 0) words[end / 64] = word;
  }
};

// Squared distance from p to an axis-aligned rectangle (0 inside) [m²]: a lower bound on the distance to the
// box it holds.
inline double rect_distance_sq(const Aabb& r, Vec2 p) {
  const double dx = std::max({r.lo.x - p.x, 0.0, p.x - r.hi.x});
  const double dy = std::max({r.lo.y - p.y, 0.0, p.y - r.hi.y});
  return dx * dx + dy * dy;
}

// Squared distance from p to a box (0 inside) [m²].
inline double box_distance_sq(const ErrorBox& box, Vec2 p) {
  const Vec2 r = p - box.origin_m;
  const double u = dot(r, box.axis);
  const double n = cross(box.axis, r);
  const double du = std::max({box.u_min - u, 0.0, u - box.u_max});
  const double dn = std::max({box.n_min - n, 0.0, n - box.n_max});
  return du * du + dn * dn;
}

// True for a segment node at the level a walk targets, resolved per curve (Scene::clamp_level). A walk
// reaches a curve's segments from its coarsest level down, so a segment's level is never above that
// clamp, which for a level then comes down to comparing with the target itself (or 0, for a negative
// target); a tolerance step needs the curve's own level for it.
inline bool at_target_level(const Scene& sc, std::uint32_t node, int level) {
  if (!sc.is_segment(node)) return false;
  if (level >= kToleranceLevelBase) return sc.tag_level(node) <= sc.clamp_level(sc.tag_curve(node), level);
  return sc.tag_level(node) <= std::max(level, 0);
}

// "d at s is a better answer than best_d at best_s": smaller (a distance, or a first hit's sweep parameter), or
// as small and the smaller (curve, level, segment), so ties do not depend on the order segments are met in.
inline bool closer(double d, SegmentRef s, double best_d, SegmentRef best_s) {
  if (d != best_d) return d < best_d;
  if (s.curve != best_s.curve) return s.curve < best_s.curve;
  if (s.level != best_s.level) return s.level < best_s.level;
  return s.segment < best_s.segment;
}

// True when s is one of the count segments at excluded (the walls a query leaves out: edge contact's).
inline bool is_excluded(SegmentRef s, const SegmentRef* excluded, int count) {
  for (int i = 0; i < count; ++i) {
    if (excluded[i] == s) return true;
  }
  return false;
}

}  // namespace

namespace {

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
    return static_cast<std::size_t>(_mm_cvtss_f32(min4(_mm_or_ps(_mm_and_ps(at_min, entry_), _mm_andnot_ps(at_min, none)))));
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

}  // namespace

// at_target_level, and for a cut step the cut's own segments. A walk comes down from the roots and stops at
// the first cut segment on its way, so it never reaches a node below the cut.
bool BoundarySection::at_target(std::uint32_t node, int level) const noexcept {
  if (is_cut_level(level)) return scene_->is_segment(node) && in_cut(cut_mask_, node, level - kCutLevelBase);
  return at_target_level(*scene_, node, level);
}

// The end points of wall node `node` (at_target of `level`, already walls_of): joined at a cut step, else the
// segment's own.
void BoundarySection::wall_node_points(std::uint32_t node, int level, Vec2* a, Vec2* b) const noexcept {
  if (is_cut_level(level)) {
    joined_cut_segment(*scene_, cut_mask_, node, level - kCutLevelBase, a, b);
  } else {
    scene_->segment_points(node, a, b);
  }
}

bool BoundarySection::wall_neighbour(SegmentRef s, int level, int dir, SegmentRef* out) const noexcept {
  level = walls_of(level);
  const Scene& sc = *scene_;
  const CurveInfo& ci = sc.curve(static_cast<std::size_t>(s.curve));
  const auto n = static_cast<std::int32_t>(ci.segment_count[s.level]);
  std::int32_t k = s.segment + (dir > 0 ? 1 : -1);
  if (k < 0 || k >= n) {
    if (!ci.closed) return false;
    k = (k + n) % n;
  }
  if (k == s.segment) return false;
  if (!is_cut_level(level)) {
    *out = SegmentRef{s.curve, s.level, k};
    return true;
  }
  // The cut segment covering level-0 segment j, the first past s's end (or the last before its start):
  // exactly one of its ancestors-or-self is in the cut. Same-level segment k's level-0 range holds j.
  const int step = level - kCutLevelBase;
  const auto n0 = static_cast<std::int64_t>(ci.segment_count[0]);
  const std::int64_t j = dir > 0 ? (static_cast<std::int64_t>(k) << s.level) : ((static_cast<std::int64_t>(k) + 1) << s.level) - 1;
  const CurveNodes& cn = sc.curve_nodes(static_cast<std::size_t>(s.curve));
  for (int l = static_cast<int>(ci.levels) - 1; l >= 0; --l) {
    const auto i = static_cast<std::uint32_t>((j % n0) >> l);
    if (in_cut(cut_mask_, cn.box_offset[l] + i, step)) {
      *out = SegmentRef{s.curve, l, static_cast<std::int32_t>(i)};
      return !(out->level == s.level && out->segment == s.segment);
    }
  }
  return false;  // not reached: every level-0 segment is under exactly one cut segment
}

bool clip_segment_box(const ErrorBox& box, Vec2 a, Vec2 b, double margin_m, double* t_enter, double* t_exit) {
  // Work in the box frame: u along the axis, n along the left normal.
  const Vec2 ra = a - box.origin_m;
  const Vec2 d = b - a;
  const double p0[2] = {dot(ra, box.axis), cross(box.axis, ra)};
  const double dp[2] = {dot(d, box.axis), cross(box.axis, d)};
  const double lo[2] = {box.u_min - margin_m, box.n_min - margin_m};
  const double hi[2] = {box.u_max + margin_m, box.n_max + margin_m};
  // Both slabs always, without a branch on the data (a clip's outcome is a coin toss to the predictor): t0 only
  // grows and t1 only shrinks, so an empty interval after the first slab stays empty.
  double t0 = 0.0, t1 = 1.0;
  bool inside_parallel = true;
  for (int i = 0; i < 2; ++i) {
    if (dp[i] == 0.0) {  // parallel to this slab: inside it or not at all (seldom: a predictable branch)
      inside_parallel = inside_parallel && p0[i] >= lo[i] && p0[i] <= hi[i];
      continue;
    }
    const double inv = 1.0 / dp[i];
    const double ta = (lo[i] - p0[i]) * inv;
    const double tb = (hi[i] - p0[i]) * inv;
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (!inside_parallel || t0 > t1) return false;
  *t_enter = t0;
  *t_exit = t1;
  return true;
}

bool intersect_sweep_segment(Vec2 a, Vec2 b, Vec2 p, Vec2 q, double* t) {
  const Vec2 r = b - a;
  const Vec2 s = q - p;
  const double denom = cross(r, s);
  if (denom == 0.0) return false;  // parallel or collinear: sliding along a wall is not crossing it
  const Vec2 ap = p - a;
  const double tt = cross(ap, s) / denom;
  const double uu = cross(ap, r) / denom;
  if (tt < 0.0 || tt > 1.0 || uu < 0.0 || uu > 1.0) return false;
  *t = tt;
  return true;
}

BoundarySection::BoundarySection(const Scene& scene, double merge_margin_m, bool cut_walls)
    : BoundarySection(scene, merge_margin_m, cut_walls ? make_cut_walls(scene) : nullptr) {}

BoundarySection::BoundarySection(const Scene& scene, double merge_margin_m, std::shared_ptr<const CutWalls> cuts)
    : scene_(&scene), merge_margin_m_(merge_margin_m), cuts_(std::move(cuts)) {
  if (cuts_ && cuts_->scene != &scene) throw std::invalid_argument("BoundarySection: the cut walls were made for another scene");
  cut_mask_ = cuts_ ? cuts_->masks.data() : nullptr;
  const std::size_t n = scene.node_count();
  std::size_t widest_root = 0;  // widest fan-out of any node (chunks and hierarchy leaves: 4)
  for (std::uint32_t node = 0; node < n; ++node) {
    std::uint32_t first = 0, count = 0;
    scene.children(node, &first, &count);
    widest_root = std::max<std::size_t>(widest_root, count);
  }
  // A node's state counts its children in the frontier in three bits (node_state_); the scene has at most 4 a node.
  if (widest_root > kChildrenInMask / kChildInUnit) {
    throw std::invalid_argument("BoundarySection: a scene node has " + std::to_string(widest_root) +
                                " children; the section counts at most " + std::to_string(kChildrenInMask / kChildInUnit));
  }
  // Room for every node twice: a level change's coarsening appends ancestors before its compaction drops the
  // entries they replace (splits and merges change the section in place).
  // The section is bounded (kMaxSectionEntries), and with it its storage (about 52 bytes an entry) and its scan,
  // the one work a full query does past its budget (about 20 instructions an entry): when it is full, boxes are
  // simply not split (the query still descends, and answers the same), and a level change starts again from the
  // roots.
  const WideIndex& wi = scene.wide_index();
  wide_base_ = static_cast<std::uint32_t>(n);
  const std::size_t ids = n + wi.nodes.size();  // scene nodes, then wide nodes (the wide frontier's ids)
  if (ids >= kNoParent) throw std::invalid_argument("BoundarySection: the scene's nodes and wide nodes exceed 32-bit section ids");
  capacity_ = std::min<std::size_t>(2 * ids, kMaxSectionEntries) + widest_root + 8;
  section_.reserve(capacity_);
  section_parent_.assign(capacity_, kNoParent);
  section_rect_.size_for(capacity_ + kScanLanes);
  rect_d_sq_.assign(capacity_ + kScanLanes, 0.0f);
  rect_overlap_bits_.assign((capacity_ + kScanLanes) / 64 + 1, 0);
  rect_near_bits_.assign((capacity_ + kScanLanes) / 64 + 1, 0);
  if (scene.curve_count() > 0) {  // every section rectangle lies within the root's
    const Aabb root = scene.aabb(scene.scene_root());
    scale_m_ = std::max({std::abs(root.lo.x), std::abs(root.lo.y), std::abs(root.hi.x), std::abs(root.hi.y)});
  }
  if (!wi.nodes.empty()) {  // and the wide root's (its rectangles are padded)
    Vec2 lo, hi;
    wi.node_rect(0, &lo, &hi);
    scale_m_ = std::max({scale_m_, std::abs(lo.x), std::abs(lo.y), std::abs(hi.x), std::abs(hi.y)});
  }
  node_state_.assign(ids, 0);
  candidates_.reserve(capacity_);
  // Widest fan-out, plus that many per level of curve and hierarchy (hk/constants.hpp).
  // and for the wide frontier three per wide level and one per curve level below the items.
  stack_.resize(std::max(tree_stack_entries(widest_root), wi.stack_entries() + static_cast<std::size_t>(kMaxLevels)));
  marked_.assign(2 * capacity_, 0);
  walk_.resize(wi.stack_entries());
  link_wide_nodes();
  // The level ids whose walls the wide index holds: those at which every curve is at or below its item level.
  for (int id = 0; id < kCutLevelBase; ++id) {
    bool served = true;
    for (std::size_t c = 0; c < scene.curve_count() && served; ++c) served = scene.clamp_level(c, id) <= wide_item_level(scene.curve(c).levels);
    wide_serves_[static_cast<std::size_t>(id)] = served;
  }
  reset();
}

std::size_t BoundarySection::bytes() const noexcept {
  const auto of = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return of(section_) + of(section_parent_) + of(section_rect_.lo_x) + of(section_rect_.lo_y) + of(section_rect_.hi_x) +
         of(section_rect_.hi_y) + of(rect_d_sq_) + of(rect_overlap_bits_) + of(rect_near_bits_) + of(node_state_) +
         of(marked_) + of(candidates_) + of(stack_) + of(walk_.t_enter) + of(walk_.d_sq) +
         of(walk_.code) + of(wide_up_) + of(item_up_) + of(item_first_);
}

void BoundarySection::reset() {
  last_closest_node_ = kWideEmpty;  // a reset section answers like a new one, box test for box test
  for (std::size_t i = 0; i < section_.size(); ++i) {
    clear_state(section_[i], kInSection);
    // Only a section node's parent counts any children in.
    if (section_parent_[i] != kNoParent) clear_state(section_parent_[i], kChildrenInMask);
  }
  section_.clear();
  ball_radius_sq_ = 0.0;
  ball_walls_.radius_sq = 0.0;
  ball_walls_.count = 0;
  ball_walls_.runs = 0;
  ball_walls_.copied = false;
  wide_ball_radius_m_ = 0.0;
  wide_ball_seed_ = kWideEmpty;
  if (scene_->curve_count() == 0) return;
  push_section(wide_mode_ ? wide_base_ : scene_->scene_root(), kNoParent);
}

void BoundarySection::push_section(std::uint32_t node, std::uint32_t parent) {
  section_.push_back(node);  // within the reserved capacity: no allocation
  set_section_entry(section_.size() - 1, node, parent);
}

// Puts node in the section at `entry` in place of the entry's node, with its rectangle, and marks it in and
// counted among its parent's children in (`parent`: Scene::parent(node), or kNoParent for the root). The caller
// marks the node it replaces out (mark_out).
void BoundarySection::set_section_entry(std::size_t entry, std::uint32_t node, std::uint32_t parent) {
  section_rect_.set(entry, entry_rect(node));
  place_entry(entry, node, parent);
}

// set_section_entry but for the rectangle, which the caller stores.
void BoundarySection::place_entry(std::size_t entry, std::uint32_t node, std::uint32_t parent) noexcept {
  section_[entry] = node;
  section_parent_[entry] = parent;
  node_state_[node] |= kInSection;
  // The count stays within its bits: at most the widest fan-out, checked at construction.
  if (parent != kNoParent) node_state_[parent] = static_cast<std::uint8_t>(node_state_[parent] + kChildInUnit);
}

// The parent of section id `node` in the frontier's hierarchy, or kNoParent for its root. The tree's: Scene::parent
// (the scene root's parent is itself). The wide frontier's: a wide node's is the wide node naming it, an item's the
// wide node whose slot names it, below the items Scene::parent.
std::uint32_t BoundarySection::parent_or_none(std::uint32_t node) const noexcept {
  const Scene& sc = *scene_;
  if (wide_mode_) {
    if (is_wide_id(node)) {
      const std::uint32_t up = wide_up_[node - wide_base_];
      return up == kNoParent ? kNoParent : wide_base_ + (up >> 2);
    }
    const std::uint32_t c = sc.tag_curve(node);
    const CurveNodes& cn = sc.curve_nodes(c);
    const int item = wide_item_level(static_cast<int>(cn.levels));
    if (sc.tag_level(node) == item) return wide_base_ + (item_up_[item_first_[c] + (node - cn.box_offset[item])] >> 2);
  }
  return node == sc.scene_root() ? kNoParent : sc.parent(node);
}

// The wide frontier's links (wide_up_, item_up_, item_first_) and the root's rectangle, from the index. O(wide nodes).
void BoundarySection::link_wide_nodes() {
  const Scene& sc = *scene_;
  const WideIndex& wi = sc.wide_index();
  item_first_.assign(sc.curve_count(), 0);
  std::uint32_t items = 0;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {  // items numbered curve by curve
    item_first_[c] = items;
    items += sc.curve(c).segment_count[wide_item_level(sc.curve(c).levels)];
  }
  item_up_.assign(items, kNoParent);
  wide_up_.assign(wi.nodes.size(), kNoParent);
  if (!wi.nodes.empty()) wi.node_rect(0, &wide_root_rect_.lo, &wide_root_rect_.hi);
  for (std::uint32_t w = 0; w < wi.nodes.size(); ++w) {
    const WideNode& nd = wi.nodes[w];
    for (std::uint32_t i = 0; i < 4; ++i) {
      const std::uint32_t code = nd.child[i];
      if (code == kWideEmpty) continue;
      if (code & kWideLeaf) {
        const std::uint32_t item = code & ~kWideLeaf;
        const std::uint32_t c = sc.tag_curve(item);
        const std::uint32_t k = item - sc.curve_nodes(c).box_offset[sc.tag_level(item)];
        item_up_[item_first_[c] + k] = w << 2 | i;
      } else {
        wide_up_[code] = w << 2 | i;
      }
    }
  }
}

// The rectangle of section id `id` [m]: a wide node's, its slot's in its parent (the root's, its slots' union); a
// scene node's, Scene::aabb.
Aabb BoundarySection::entry_rect(std::uint32_t id) const noexcept {
  if (!is_wide_id(id)) return scene_->aabb(id);
  const std::uint32_t up = wide_up_[id - wide_base_];
  if (up == kNoParent) return wide_root_rect_;
  const WideNode& n = scene_->wide_index().nodes[up >> 2];
  const std::uint32_t i = up & 3u;
  return Aabb{{n.lo_x[i], n.lo_y[i]}, {n.hi_x[i], n.hi_y[i]}};
}

// The box of section id `id`: a scene node's (Scene::box), or a wide node's rectangle as an axis-aligned box (as
// Scene::box gives a chunk's).
ErrorBox BoundarySection::entry_box(std::uint32_t id) const noexcept {
  if (!is_wide_id(id)) return scene_->box(id);
  return rect_box(entry_rect(id));
}

// entry_box of section entry i, for a wide node read from the section's own rectangle rather than the index: its
// slot's in its parent, stored as it is by a split (split_wide) or widened outward a little (set_section_entry);
// either holds everything under the node.
ErrorBox BoundarySection::entry_box_at(std::size_t i) const noexcept {
  const std::uint32_t id = section_[i];
  if (!is_wide_id(id)) return scene_->box(id);
  const SectionRects& r = section_rect_;
  return rect_box(Aabb{{r.lo_x[i], r.lo_y[i]}, {r.hi_x[i], r.hi_y[i]}});
}

// How many children section id `id` has in the frontier's hierarchy (entry_children's count), cheaply.
std::uint32_t BoundarySection::child_count(std::uint32_t id) const noexcept {
  if (is_wide_id(id)) {
    const WideNode& n = scene_->wide_index().nodes[id - wide_base_];
    return static_cast<std::uint32_t>((n.child[0] != kWideEmpty) + (n.child[1] != kWideEmpty) + (n.child[2] != kWideEmpty) +
                                      (n.child[3] != kWideEmpty));
  }
  std::uint32_t first = 0, count = 0;
  scene_->children(id, &first, &count);
  return count;
}

// The children of section id `id` in the frontier's hierarchy, written to out (at most kMaxEntryChildren); returns
// their count. A wide node's: its slots' wide nodes and items, empty slots left out; a scene node's: Scene::children
// (the wide frontier never holds a scene node above the items).
std::uint32_t BoundarySection::entry_children(std::uint32_t id, std::uint32_t* out) const noexcept {
  if (is_wide_id(id)) {
    const WideNode& nd = scene_->wide_index().nodes[id - wide_base_];
    std::uint32_t count = 0;
    for (std::uint32_t code : nd.child) {
      if (code == kWideEmpty) continue;
      out[count++] = wide_child_id(code);
    }
    return count;
  }
  std::uint32_t first = 0, count = 0;
  scene_->children(id, &first, &count);
  for (std::uint32_t i = 0; i < count; ++i) out[i] = first + i;
  return count;
}

// Marks a node out of the section, and no longer counted among its parent's children in.
void BoundarySection::mark_out(std::uint32_t node, std::uint32_t parent) noexcept {
  clear_state(node, kInSection);
  if (parent != kNoParent) node_state_[parent] = static_cast<std::uint8_t>(node_state_[parent] - kChildInUnit);  // it was counted
}

// Takes the entry out: the last entry moves into its place (the order of entries is no answer's business).
void BoundarySection::remove_section_entry(std::size_t entry) noexcept {
  const std::size_t last = section_.size() - 1;
  if (entry != last) {
    section_rect_.copy(entry, last);
    section_[entry] = section_[last];
    section_parent_[entry] = section_parent_[last];
  }
  section_.pop_back();
}

// Splits the node at section entry `entry` into its children: the first takes its place, the others are
// appended, so no entry is left to drop. Without room the node stays (a box holds its children's walls).
void BoundarySection::split(std::uint32_t node, std::size_t entry) {
  if (is_wide_id(node)) {
    split_wide(node, entry);
    return;
  }
  std::uint32_t first = 0, count = 0;
  scene_->children(node, &first, &count);
  if (count == 0 || !in_section(node)) return;
  if (section_.size() + count + 8 > capacity_) return;  // full: keep the node
  mark_out(node, section_parent_[entry]);
  set_section_entry(entry, first, node);
  for (std::uint32_t i = 1; i < count; ++i) push_section(first + i, node);
}

// split for a wide node: its slots' wide nodes and items take its place, each with its slot's rectangle (which
// holds it: the slot is its rectangle padded outward, wide_index.hpp), read from the node itself.
void BoundarySection::split_wide(std::uint32_t node, std::size_t entry) {
  const WideNode& n = scene_->wide_index().nodes[node - wide_base_];
  if (!in_section(node) || section_.size() + 4 + 8 > capacity_) return;  // full: keep the node
  mark_out(node, section_parent_[entry]);
  bool first = true;
  for (int i = 0; i < 4; ++i) {
    const std::uint32_t code = n.child[i];
    if (code == kWideEmpty) continue;
    const std::size_t at = first ? entry : section_.size();
    if (!first) section_.push_back(0);  // within the reserved capacity: no allocation (place_entry fills it)
    first = false;
    section_rect_.set_floats(at, n.lo_x[i], n.lo_y[i], n.hi_x[i], n.hi_y[i]);
    place_entry(at, wide_child_id(code), node);
  }
}

// Merges the children (count of them) of `parent`, all in the section, one of them at `entry`: the parent takes
// that entry's place and the others' entries are taken out (found by a scan of the section's parents, a few dozen).
// False, with nothing changed, when they are not all found (never, for a frontier) or there are more than
// kMaxSiblings (never: no node has more than 4 children, scene.hpp and wide_index.hpp).
bool BoundarySection::merge_children(std::size_t entry, std::uint32_t parent, const std::uint32_t* children, std::uint32_t count) {
  constexpr std::size_t kMaxSiblings = 15;
  std::size_t sibling_entry[kMaxSiblings];
  std::size_t k = 0;
  for (std::size_t i = 0; i < section_.size(); ++i) {
    if (section_parent_[i] != parent || i == entry) continue;
    if (k == kMaxSiblings) return false;
    sibling_entry[k++] = i;  // increasing
  }
  if (k + 1 != count) return false;
  for (std::uint32_t i = 0; i < count; ++i) clear_state(children[i], kInSection);
  clear_state(parent, kChildrenInMask);
  set_section_entry(entry, parent, parent_or_none(parent));
  while (k > 0) remove_section_entry(sibling_entry[--k]);  // highest first: a later one is never the last moved
  return true;
}

// One query's inputs, answer so far and counters, passed to each phase of first_hit.
struct BoundarySection::Query {
  Vec2 a, b;                    // the sweep [m]
  Aabb sweep;                   // the rectangle around it
  int level = 0;                // target level (clamped per curve)
  const SegmentRef* excluded = nullptr;
  int excluded_count = 0;
  QueryBudget* budget = nullptr;
  SweepHit best;                // nearest exact hit so far (t = +inf: none)
  double unresolved_t = std::numeric_limits<double>::infinity();  // entry of the nearest box left unrefined
  std::uint32_t unresolved_node = 0;
  double nearest_sq = std::numeric_limits<double>::infinity();  // squared distance from b to the section's nearest box
  QueryStats st;
  bool refused = false;  // optional work was refused for want of budget (a wide node may be refused before it is quite spent)
  std::size_t scanned = 0;  // section entries phase 1 scanned (the first ones of section_)
  std::size_t hit = 0;      // of which the sweep met, grown by the merge margin (kHitMark)
  std::size_t nearest_rect = 0;  // of which the one whose rectangle is nearest to b (scanned when none)

  float ax = 0.0f, ay = 0.0f, ix = 0.0f, iy = 0.0f;  // the sweep for sweep_node: its start, the reciprocals of its extent

  Query(Vec2 a_m, Vec2 b_m, int target_level, const SegmentRef* excluded_segments, int n_excluded, QueryBudget& shared_budget)
      : a(a_m), b(b_m), sweep(rect_of(a_m, b_m)),
        level(target_level), excluded(excluded_segments), excluded_count(n_excluded), budget(&shared_budget) {
    best.t = std::numeric_limits<double>::infinity();  // no exact hit yet
    best.point_m = b_m;
    ax = static_cast<float>(a_m.x);
    ay = static_cast<float>(a_m.y);
    ix = slab_reciprocal(b_m.x - a_m.x);
    iy = slab_reciprocal(b_m.y - a_m.y);
  }

  // The section entries' clips: always done and charged, even past the budget.
  void charge_section_boxes(std::int32_t n) noexcept {
    st.box_tests += n;
    st.section_box_tests += n;
    budget->charge(n);
  }
  // Any other box test: only while the budget lasts.
  bool spend_box() noexcept { return spend_boxes(1); }
  // A wide node's four rectangles: all or none.
  bool spend_wide_node() noexcept { return spend_boxes(kWideBoxTestsPerNode); }
  bool spend_boxes(std::int32_t n) noexcept {
    if (!budget->spend(n)) {
      refused = true;
      return false;
    }
    st.box_tests += n;
    return true;
  }
  bool is_excluded(SegmentRef s) const noexcept { return hk::is_excluded(s, excluded, excluded_count); }
  // One wall (segment ref from p0 to p1 [m], not excluded) tested against the sweep; kept when it is the nearest hit
  // so far (of equals, the smallest (curve, level, segment): the answer does not depend on the order of the walk).
  // A rectangle test first: the rectangles apart, no common point.
  void test_wall(SegmentRef ref, Vec2 p0, Vec2 p1) noexcept {
    ++st.segment_tests;
    st.coarsest_answer_level = std::max(st.coarsest_answer_level, ref.level);
    double t = 0.0;
    if (overlaps(rect_of(p0, p1), sweep, 0.0) && intersect_sweep_segment(a, b, p0, p1, &t) && closer(t, ref, best.t, best.segment)) {
      best.hit = true;
      best.t = t;
      best.segment = ref;
    }
  }
  // Boxes entered past this cannot hold anything nearer than what is known.
  double horizon() const noexcept { return std::min(best.t, unresolved_t); }
};

// Free-space ball (seed §3: "distances to the boxes ... can be used to schedule box updates"): the
// last full query proved that no box of the section comes within the ball's radius of ball_center_m_, and
// those boxes covered every wall of the level ids it served (ball_levels_; follow_level forgets the ball for
// any other id). A sweep inside that ball cannot hit anything: answer at once.
bool BoundarySection::inside_free_ball(Vec2 a, Vec2 b) const noexcept {
  const double r_sq = ball_radius_sq_;
  const Vec2 da = a - ball_center_m_, db = b - ball_center_m_;
  return (dot(da, da) < r_sq) & (dot(db, db) < r_sq);  // r = 0 (unknown) admits nothing; & : one branch, not two
}

// The ball's walls (gather_ball_walls) answer a sweep of their level id inside their ball: the first hit among
// them, excluded ones left out, the same answer a full query gives (every wall within the ball is among them;
// ties as test_segment). False, with nothing written, for a sweep they cannot answer. Charges no box test. The
// first sweep inside the ball copies the walls (copy_ball_walls).
bool BoundarySection::answer_from_ball_walls(Vec2 a, Vec2 b, int level, const SegmentRef* excluded, int excluded_count,
                                             SweepHit* out, QueryStats* stats) noexcept {
  BallWalls& w = ball_walls_;
  if (level != w.level) return false;
  const double r_sq = w.radius_sq;
  const Vec2 da = a - w.center_m, db = b - w.center_m;
  if (!(dot(da, da) < r_sq && dot(db, db) < r_sq)) return false;
  if (!w.copied) copy_ball_walls();
  // The walls whose rectangle meets the sweep's (the rectangles apart: no common point), as a bit mask, two
  // walls per step (a slot past count meets nothing that counts: the mask drops it).
  const Aabb sweep = rect_of(a, b);
  unsigned meets = 0;
  for (int k = 0; k < w.count; k += 2) {
#if defined(__SSE2__)
    const __m128d lx = _mm_load_pd(w.lo_x + k), ly = _mm_load_pd(w.lo_y + k), hx = _mm_load_pd(w.hi_x + k), hy = _mm_load_pd(w.hi_y + k);
    const __m128d m = _mm_and_pd(_mm_and_pd(_mm_cmple_pd(lx, _mm_set1_pd(sweep.hi.x)), _mm_cmple_pd(_mm_set1_pd(sweep.lo.x), hx)),
                                 _mm_and_pd(_mm_cmple_pd(ly, _mm_set1_pd(sweep.hi.y)), _mm_cmple_pd(_mm_set1_pd(sweep.lo.y), hy)));
    meets |= static_cast<unsigned>(_mm_movemask_pd(m)) << k;
#else
    for (int i = k; i < k + 2; ++i) {
      meets |= (w.lo_x[i] <= sweep.hi.x && sweep.lo.x <= w.hi_x[i] && w.lo_y[i] <= sweep.hi.y && sweep.lo.y <= w.hi_y[i] ? 1u : 0u) << i;
    }
#endif
  }
  meets &= (1u << w.count) - 1u;
  SweepHit best;
  best.t = std::numeric_limits<double>::infinity();
  std::int32_t tested = 0;
  int coarsest = 0;
  for (; meets != 0; meets &= meets - 1) {
    const int k = __builtin_ctz(meets);
    if (is_excluded(w.ref[k], excluded, excluded_count)) continue;
    ++tested;
    coarsest = std::max(coarsest, w.ref[k].level);
    double t = 0.0;
    if (intersect_sweep_segment(a, b, w.p0_m[k], w.p1_m[k], &t) && closer(t, w.ref[k], best.t, best.segment)) {
      best.hit = true;
      best.t = t;
      best.segment = w.ref[k];
    }
  }
  if (best.hit) {
    best.point_m = lerp(a, b, best.t);
  } else {
    best.t = 1.0;
    best.point_m = b;
  }
  if (stats) {
    *stats = QueryStats{};
    stats->segment_tests = tested;
    stats->coarsest_answer_level = coarsest;
    stats->ball_walls = true;
    stats->section_size = static_cast<std::int32_t>(section_.size());
  }
  *out = best;
  return true;
}

// Phase 0: the section serves the level ids of this query and the one before it (two in turn while the
// contact solver renders both walls of a level change; one otherwise): every segment entry is at or above
// the walls of both on its curve (a level: its clamp_level; a cut step: the cut), so its box holds their
// walls, and splits stop at the coarser of the two (at_floor). A new id keeps the section: entries below
// its walls give way to their ancestor at them (coarsen_section), which holds the same stretch of curve; to
// a finer id nothing changes. The free-space ball holds for the two ids it was measured for, and is
// forgotten at any other. The frontier is the wide one while the wide index serves both ids (wide_frontier), else
// the tree's; a change of ids that changes which starts the section again from that frontier's root (reset).
// Called only when the ids change (first_hit).
void BoundarySection::follow_level(int level) noexcept {
  const int previous = last_level_, served = other_level_;  // the section serves both
  other_level_ = previous < 0 ? level : previous;
  last_level_ = level;
  const bool wide = wide_frontier(level) && wide_frontier(other_level_);
  if (previous < 0 || wide != wide_mode_) {  // the other frontier: start it from its root
    wide_mode_ = wide;
    reset();
    return;
  }
  if (level == previous) return;
  if (level != ball_levels_[0] && level != ball_levels_[1]) ball_radius_sq_ = 0.0;
  if (level != served) coarsen_section(level);  // a transition's two ids in turn: nothing to coarsen
}

// The node's ancestor at the walls of `level` on its curve (a segment of that level, or of that cut step's cut)
// when the node lies below them, else the node itself: up by Scene::parent, O(levels).
std::uint32_t BoundarySection::wall_ancestor(std::uint32_t node, int level) const noexcept {
  const Scene& sc = *scene_;
  if (!sc.is_segment(node)) return node;
  if (!is_cut_level(level)) {
    const int target = sc.clamp_level(sc.tag_curve(node), level);
    std::uint32_t a = node;
    while (sc.tag_level(a) < target) a = sc.parent(a);  // target ≤ the curve's coarsest: a stays a segment
    return a;
  }
  for (std::uint32_t a = sc.parent(node); sc.is_segment(a); a = sc.parent(a)) {  // the cut is a frontier: at most one
    if (in_cut(cut_mask_, a, level - kCutLevelBase)) return a;
  }
  return node;
}

// Every segment entry below the walls of `level` replaced by its ancestor at them (wall_ancestor; once, however
// many of its descendants were in), so the section still covers the same stretches of curve, no node with
// its ancestor. Without room for the ancestors (a section at its storage bound), the section starts again
// from the root.
void BoundarySection::coarsen_section(int level) noexcept {
  const std::size_t n = section_.size();
  bool changed = false;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t node = section_[i];
    const std::uint32_t ancestor = wall_ancestor(node, level);
    if (ancestor == node) continue;
    if (section_.size() >= capacity_) {
      reset();
      return;
    }
    mark_out(node, section_parent_[i]);
    if (!in_section(ancestor)) push_section(ancestor, parent_or_none(ancestor));
    changed = true;
  }
  if (changed) drop_departed_entries();
}

// Splits stop here: a segment node at the walls of either id the section serves (so at the coarser of the
// two; the section's entries are never below either, follow_level).
bool BoundarySection::at_floor(std::uint32_t node, int level) const noexcept {
  return at_target(node, level) || at_target(node, other_level_);
}

void BoundarySection::next_tick() noexcept { ++tick_; }  // wraps harmlessly: it only turns the merges' round robin

// The end of a full query: every mark its phases set, cleared (the next query starts with none).
void BoundarySection::clear_marks() noexcept {
  for (std::size_t i = 0; i < marked_count_; ++i) clear_state(marked_[i], kMarks);
  marked_count_ = 0;
}

// Phase 1: clip the sweep against every box of the boundary section, grown by the merge margin, so one
// clip answers both "hit?" (then an exact clip makes it a candidate) and "still near?" (else it may merge).
// On the way, the distance from the end of the sweep to the nearest box: the next free-space ball. The
// rectangles settle most entries: scan_section_rects bounds them all (four per SSE instruction), and only
// the entries whose rectangle meets the sweep, or is nearer than the nearest box found, have their box
// rebuilt. An entry not hit is idle (no kHitMark): merge_idle_siblings may merge it.
void BoundarySection::clip_section(Query& q) {
  candidates_.clear();
  const std::size_t n_section = section_.size();
  q.scanned = n_section;
  q.charge_section_boxes(static_cast<std::int32_t>(n_section));
  const std::size_t nearest_rect = scan_section_rects(q);
  q.nearest_rect = nearest_rect;
  if (nearest_rect == n_section) return;  // an empty section (an empty scene)
  // The free-space ball: the nearest box. A rectangle holds its box, so a box is nearer than the nearest found
  // so far only when its rectangle is; starting from the box of the nearest rectangle leaves few others to
  // rebuild. The minimum is the same whatever the order.
  q.nearest_sq = box_distance_sq(entry_box_at(nearest_rect), q.b);
  mark_near_rects(q.nearest_sq, nearest_rect);
  const std::size_t words = (n_section + 63) / 64;
  for (std::size_t w = 0; w < words; ++w) {
    for (std::uint64_t m = rect_overlap_bits_[w] | rect_near_bits_[w]; m != 0; m &= m - 1) {
      const std::size_t i = 64 * w + static_cast<std::size_t>(__builtin_ctzll(m));
      if (i >= n_section) break;  // past the end: the last group's far entries (never marked)
      const std::uint32_t node = section_[i];
      const std::uint64_t bit = std::uint64_t{1} << (i % 64);
      const ErrorBox box = entry_box_at(i);
      if (rect_near_bits_[w] & bit) q.nearest_sq = std::min(q.nearest_sq, box_distance_sq(box, q.b));
      double te = 0.0, tx = 0.0;
      if ((rect_overlap_bits_[w] & bit) && clip_segment_box(box, q.a, q.b, merge_margin_m_, &te, &tx)) {
        mark(node, kHitMark);
        ++q.hit;
        if (clip_segment_box(box, q.a, q.b, 0.0, &te, &tx)) candidates_.push_back({te, node, static_cast<std::uint32_t>(i)});
      }
    }
  }
}

// The rectangle pass of clip_section: for every section entry, a lower bound on the squared distance from the
// sweep's end to its rectangle (rect_d_sq_) and whether the rectangle, grown by the merge margin, may meet the
// sweep's (bit i % 64 of rect_overlap_bits_[i / 64]), four entries per SSE instruction. The rectangles are floats
// widened outward (SectionRects::set), so both answers are conservative: every entry whose exact rectangle meets
// the sweep's grown by the margin has its bit (the comparisons are against the sweep's bounds widened outward as
// well, with no arithmetic on the rectangles), and each distance is at most the exact one (a slack of 2^-20 of
// the largest coordinate, four times what rounding the point and the subtractions can add, is taken off each
// axis's distance; with it the squares' rounding cannot lift the sum above the exact distance either). The exact
// boxes decide after it (clip_section). Entries in groups of four: the arrays hold four past the most there can
// be, and the four past the section are made infinitely far (SectionRects::set_far_group), so the last group's extra
// lanes measure +inf and meet nothing. Returns the entry of the nearest rectangle by these bounds (the first of
// equals; section_.size() when it is empty).
std::size_t BoundarySection::scan_section_rects(const Query& q) {
  const std::size_t n = section_.size();
  const float* lo_x = section_rect_.lo_x.data();
  const float* lo_y = section_rect_.lo_y.data();
  const float* hi_x = section_rect_.hi_x.data();
  const float* hi_y = section_rect_.hi_y.data();
  float* d_sq = rect_d_sq_.data();
  QuadBitWriter overlap{rect_overlap_bits_.data()};
  // The sweep's rectangle grown by the margin, widened outward as the entries' are: an entry may meet it when
  // lo ≤ s_hi and s_lo ≤ hi.
  const double m = merge_margin_m_;
  const float s_lo_x = float_below(q.sweep.lo.x - m), s_lo_y = float_below(q.sweep.lo.y - m);
  const float s_hi_x = float_above(q.sweep.hi.x + m), s_hi_y = float_above(q.sweep.hi.y + m);
  const float px = static_cast<float>(q.b.x), py = static_cast<float>(q.b.y);
  const double largest = std::max({scale_m_, std::abs(q.b.x), std::abs(q.b.y)});
  const float slack = float_above(1e-12 + largest * 0x1p-20);
  section_rect_.set_far_group(n);  // the last group's entries past the section
  std::size_t nearest = n;
  std::size_t i = 0;
#if defined(__SSE2__)
  const __m128 vpx = _mm_set1_ps(px), vpy = _mm_set1_ps(py), zero = _mm_setzero_ps(), vslack = _mm_set1_ps(slack);
  const __m128 v_slo_x = _mm_set1_ps(s_lo_x), v_slo_y = _mm_set1_ps(s_lo_y), v_shi_x = _mm_set1_ps(s_hi_x), v_shi_y = _mm_set1_ps(s_hi_y);
  static_assert(kMaxSectionEntries < (1u << 24), "entries are exact as floats (NearestOfFours)");
  NearestOfFours nearest_rect(n);
  for (; i < n; i += kScanLanes) {
    const __m128 lx = _mm_loadu_ps(lo_x + i), ly = _mm_loadu_ps(lo_y + i), hx = _mm_loadu_ps(hi_x + i), hy = _mm_loadu_ps(hi_y + i);
    const __m128 dx = _mm_max_ps(_mm_sub_ps(_mm_max_ps(_mm_sub_ps(lx, vpx), _mm_sub_ps(vpx, hx)), vslack), zero);
    const __m128 dy = _mm_max_ps(_mm_sub_ps(_mm_max_ps(_mm_sub_ps(ly, vpy), _mm_sub_ps(vpy, hy)), vslack), zero);
    const __m128 d = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy));
    _mm_storeu_ps(d_sq + i, d);
    nearest_rect.take(d);
    const __m128 meets = _mm_and_ps(_mm_and_ps(_mm_cmple_ps(lx, v_shi_x), _mm_cmple_ps(v_slo_x, hx)),
                                    _mm_and_ps(_mm_cmple_ps(ly, v_shi_y), _mm_cmple_ps(v_slo_y, hy)));
    overlap.put(i, static_cast<unsigned>(_mm_movemask_ps(meets)));
  }
  nearest = nearest_rect.nearest();
#else
  float nearest_sq = std::numeric_limits<float>::infinity();
  for (; i < n; i += kScanLanes) {
    unsigned four_bits = 0;
    for (std::size_t k = i; k < i + kScanLanes; ++k) {
      const float dx = std::max(std::max(lo_x[k] - px, px - hi_x[k]) - slack, 0.0f);
      const float dy = std::max(std::max(lo_y[k] - py, py - hi_y[k]) - slack, 0.0f);
      d_sq[k] = dx * dx + dy * dy;
      if (d_sq[k] < nearest_sq) {
        nearest_sq = d_sq[k];
        nearest = k;
      }
      if (lo_x[k] <= s_hi_x && s_lo_x <= hi_x[k] && lo_y[k] <= s_hi_y && s_lo_y <= hi_y[k]) four_bits |= 1u << (k - i);
    }
    overlap.put(i, four_bits);
  }
#endif
  overlap.finish(i);
  return nearest;
}

// The entries whose rectangle may be nearer to the sweep's end than bound_sq [m²] (their distance bound is
// below it, rounded up to a float), but for `skip` (whose box was measured already): bit i % 64 of
// rect_near_bits_[i / 64]. In groups of four, as scan_section_rects.
void BoundarySection::mark_near_rects(double bound_sq, std::size_t skip) {
  const std::size_t n = section_.size();
  const float* d_sq = rect_d_sq_.data();
  const float bound = float_above(bound_sq);
  QuadBitWriter near{rect_near_bits_.data()};
  std::size_t i = 0;
  for (; i < n; i += kScanLanes) {
#if defined(__SSE2__)
    near.put(i, static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(_mm_loadu_ps(d_sq + i), _mm_set1_ps(bound)))));
#else
    unsigned four_bits = 0;
    for (std::size_t k = 0; k < kScanLanes; ++k) four_bits |= (d_sq[i + k] < bound ? 1u : 0u) << k;
    near.put(i, four_bits);
#endif
  }
  near.finish(i);
  rect_near_bits_[skip / 64] &= ~(std::uint64_t{1} << (skip % 64));
}

// Intersects the sweep with one segment of the target level; keeps the nearest hit (of equals, the smallest
// (curve, level, segment): the answer does not depend on the order of the walk, nor on the section's state).
void BoundarySection::test_segment(Query& q, std::uint32_t node) {
  const NodeInfo in = scene_->info(node);
  const SegmentRef ref{static_cast<std::int32_t>(in.curve), in.level, static_cast<std::int32_t>(in.index)};
  if (q.is_excluded(ref)) return;
  Vec2 p0, p1;
  wall_node_points(node, q.level, &p0, &p1);
  q.test_wall(ref, p0, p1);
}

// Pushes the children of `node` the sweep enters, nearest on top. Returns false, with nothing pushed,
// when the budget or the stack ran out first: the box then stays unrefined.
bool BoundarySection::push_hit_children(Query& q, std::uint32_t node, int& top) {
  if (is_wide_id(node)) return push_wide_children(q, node, top);
  const Scene& sc = *scene_;
  std::uint32_t first = 0, count = 0;
  sc.children(node, &first, &count);
  const int base = top;
  for (std::uint32_t i = 0; i < count; ++i) {
    double te = 0.0, tx = 0.0;
    if (!q.spend_box()) {
      top = base;
      return false;
    }
    if (overlaps(sc.loose_aabb(first + i), q.sweep, 0.0) && clip_segment_box(sc.box(first + i), q.a, q.b, 0.0, &te, &tx) && te <= q.best.t &&
        !push(top, {te, first + i, kNotAnEntry})) {
      top = base;  // the stack is full: as past the budget
      return false;
    }
  }
  std::sort(stack_.begin() + base, stack_.begin() + top, [](const Candidate& x, const Candidate& y) { return x.t_enter > y.t_enter; });
  return true;
}

// push_hit_children for a wide node (the wide frontier): its four rectangles in one SIMD test (sweep_node, as the
// wide index's walks), four optional box tests, all or none; the slots the sweep enters before the horizon pushed,
// nearest on top, as their section ids (a wide node, or an item's segment node).
bool BoundarySection::push_wide_children(Query& q, std::uint32_t node, int& top) {
  if (!q.spend_wide_node()) return false;
  const WideNode& n = scene_->wide_index().nodes[node - wide_base_];
  float t_enter[4];
  const double h = q.horizon();
  const int mask = sweep_node(n, q.ax, q.ay, q.ix, q.iy, h > 1.0 ? 1.0f : float_at_least(h), t_enter);
  const int base = top;
  for (int i = 0; i < 4; ++i) {
    if (!(mask & (1 << i))) continue;
    const std::uint32_t id = wide_child_id(n.child[i]);
    if (!push(top, {static_cast<double>(t_enter[i]), id, kNotAnEntry})) {
      top = base;  // the stack is full: as past the budget
      return false;
    }
  }
  std::sort(stack_.begin() + base, stack_.begin() + top, [](const Candidate& x, const Candidate& y) { return x.t_enter > y.t_enter; });
  return true;
}

// The walls of level id `level` under a segment node at most kDirectLevels above them: their count (at most
// 2^kDirectLevels) and, in *first, the first one's node (they are consecutive nodes, whose points are
// consecutive too); 0 for any other node (a chunk or above, a node farther above its walls, a cut step's
// walls, which are of mixed levels). The node must not lie below the walls (no section entry does).
std::uint32_t BoundarySection::segments_under(std::uint32_t node, int level, std::uint32_t* first) const noexcept {
  const Scene& sc = *scene_;
  if (!sc.is_segment(node) || is_cut_level(level)) return 0;
  const std::uint32_t c = sc.tag_curve(node);
  const int l = sc.tag_level(node);
  const int target = sc.clamp_level(c, level);
  if (l - target > kDirectLevels) return 0;
  const CurveNodes& cn = sc.curve_nodes(c);
  *first = cn.box_offset[target] + ((node - cn.box_offset[l]) << (l - target));
  return 1u << (l - target);
}

// A box near its target level: the target level's segments under it (at most 2^kDirectLevels, consecutive
// nodes whose points are consecutive too) tested directly rather than through the boxes between, as the wide
// index's walks test the segments under an item. Same first hit (the nearest of the segments under the box,
// the boxes between only prune). Each segment costs one optional box test, all or none: false, with nothing
// tested or charged, when the box is not a segment box within kDirectLevels of a level target (a cut step's
// segments are of mixed levels) or the budget cannot cover them (the descent then goes box by box, anytime).
bool BoundarySection::test_segments_under(Query& q, std::uint32_t node) {
  std::uint32_t first = 0;
  const std::uint32_t count = segments_under(node, q.level, &first);
  if (count == 0 || !q.budget->affords(static_cast<std::int32_t>(count))) return false;  // not refused: the descent may still go part way
  q.spend_boxes(static_cast<std::int32_t>(count));
  test_level_run(q, first, count);
  return true;
}

// test_segment for the `count` consecutive segment nodes of one level of one curve from `first` (not a cut step's),
// with what they share found once: their curve and level (their indices run on from the first's) and their points
// (consecutive slots), each its own level's wall.
void BoundarySection::test_level_run(Query& q, std::uint32_t first, std::uint32_t count) {
  const NodeInfo in = scene_->info(first);
  const Vec2* pts = scene_->slot_points(first);
  for (std::uint32_t i = 0; i < count; ++i) {
    const SegmentRef ref{static_cast<std::int32_t>(in.curve), in.level, static_cast<std::int32_t>(in.index + i)};
    if (!q.is_excluded(ref)) q.test_wall(ref, pts[i], pts[i + 1]);
  }
}

// Phase 2: nearest first. Hit boxes in order of entry, each refined depth-first (nearest child first)
// down to the target level (within 3 levels of it, the segments under the box at once: test_segments_under),
// pruned past the best hit. Past the budget, boxes are not refined: the nearest
// such box bounds what is proven clear (a box holds everything finer).
void BoundarySection::refine_candidates(Query& q) {
  std::sort(candidates_.begin(), candidates_.end(), [](const Candidate& x, const Candidate& y) { return x.t_enter < y.t_enter; });
  for (const Candidate& cand : candidates_) {
    if (cand.t_enter > q.horizon()) break;
    int top = 0;
    stack_[top++] = cand;
    while (top > 0) {
      const Candidate cur = stack_[--top];
      if (cur.t_enter > q.horizon()) continue;
      if (at_target(cur.node, q.level)) {
        test_segment(q, cur.node);
      } else if (!test_segments_under(q, cur.node) && !push_hit_children(q, cur.node, top) && cur.t_enter < q.unresolved_t) {
        q.unresolved_t = cur.t_enter;
        q.unresolved_node = cur.node;
      }
    }
  }
}

// Phase 3: the ball's walls, a second free-space ball around the same centre (the end of the sweep) that
// reaches past the nearest boxes: the section entries nearest to it, in order of their rectangles' distance,
// while each is a segment box within kDirectLevels of its walls and all their walls fit in kMaxBallWalls, have
// those walls noted, as runs copied out when first needed (seed §3: coherence; the walls under a box are its
// only walls of the level); the ball's radius is the distance to the nearest entry left out (its box's distance,
// and no more than the next one's rectangle's, which bounds every farther box from below). Every wall of the
// level within that radius is then among those noted, so a later sweep inside the ball is answered exactly by
// them alone (answer_from_ball_walls): near a wall, or sliding along one in contact, where the plain ball is as small as the gap to it. Kept only
// when it reaches farther than the plain ball. Runs before the splits and merges, which change the entries in
// place: it reads them as phase 1 scanned them.
void BoundarySection::gather_ball_walls(const Query& q) noexcept {
  BallWalls& w = ball_walls_;
  w.radius_sq = 0.0;
  w.count = 0;
  w.runs = 0;
  w.copied = false;
  const std::size_t n = q.scanned;
  std::uint32_t unused = 0;
  if (q.nearest_rect >= n || segments_under(section_[q.nearest_rect], q.level, &unused) == 0) return;  // no walls to copy
  // Note the walls of the nearest entries, in order of their rectangles' distance (each taken out of rect_d_sq_ as it
  // is reached, so the next is the nearest left), while they fit (copied when first needed: copy_ball_walls).
  float* d_sq = rect_d_sq_.data();
  constexpr double kAllWallsRadius_m = 1.0;  // every entry's walls noted: any radius holds; the workspace is smaller
  double r_sq = kAllWallsRadius_m * kAllWallsRadius_m;
  for (std::size_t e = q.nearest_rect; e < n;) {
    std::uint32_t first = 0;
    const std::uint32_t count = w.runs == kBallWallEntries ? 0 : segments_under(section_[e], q.level, &first);
    d_sq[e] = std::numeric_limits<float>::infinity();
    if (count == 0 || w.count + static_cast<int>(count) > kMaxBallWalls) {
      // The radius: the first entry left out, by its box; every other one is no nearer than the next rectangle.
      r_sq = box_distance_sq(entry_box_at(e), q.b);
      const std::size_t next = nearest_rect_left(n);
      if (next < n) r_sq = std::min(r_sq, static_cast<double>(d_sq[next]));
      break;
    }
    w.run_first[w.runs] = first;
    w.run_count[w.runs] = count;
    ++w.runs;
    w.count += static_cast<int>(count);
    e = nearest_rect_left(n);
  }
  if (w.count == 0 || r_sq <= q.nearest_sq) {
    w.count = 0;
    w.runs = 0;
    return;
  }
  w.center_m = q.b;
  w.radius_sq = r_sq;
  w.level = q.level;
}

// The entry of the nearest rectangle left in rect_d_sq_ (the first of equals; entries taken out are +inf), or n when
// none is left: four entries per SSE instruction, no branch on the data (the scan's groups of four, its padding +inf).
std::size_t BoundarySection::nearest_rect_left(std::size_t n) const noexcept {
  const float* d_sq = rect_d_sq_.data();
  std::size_t nearest = n;
#if defined(__SSE2__)
  NearestOfFours nearest_rect(n);
  for (std::size_t i = 0; i < n; i += kScanLanes) nearest_rect.take(_mm_loadu_ps(d_sq + i));
  nearest = nearest_rect.nearest();
#else
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    if (d_sq[i] < best) {
      best = d_sq[i];
      nearest = i;
    }
  }
#endif
  return nearest;
}

// The ball's walls noted by gather_ball_walls, copied out: each run's consecutive segments (one level of one
// curve), their end points, rectangles and references, in run order. Reads the scene only here, so a full query
// whose walls ball no later sweep enters leaves their points where they are (on a large scene, seldom cached).
void BoundarySection::copy_ball_walls() noexcept {
  BallWalls& w = ball_walls_;
  const Scene& sc = *scene_;
  int k = 0;
  for (int r = 0; r < w.runs; ++r) {
    const NodeInfo in = sc.info(w.run_first[r]);
    for (std::uint32_t i = 0; i < w.run_count[r]; ++i, ++k) {
      sc.segment_points(w.run_first[r] + i, &w.p0_m[k], &w.p1_m[k]);
      const Aabb rect = rect_of(w.p0_m[k], w.p1_m[k]);
      w.lo_x[k] = rect.lo.x;
      w.lo_y[k] = rect.lo.y;
      w.hi_x[k] = rect.hi.x;
      w.hi_y[k] = rect.hi.y;
      w.ref[k] = SegmentRef{static_cast<std::int32_t>(in.curve), in.level, static_cast<std::int32_t>(in.index + i)};
    }
  }
  w.copied = true;
}

// Phase 4: the boundary section follows the handle: what was hit is split (one level per tick), down to
// the coarser of the two ids the section serves (follow_level).
void BoundarySection::split_hit_boxes(Query& q) {
  for (const Candidate& cand : candidates_) {
    if (!at_floor(cand.node, q.level)) {
      split(cand.node, cand.entry);
      ++q.st.splits;
    }
  }
}

// Phase 5: siblings whose parent is clear of the sweep by the margin merge into it (merge_children: in place, no
// entry left to drop). Merging only shrinks the section, so it can be lazy: a full query owes one check per 8 idle
// entries (merge_debt_), which the ticks the free-space ball or its walls answer pay, one or two each (merge_on_ball_tick); past
// kMaxMergeDebt owed (a walk through walls, few ball ticks) the full query pays the excess itself, parents taken
// round robin.
void BoundarySection::merge_idle_siblings(Query& q) {
  // Merges must keep up with the splits, or the section grows without bound: with 4 checks per tick and no
  // more, a long walk over a dense scene grew it to 9 000–18 000 entries (CollisionQuery.
  // BoundarySectionStaysSmallOnALongWalk; the tick's scan grows with it). So one check per kIdlePerMergeCheck
  // idle entries: a section grown by a burst of splits is merged back (with the tree's frontier and the checks made
  // by the full query itself, 884 entries at most on that walk, one per 16 fell behind there, 3 037; with the wide
  // frontier and the checks paid by the ball ticks, 174). Nothing more, so a section with fewer than 8 idle entries
  // owes none: two checks more every full query, whatever the section's size (until 2026-11-27), cost more than the
  // smaller section they kept saved (PERFORMANCE.md, round two).
  constexpr std::size_t kIdlePerMergeCheck = 8;
  // As many entries as phase 1 scanned, in section order from a point that moves with the tick (round robin);
  // the idle ones are those it did not find hit. Splits and merges since put other nodes at some of them (a
  // child, a parent, the last entry moved into a merged sibling's place) and the section may be shorter now: a
  // new node was not hit this tick, so its parent is checked too; the parent of a split one was hit and stays.
  const std::size_t n = q.scanned;
  if (n == 0) return;
  merge_debt_ += static_cast<int>((n - q.hit) / kIdlePerMergeCheck);
  if (merge_debt_ <= kMaxMergeDebt) return;  // the ball ticks after this one pay (merge_on_ball_tick)
  const int max_checks = merge_debt_ - kMaxMergeDebt;  // what is owed past the cap: at most this query's own share
  merge_debt_ = kMaxMergeDebt;
  int checks = 0;
  std::size_t e = tick_ % n;
  for (std::size_t j = 0; j < n && checks < max_checks; ++j, e = e + 1 == n ? 0 : e + 1) {
    if (e >= section_.size()) continue;
    const std::uint32_t node = section_[e];
    const std::uint32_t parent = section_parent_[e];  // kNoParent: the root
    // Every entry is in the section and none of its ancestors is (splits and merges change it in place, a
    // frontier), so only the marks decide. One check per parent per tick: a node with many children would
    // otherwise ask again for each.
    if ((node_state_[node] & kHitMark) || parent == kNoParent || (node_state_[parent] & kCheckedMark)) continue;
    mark(parent, kCheckedMark);
    ++checks;
    // All children in: most checks end here, a sibling split deeper (three in four), on one count rather than a loop
    // over the children whose exit the predictor cannot learn. Then none of them hit this tick.
    if (children_in(parent) != child_count(parent)) continue;
    std::uint32_t child[kMaxEntryChildren];
    const std::uint32_t count = entry_children(parent, child);
    bool all_idle = true;
    for (std::uint32_t i = 0; i < count; ++i) all_idle &= (node_state_[child[i]] & kHitMark) == 0;
    if (!all_idle) continue;
    if (!q.spend_box()) break;  // merging can wait for a tick with budget left
    q.st.merges += merge_if_clear(e, parent, child, count, q.a, q.b);
  }
}

// The merge of a check that found all `count` children of `parent` in the section (`child`, one at entry e): when the
// parent's box is clear of the sweep a → b by the merge margin (so none of them meets it either), it takes their place
// (merge_children). One box test, which the caller charges. True when it merged.
bool BoundarySection::merge_if_clear(std::size_t e, std::uint32_t parent, const std::uint32_t* child, std::uint32_t count, Vec2 a, Vec2 b) {
  double te = 0.0, tx = 0.0;
  if (clip_segment_box(entry_box(parent), a, b, merge_margin_m_, &te, &tx)) return false;
  return merge_children(e, parent, child, count);
}

// The merge checks full queries left owed (merge_debt_, at least one), paid on a ball tick: one the free-space ball or
// its walls answered (a → b the sweep). One check, two while more than half of kMaxMergeDebt is owed (so that runs of
// full queries seldom leave any past the cap for a full query to pay: PERFORMANCE.md, round two). Each is
// merge_check_on_ball_tick's: at most one optional box test, charged to `budget` and counted in st.
[[gnu::noinline]] void BoundarySection::merge_on_ball_tick(Vec2 a, Vec2 b, QueryBudget& budget, QueryStats& st) noexcept {
  const int checks = merge_debt_ > kMaxMergeDebt / 2 ? 2 : 1;
  for (int i = 0; i < checks; ++i) merge_check_on_ball_tick(a, b, budget, st);
}

// One merge check of the round robin on a ball tick: the parent of the next entry, when all its children are in the
// section and its box is clear of the sweep by the margin (so none of them meets the sweep either), takes their place.
// One optional box test, charged to `budget` and counted in st (box_tests; merges when it merged).
void BoundarySection::merge_check_on_ball_tick(Vec2 a, Vec2 b, QueryBudget& budget, QueryStats& st) noexcept {
  --merge_debt_;
  const std::size_t n = section_.size();
  if (n == 0) return;
  const std::size_t e = merge_cursor_++ % n;
  const std::uint32_t parent = section_parent_[e];
  if (parent == kNoParent || children_in(parent) != child_count(parent) || !budget.spend()) return;
  ++st.box_tests;
  std::uint32_t child[kMaxEntryChildren];
  const std::uint32_t count = entry_children(parent, child);
  st.merges += merge_if_clear(e, parent, child, count, a, b);
}

// Phase 6: the next free-space ball: the distance from the end of the sweep to the nearest box phase 1
// scanned, even when the section changed since: a split box holds every wall its children hold and merged
// children every wall their parent holds, so the boxes scanned still cover every wall and no wall comes
// nearer than that. (Measuring the changed section again finds the children's boxes, which may be
// farther, but cost more than the slightly larger ball saved: PERFORMANCE.md, round two.) The section needs
// no compaction: splits and merges changed it in place, no node twice (a split puts in children of a node that
// was in, so they were not; a merge a parent it checked was not), a frontier still
// (CollisionQuery.BoundarySectionStaysSmallOnALongWalk checks it).
void BoundarySection::place_free_ball(const Query& q) noexcept {
  ball_center_m_ = q.b;
  ball_radius_sq_ = q.nearest_sq;
  ball_levels_[0] = q.level;  // the boxes scanned covered the walls of both ids the section served
  ball_levels_[1] = other_level_;
}

// The section without the entries that left it (kInSection cleared), in order, rectangles with them (after
// coarsen_section).
void BoundarySection::drop_departed_entries() noexcept {
  std::size_t w = 0;
  for (std::size_t i = 0; i < section_.size(); ++i) {  // every entry copied, kept by advancing w: no branch to mispredict
    const std::uint32_t node = section_[i];
    section_rect_.copy(w, i);
    section_[w] = node;
    section_parent_[w] = section_parent_[i];
    w += node_state_[node] & kInSection;
  }
  section_.resize(w);
}

// Phase 7: the answer. An exact hit; or, when a box left unrefined begins before it, the finest level
// reached and how far the sweep is proven clear; or clear to the end.
SweepHit BoundarySection::finish(Query& q) const {
  const Scene& sc = *scene_;
  SweepHit best = q.best;
  if (q.unresolved_t < best.t) {
    best.hit = false;
    best.blocked = true;
    best.t = q.unresolved_t;
    const std::uint32_t node = q.unresolved_node;
    if (node == kWideEmpty || (!sc.is_segment(node) && !sc.is_chunk(node))) {
      best.segment = SegmentRef{-1, Scene::kMaxLevels, -1};  // above the curves (hierarchy or wide index): no segment to name yet
    } else {
      const NodeInfo in = sc.info(node);
      const int level = sc.is_chunk(node) ? static_cast<int>(sc.curve_nodes(in.curve).levels) - 1 : in.level;  // a chunk: its coarsest segments
      best.segment = SegmentRef{static_cast<std::int32_t>(in.curve), level, static_cast<std::int32_t>(in.index)};
    }
    q.st.coarsest_answer_level = std::max(q.st.coarsest_answer_level, best.segment.level);
  }
  if (best.hit || best.blocked) {
    best.point_m = lerp(q.a, q.b, best.t);
  } else {
    best.t = 1.0;
  }
  q.st.budget_exhausted = q.budget->exhausted() || q.refused;
  q.st.section_size = static_cast<std::int32_t>(section_.size());
  return best;
}

// ---- Walks of the wide index (wide_index.hpp) ----


// The segments a walk tests at an item (segment node `item` of the item level): the target level's segments
// under it (the item itself at the item level). Writes the first node and returns the count. The walks of the
// wide index take only the level ids it serves (wide_serves), whose level is at or below every curve's items.
std::uint32_t BoundarySection::item_segments(std::uint32_t item, int level, std::uint32_t* first) const noexcept {
  const Scene& sc = *scene_;
  const std::uint32_t c = sc.tag_curve(item);
  const int k_level = sc.tag_level(item);
  const CurveNodes& cn = sc.curve_nodes(c);
  const std::uint32_t k = item - cn.box_offset[k_level];
  const int l = sc.clamp_level(c, level);  // ≤ k_level (wide_serves)
  *first = cn.box_offset[l] + (k << (k_level - l));
  return 1u << (k_level - l);
}

// Checked push onto the wide walks' stack, in order: among the entries pushed since `base` (a node's
// children, at most four) the one nearest to the walk's point ends on top. False, with nothing pushed,
// when the stack is full.
[[gnu::always_inline]] inline bool BoundarySection::push_walk(float t_enter, float d_sq, std::uint32_t code, int base, int& top) noexcept {
  if (static_cast<std::size_t>(top) >= walk_.size()) return false;
  float* t = walk_.t_enter.data();
  float* d = walk_.d_sq.data();
  std::uint32_t* c = walk_.code.data();
  int k = top++;
  for (; k > base && d[k - 1] < d_sq; --k) {
    t[k] = t[k - 1];
    d[k] = d[k - 1];
    c[k] = c[k - 1];
  }
  t[k] = t_enter;
  d[k] = d_sq;
  c[k] = code;
  return true;
}

// Tests the sweep against the target level's segments at an item (test_level_run).
void BoundarySection::wide_test_item(Query& q, std::uint32_t item) {
  std::uint32_t first = 0;
  const std::uint32_t count = item_segments(item, q.level, &first);
  test_level_run(q, first, count);
}

// One walk of the wide index for both answers of first_hit_wide: the first hit of the sweep, and the
// free-space ball at its end. A child is entered when the sweep meets its rectangle before the best hit
// so far (for the hit) or when its rectangle is nearer to b than the ball so far (for the ball), nearest
// to b first, so that the ball shrinks early. At an item the sweep is tested exactly; for the ball the
// item rectangle's own distance is taken as it is (it bounds every wall under it from below). Each node
// opened is four box tests (its four rectangles, in one SIMD test); past the budget nodes are not opened:
// the nearest such node the sweep enters bounds what is proven clear, and the ball is unknown. Returns
// the ball's radius [m] (0 when unknown).
double BoundarySection::wide_walk(Query& q, double ball_cap_m) {
  const WideIndex& wi = scene_->wide_index();
  if (wi.nodes.empty()) return ball_cap_m;
  const float ax = q.ax, ay = q.ay, ix = q.ix, iy = q.iy;
  const float bx = static_cast<float>(q.b.x), by = static_cast<float>(q.b.y);
  float ball_sq = seeded_ball_sq(wi, bx, by, static_cast<float>(ball_cap_m * ball_cap_m));
  bool ball_known = true;
  int top = 0;
  push_walk(0.0f, 0.0f, 0u, 0, top);  // the root
  while (top > 0) {
    const std::size_t k = static_cast<std::size_t>(--top);
    const WalkEntry e{walk_.t_enter[k], walk_.d_sq[k], walk_.code[k]};
    const bool for_hit = static_cast<double>(e.t_enter) <= q.horizon();
    const bool for_ball = e.d_sq < ball_sq;
    if (!for_hit && !for_ball) continue;
    if (e.code & kWideLeaf) {  // pushed for the hit only: its distance was taken for the ball when its node was opened
      wide_test_item(q, e.code & ~kWideLeaf);
      continue;
    }
    if (!q.spend_wide_node()) {
      ball_known = false;
      if (for_hit && e.t_enter < q.unresolved_t) {
        q.unresolved_t = e.t_enter;
        q.unresolved_node = kWideEmpty;
      }
      continue;
    }
    const WideNode& n = wi.nodes[e.code];
    float t_enter[4], d_sq[4];
    const double h = q.horizon();
    const int hit_mask = sweep_node(n, ax, ay, ix, iy, h > 1.0 ? 1.0f : float_at_least(h), t_enter);
    const int near_mask = near_node(n, bx, by, ball_sq, d_sq);
    const int base = top;
    for (int i = 0; i < 4; ++i) {
      const int bit = 1 << i;
      if (!((hit_mask | near_mask) & bit)) continue;
      const bool leaf = (n.child[i] & kWideLeaf) != 0;
      if (leaf && d_sq[i] < ball_sq) {  // an item's rectangle: its distance is final, the ball shrinks at once
        ball_sq = d_sq[i];
        wide_ball_seed_ = e.code << 2 | static_cast<std::uint32_t>(i);
      }
      if (leaf && !(hit_mask & bit)) continue;
      if (!push_walk((hit_mask & bit) ? t_enter[i] : std::numeric_limits<float>::infinity(), d_sq[i], n.child[i], base, top)) {  // full: as past the budget
        ball_known = false;
        if (e.t_enter < q.unresolved_t) {
          q.unresolved_t = e.t_enter;
          q.unresolved_node = kWideEmpty;
        }
        top = base;
        break;
      }
    }
  }
  if (!ball_known) return 0.0;
  // The float distances bound the padded rectangles' from below up to a few ulps; the factor keeps the
  // ball strictly inside what the exact rectangles allow.
  return std::sqrt(static_cast<double>(ball_sq)) * (1.0 - 1e-6);
}

// The ball's first bound: the squared distance from (bx, by) to the item rectangle nearest to the last
// walk's end (a real rectangle, so an upper bound on the nearest one's, and pruning at it from the root
// down opens fewer nodes; the hand moves little between ticks), computed as near_node computes it, or
// cap_sq when there is no such rectangle or it is farther.
float BoundarySection::seeded_ball_sq(const WideIndex& wi, float bx, float by, float cap_sq) const noexcept {
  if (wide_ball_seed_ == kWideEmpty) return cap_sq;
  const WideNode& n = wi.nodes[wide_ball_seed_ >> 2];
  const std::uint32_t i = wide_ball_seed_ & 3u;
  const float dx = std::max(std::max(n.lo_x[i] - bx, bx - n.hi_x[i]), 0.0f);
  const float dy = std::max(std::max(n.lo_y[i] - by, by - n.hi_y[i]), 0.0f);
  return std::min(dx * dx + dy * dy, cap_sq);
}

SweepHit BoundarySection::first_hit_wide(Vec2 a, Vec2 b, int level, const SegmentRef* excluded, int excluded_count,
                                         QueryBudget& budget, QueryStats* stats_out) {
  level = walls_of(level);
  if (is_cut_level(level)) {  // not walked here (first_hit walks cuts): nothing is proven clear, never guess
    if (stats_out) *stats_out = QueryStats{};
    SweepHit none;
    none.blocked = true;
    none.t = 0.0;
    none.point_m = a;
    none.segment = SegmentRef{-1, Scene::kMaxLevels, -1};
    return none;
  }
  if (!wide_serves(level)) return first_hit_tree(a, b, level, excluded, excluded_count, budget, stats_out);
  const double r_sq = wide_ball_radius_m_ * wide_ball_radius_m_;
  if (length_sq(a - wide_ball_center_m_) < r_sq && length_sq(b - wide_ball_center_m_) < r_sq) {
    if (stats_out) *stats_out = QueryStats{};
    SweepHit clear;
    clear.point_m = b;
    return clear;
  }
  Query q(a, b, level, excluded, excluded_count, budget);
  const double ball_m = wide_walk(q, kWideBallCap_m);
  const bool clear = !q.best.hit && q.unresolved_t == std::numeric_limits<double>::infinity();
  wide_ball_center_m_ = b;
  wide_ball_radius_m_ = clear ? ball_m : 0.0;
  const SweepHit answer = finish(q);
  q.st.section_size = 0;
  if (stats_out) *stats_out = q.st;
  return answer;
}

// first_hit_wide at a level id coarser than the wide index's items: the descent of first_hit's phase 2 from the
// scene root, with no section and no ball (refine_candidates: nearest box first, pruned past the best hit, one
// optional box test per box). Past the budget the answer is blocked at the nearest box left unrefined, named as
// first_hit names it (finish).
SweepHit BoundarySection::first_hit_tree(Vec2 a, Vec2 b, int level, const SegmentRef* excluded, int excluded_count,
                                         QueryBudget& budget, QueryStats* stats_out) {
  const Scene& sc = *scene_;
  Query q(a, b, level, excluded, excluded_count, budget);
  candidates_.clear();
  if (sc.curve_count() > 0) {
    const std::uint32_t root = sc.scene_root();
    double te = 0.0, tx = 0.0;
    if (!q.spend_box()) {
      q.unresolved_t = 0.0;  // nothing proven clear
      q.unresolved_node = root;
    } else if (clip_segment_box(sc.box(root), a, b, 0.0, &te, &tx)) {
      candidates_.push_back({te, root, kNotAnEntry});
    }
  }
  refine_candidates(q);
  const SweepHit answer = finish(q);
  q.st.section_size = 0;
  if (stats_out) *stats_out = q.st;
  return answer;
}

// What a ball tick (a → b answered by the free-space ball or its walls) does to the section: the merge checks full
// queries left owed, while some are (merge_on_ball_tick), counted in *stats (box_tests, merges) with the section's
// size after them.
inline void BoundarySection::pay_merge_debt(Vec2 a, Vec2 b, QueryBudget& budget, QueryStats* stats) noexcept {
  QueryStats unused;
  if (merge_debt_ > 0) merge_on_ball_tick(a, b, budget, stats ? *stats : unused);
  if (stats) stats->section_size = static_cast<std::int32_t>(section_.size());
}

SweepHit BoundarySection::first_hit(Vec2 a, Vec2 b, int level, const SegmentRef* excluded, int excluded_count,
                                    QueryBudget& budget, QueryStats* stats_out) {
  level = walls_of(level);
  if (level != last_level_ || level != other_level_) follow_level(level);  // else it serves this id alone, as before
  if (inside_free_ball(a, b)) {
    if (stats_out) *stats_out = QueryStats{};
    pay_merge_debt(a, b, budget, stats_out);
    SweepHit clear;
    clear.point_m = b;
    return clear;
  }
  return first_hit_near_walls(a, b, level, excluded, excluded_count, budget, stats_out);
}

// first_hit past its free-space ball: the ball's walls, else a full query. Out of line, so the ball's answer (most
// ticks) does not pay this part's stack frame and saved registers.
[[gnu::noinline]] SweepHit BoundarySection::first_hit_near_walls(Vec2 a, Vec2 b, int level, const SegmentRef* excluded,
                                                                 int excluded_count, QueryBudget& budget, QueryStats* stats_out) {
  SweepHit near;
  if (answer_from_ball_walls(a, b, level, excluded, excluded_count, &near, stats_out)) {
    pay_merge_debt(a, b, budget, stats_out);  // a ball tick too
    return near;
  }
  Query q(a, b, level, excluded, excluded_count, budget);
  next_tick();
  clip_section(q);
  refine_candidates(q);
  gather_ball_walls(q);  // before the section changes: it reads the entries as phase 1 scanned them
  split_hit_boxes(q);
  merge_idle_siblings(q);
  clear_marks();
  place_free_ball(q);
  const SweepHit answer = finish(q);
  if (stats_out) *stats_out = q.st;
  return answer;
}

namespace {

// Larger than every real segment reference: "no answer yet".
constexpr SegmentRef kNoSegment{std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::max(),
                                std::numeric_limits<std::int32_t>::max()};

}  // namespace

// The best closest-point answer so far of one call, its pruning bound, and where to write the answer.
struct BoundarySection::ClosestQuery {
  Vec2 p;
  int level = 0;
  int curve = -1;
  double best_m = 0.0;      // distance of the best answer so far, or max_distance_m before there is one [m]
  double bound_sq = 0.0;    // best_m² grown by a few ulps: rounding never prunes what best_m itself would keep [m²]
  float bound_sq_f = 0.0f;  // bound_sq as a float no smaller, for the SIMD rectangle tests [m²]
  SegmentRef best_s = kNoSegment;
  std::uint32_t best_node = kWideEmpty;
  Vec2 best_point;
  const int* skip = nullptr;  // curves left out of the answer (skip_count of them)
  int skip_count = 0;
  ClosestQuery(Vec2 p_in, int level_in, int curve_in, double max_distance_m, const int* skip_in = nullptr, int skip_count_in = 0)
      : p(p_in), level(level_in), curve(curve_in), skip(skip_in), skip_count(skip_count_in) { set_best(max_distance_m); }
  void set_best(double d_m) {
    best_m = d_m;
    bound_sq = d_m * d_m * (1.0 + 1e-12);
    bound_sq_f = float_at_least(bound_sq);
  }
  bool found() const { return best_node != kWideEmpty; }
  // Whether curve c is left out (a short scan: the callers skip a handful).
  bool skips(std::uint32_t c) const {
    for (int i = 0; i < skip_count; ++i) {
      if (static_cast<std::uint32_t>(skip[i]) == c) return true;
    }
    return false;
  }
};

// Offers segment node `node` (end points a, b) to the query: taken when nearer than the best so far, or as
// near with the smaller (curve, level, segment). The caller has checked that the end points' rectangle
// is within the bound (rect_within_bound), perhaps before the bound last shrank: the exact distance is
// compared with the bound as it is now. The segment's reference is looked up only where it decides a
// tie or wins. Inlined: it runs several times a call.
[[gnu::always_inline]] inline void BoundarySection::closest_offer(ClosestQuery& q, std::uint32_t node, Vec2 a, Vec2 b) const noexcept {
  const Vec2 p = q.p;
  const Vec2 c = closest_point_on_segment(p, a, b);
  const double d_sq = length_sq(p - c);
  if (d_sq > q.bound_sq) return;
  const double d = std::sqrt(d_sq);  // bit for bit distance(p, c)
  if (d > q.best_m) return;
  const NodeInfo in = scene_->info(node);
  if (q.skip_count > 0 && q.skips(in.curve)) return;
  const SegmentRef ref{static_cast<std::int32_t>(in.curve), in.level, static_cast<std::int32_t>(in.index)};
  if (!closer(d, ref, q.best_m, q.best_s)) return;
  q.set_best(d);
  q.best_s = ref;
  q.best_node = node;
  q.best_point = c;
}

namespace {

// True when the rectangle of a and b comes within sqrt(bound_sq) of p: a lower bound on the segment's
// distance, without a division.
inline bool rect_within_bound(Vec2 p, Vec2 a, Vec2 b, double bound_sq) {
  const double rx = std::max({std::min(a.x, b.x) - p.x, 0.0, p.x - std::max(a.x, b.x)});
  const double ry = std::max({std::min(a.y, b.y) - p.y, 0.0, p.y - std::max(a.y, b.y)});
  return rx * rx + ry * ry <= bound_sq;
}

// rect_within_bound for the two segments s[0]→s[1] and s[1]→s[2] at once (SSE2, the same operations in
// double, so the same answers): bit 0 for the first, bit 1 for the second.
inline int rects_within_bound2(const Vec2* s, Vec2 p, double bound_sq) {
#if defined(__SSE2__)
  const __m128d p0 = _mm_loadu_pd(&s[0].x), p1 = _mm_loadu_pd(&s[1].x), p2 = _mm_loadu_pd(&s[2].x);
  const __m128d ax = _mm_unpacklo_pd(p0, p1), ay = _mm_unpackhi_pd(p0, p1);
  const __m128d bx = _mm_unpacklo_pd(p1, p2), by = _mm_unpackhi_pd(p1, p2);
  const __m128d px = _mm_set1_pd(p.x), py = _mm_set1_pd(p.y), zero = _mm_setzero_pd();
  const __m128d rx = _mm_max_pd(_mm_max_pd(_mm_sub_pd(_mm_min_pd(ax, bx), px), _mm_sub_pd(px, _mm_max_pd(ax, bx))), zero);
  const __m128d ry = _mm_max_pd(_mm_max_pd(_mm_sub_pd(_mm_min_pd(ay, by), py), _mm_sub_pd(py, _mm_max_pd(ay, by))), zero);
  const __m128d r2 = _mm_add_pd(_mm_mul_pd(rx, rx), _mm_mul_pd(ry, ry));
  return _mm_movemask_pd(_mm_cmple_pd(r2, _mm_set1_pd(bound_sq)));
#else
  return (rect_within_bound(p, s[0], s[1], bound_sq) ? 1 : 0) | (rect_within_bound(p, s[1], s[2], bound_sq) ? 2 : 0);
#endif
}

}  // namespace

// The seed: the previous call's answer, measured again at the new point, when that call was for the same
// level and curve. A real candidate, so the walk's bound is tight from the root down; the hand moves
// little between ticks, so it is nearly always the answer again or within a few of it.
void BoundarySection::closest_seed(ClosestQuery& q) const noexcept {
  if (last_closest_node_ == kWideEmpty || last_closest_level_ != q.level || last_closest_curve_ != q.curve) return;
  Vec2 a, b;
  scene_->segment_points(last_closest_node_, &a, &b);
  closest_offer(q, last_closest_node_, a, b);
}

// At an item of the walk: offers the target level's segments under it.
void BoundarySection::closest_test_item(ClosestQuery& q, std::uint32_t item) noexcept {
  const Scene& sc = *scene_;
  if (q.curve >= 0 && static_cast<int>(sc.tag_curve(item)) != q.curve) return;
  if (q.skip_count > 0 && q.skips(sc.tag_curve(item))) return;
  std::uint32_t first = 0;
  const std::uint32_t count = item_segments(item, q.level, &first);
  // The segments under an item are consecutive slots: their rectangles two at a time, then the exact
  // distance of those within the bound (which may shrink on the way).
  const Vec2* s = sc.slot_points(first);
  std::uint32_t i = 0;
  for (; i + 1 < count; i += 2) {
    const int mask = rects_within_bound2(s + i, q.p, q.bound_sq);
    if (mask & 1) closest_offer(q, first + i, s[i], s[i + 1]);
    if (mask & 2) closest_offer(q, first + i + 1, s[i + 1], s[i + 2]);
  }
  if (i < count && rect_within_bound(q.p, s[i], s[i + 1], q.bound_sq)) closest_offer(q, first + i, s[i], s[i + 1]);
}

// Opens node n for the closest-point walk: *next is its nearest child within the bound (kWideEmpty when
// none is), and the others within it are pushed. False, with *top as it was, when the stack is full.
[[gnu::always_inline]] inline bool BoundarySection::closest_open_node(const ClosestQuery& q, const WideNode& n, float px, float py, int* top,
                                                                      std::uint32_t* next) noexcept {
  float d_sq[4];
  const int mask = near_node(n, px, py, q.bound_sq_f, d_sq);
  *next = kWideEmpty;
  if (mask == 0) return true;
  const int base = *top;
  for (int i = 0; i < 4; ++i) {
    if (!(mask & (1 << i))) continue;
    if (!push_walk(std::numeric_limits<float>::infinity(), d_sq[i], n.child[i], base, *top)) {
      *top = base;
      return false;
    }
  }
  *next = walk_.code[static_cast<std::size_t>(--*top)];  // pushed nearest last: on top
  return true;
}

// The next entry of the closest-point walk still within the bound, taken off the stack; kWideEmpty when
// none is left.
[[gnu::always_inline]] inline std::uint32_t BoundarySection::closest_pop(const ClosestQuery& q, int* top) const noexcept {
  while (*top > 0) {
    const std::size_t k = static_cast<std::size_t>(--*top);
    if (static_cast<double>(walk_.d_sq[k]) <= q.bound_sq) return walk_.code[k];
  }
  return kWideEmpty;
}

// The walk of the wide index: depth first, nearest rectangle first, pruned at the best distance so far
// (which only shrinks). At a node the nearest child within the bound is entered at once and the others
// are pushed, farthest first, for later. False when the budget or the stack ran out (the answer is then
// unknown).
bool BoundarySection::closest_walk(ClosestQuery& q, QueryBudget* budget) noexcept {
  const WideIndex& wi = scene_->wide_index();
  if (wi.nodes.empty()) return true;
  const float px = static_cast<float>(q.p.x), py = static_cast<float>(q.p.y);
  int top = 0;
  std::uint32_t code = 0u;  // the entry being visited: the root first
  for (;;) {
    if (code & kWideLeaf) {
      closest_test_item(q, code & ~kWideLeaf);
    } else if (budget && !budget->spend(kWideBoxTestsPerNode)) {
      return false;  // the caller sees budget->ran_out
    } else if (!closest_open_node(q, wi.nodes[code], px, py, &top, &code)) {
      if (budget) budget->ran_out = true;  // the stack is full: the answer is unknown, as past the budget
      return false;
    } else if (code != kWideEmpty) {
      continue;  // the nearest child, entered at once
    }
    code = closest_pop(q, &top);
    if (code == kWideEmpty) return true;
  }
}

bool BoundarySection::closest_point(Vec2 p, int level, double max_distance_m, Vec2* point_out, SegmentRef* segment_out, int curve,
                                    QueryBudget* budget, const int* skip_curves, int skip_count) {
  level = walls_of(level);
  if (is_cut_level(level)) {
    return closest_point_cut(p, level - kCutLevelBase, max_distance_m, point_out, segment_out, curve, budget, skip_curves, skip_count);
  }
  if (scene_->curve_count() == 0) return false;
  ClosestQuery q(p, level, curve, max_distance_m, skip_curves, skip_count);
  closest_seed(q);
  const bool complete = wide_serves(level) ? closest_walk(q, budget) : closest_tree_walk(q, budget);
  last_closest_level_ = level;
  last_closest_curve_ = curve;
  last_closest_node_ = complete ? q.best_node : kWideEmpty;
  if (!complete || !q.found()) return false;
  if (point_out) *point_out = q.best_point;
  if (segment_out) *segment_out = q.best_s;
  return true;
}

// ---- Closest points at a tolerance cut (the tree of error boxes) ----

// The walk of the tree of error boxes for closest points, from the scene root: depth first, nearest box first,
// pruned at the best distance so far (branch and bound, as closest_walk). Each box's distance bounds every wall
// under it from below: a level's segments (a box holds everything finer) and a cut's joined pieces (each inside its
// own segment's box, tolerance_cut.hpp). Stops at the walls of q.level (at_target), offering each, joined at a cut
// step. With a `budget`, each box measured is one optional box test; false when it or the stack ran out (the
// answer is then unknown, budget->ran_out set).
bool BoundarySection::closest_tree_walk(ClosestQuery& q, QueryBudget* budget) noexcept {
  const Scene& sc = *scene_;
  const Vec2 p = q.p;
  const int curve = q.curve;
  // A node of another curve than `curve`, or of a skipped one, holds nothing to answer (a hierarchy node may: kept).
  const auto other_curve = [&sc, &q, curve](std::uint32_t node) {
    if (curve < 0 && q.skip_count == 0) return false;
    std::uint32_t c = 0;
    if (sc.is_segment(node)) {
      c = sc.tag_curve(node);
    } else if (sc.is_chunk(node)) {
      c = sc.info(node).curve;
    } else {
      return false;
    }
    return (curve >= 0 && c != static_cast<std::uint32_t>(curve)) || q.skips(c);
  };
  int top = 0;
  stack_[static_cast<std::size_t>(top++)] = Candidate{0.0, sc.scene_root(), kNotAnEntry};  // t_enter: the box's squared distance [m²]
  while (top > 0) {
    const Candidate cur = stack_[static_cast<std::size_t>(--top)];
    if (cur.t_enter > q.bound_sq) continue;  // the bound shrank since it was pushed
    if (at_target(cur.node, q.level)) {
      Vec2 a, b;
      wall_node_points(cur.node, q.level, &a, &b);
      closest_offer(q, cur.node, a, b);
      continue;
    }
    std::uint32_t first = 0, count = 0;
    sc.children(cur.node, &first, &count);
    const int base = top;
    for (std::uint32_t i = 0; i < count; ++i) {
      const std::uint32_t child = first + i;
      if (other_curve(child)) continue;
      if (rect_distance_sq(sc.loose_aabb(child), p) > q.bound_sq) continue;  // the rectangle holds the box: a cheaper lower bound
      if (budget && !budget->spend()) return false;
      const double d_sq = box_distance_sq(sc.box(child), p);
      if (d_sq > q.bound_sq) continue;
      if (!push(top, Candidate{d_sq, child, kNotAnEntry})) {  // full (never, within the tree's depth): the answer is unknown
        if (budget) budget->ran_out = true;
        return false;
      }
    }
    std::sort(stack_.begin() + base, stack_.begin() + top, [](const Candidate& x, const Candidate& y) { return x.t_enter > y.t_enter; });
  }
  return true;
}

bool BoundarySection::closest_point_cut(Vec2 p, int step, double max_distance_m, Vec2* point_out, SegmentRef* segment_out, int curve,
                                        QueryBudget* budget, const int* skip_curves, int skip_count) {
  if (!has_cuts()) {
    return closest_point(p, kToleranceLevelBase + step, max_distance_m, point_out, segment_out, curve, budget, skip_curves, skip_count);
  }
  const Scene& sc = *scene_;
  if (sc.curve_count() == 0) return false;
  ClosestQuery q(p, kCutLevelBase + step, curve, max_distance_m, skip_curves, skip_count);
  if (!closest_tree_walk(q, budget)) return false;
  if (!q.found()) return false;
  if (point_out) *point_out = q.best_point;
  if (segment_out) *segment_out = q.best_s;
  return true;
}

}  // namespace hk
