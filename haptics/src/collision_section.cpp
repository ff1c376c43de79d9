// The boundary section's storage and its edits: construction, reset, entries put in and taken out, the
// frontier's hierarchy (tree nodes and wide index nodes), splits and merges of entries (seed paper §3).
#include <string>

#include "collision_query_internal.hpp"
#include "hk/error.hpp"

namespace hk {

BoundarySection::BoundarySection(const Scene& scene, double merge_margin_m, bool cut_walls)
    : BoundarySection(scene, merge_margin_m, cut_walls ? make_cut_walls(scene) : nullptr) {}

BoundarySection::BoundarySection(const Scene& scene, double merge_margin_m, std::shared_ptr<const CutWalls> cuts)
    : scene_(&scene), merge_margin_m_(merge_margin_m), cuts_(std::move(cuts)) {
  if (cuts_ && cuts_->scene != &scene)
    throw hk::ArgumentError("BoundarySection: the cut walls were made for another scene");
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
    throw hk::ArgumentError("BoundarySection: a scene node has " + std::to_string(widest_root) +
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
  if (ids >= kNoParent)
    throw hk::ArgumentError("BoundarySection: the scene's nodes and wide nodes exceed 32-bit section ids");
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
  Ops::link_wide_nodes(*this);
  // The level ids whose walls the wide index holds: those at which every curve is at or below its item level.
  for (int id = 0; id < kCutLevelBase; ++id) {
    bool served = true;
    for (std::size_t c = 0; c < scene.curve_count() && served; ++c)
      served = scene.clamp_level(c, id) <= wide_item_level(scene.curve(c).levels);
    wide_serves_[static_cast<std::size_t>(id)] = served;
  }
  reset();
}

std::size_t BoundarySection::bytes() const noexcept {
  const auto of = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  return of(section_) + of(section_parent_) + of(section_rect_.lo_x) + of(section_rect_.lo_y) + of(section_rect_.hi_x) +
         of(section_rect_.hi_y) + of(rect_d_sq_) + of(rect_overlap_bits_) + of(rect_near_bits_) + of(node_state_) +
         of(marked_) + of(candidates_) + of(stack_) + of(walk_.t_enter) + of(walk_.d_sq) + of(walk_.code) +
         of(wide_up_) + of(item_up_) + of(item_first_);
}

void BoundarySection::reset() noexcept {
  last_closest_node_ = kWideEmpty;  // a reset section answers like a new one, box test for box test
  for (std::size_t i = 0; i < section_.size(); ++i) {
    Ops::clear_state(*this, section_[i], kInSection);
    // Only a section node's parent counts any children in.
    if (section_parent_[i] != kNoParent) Ops::clear_state(*this, section_parent_[i], kChildrenInMask);
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
  Ops::push_section(*this, wide_mode_ ? wide_base_ : scene_->scene_root(), kNoParent);
}

void BoundarySection::Ops::push_section(BoundarySection& self, std::uint32_t node, std::uint32_t parent) noexcept {
  self.section_.push_back(node);  // within the reserved capacity: no allocation
  set_section_entry(self, self.section_.size() - 1, node, parent);
}

// Puts node in the section at `entry` in place of the entry's node, with its rectangle, and marks it in and
// counted among its parent's children in (`parent`: Scene::parent(node), or kNoParent for the root). The caller
// marks the node it replaces out (mark_out).
void BoundarySection::Ops::set_section_entry(BoundarySection& self, std::size_t entry, std::uint32_t node,
                                             std::uint32_t parent) noexcept {
  self.section_rect_.set(entry, entry_rect(self, node));
  place_entry(self, entry, node, parent);
}

// set_section_entry but for the rectangle, which the caller stores.
void BoundarySection::Ops::place_entry(BoundarySection& self, std::size_t entry, std::uint32_t node,
                                       std::uint32_t parent) noexcept {
  self.section_[entry] = node;
  self.section_parent_[entry] = parent;
  self.node_state_[node] |= kInSection;
  // The count stays within its bits: at most the widest fan-out, checked at construction.
  if (parent != kNoParent)
    self.node_state_[parent] = static_cast<std::uint8_t>(self.node_state_[parent] + kChildInUnit);
}

// The parent of section id `node` in the frontier's hierarchy, or kNoParent for its root. The tree's: Scene::parent
// (the scene root's parent is itself). The wide frontier's: a wide node's is the wide node naming it, an item's the
// wide node whose slot names it, below the items Scene::parent.
std::uint32_t BoundarySection::Ops::parent_or_none(const BoundarySection& self, std::uint32_t node) noexcept {
  const Scene& sc = *self.scene_;
  if (self.wide_mode_) {
    if (is_wide_id(self, node)) {
      const std::uint32_t up = self.wide_up_[node - self.wide_base_];
      return up == kNoParent ? kNoParent : self.wide_base_ + (up >> 2);
    }
    const std::uint32_t c = sc.tag_curve(node);
    const CurveNodes& cn = sc.curve_nodes(c);
    const int item = wide_item_level(static_cast<int>(cn.levels));
    if (sc.tag_level(node) == item)
      return self.wide_base_ + (self.item_up_[self.item_first_[c] + (node - cn.box_offset[item])] >> 2);
  }
  return node == sc.scene_root() ? kNoParent : sc.parent(node);
}

// The wide frontier's links (wide_up_, item_up_, item_first_) and the root's rectangle, from the index. O(wide nodes).
void BoundarySection::Ops::link_wide_nodes(BoundarySection& self) {
  const Scene& sc = *self.scene_;
  const WideIndex& wi = sc.wide_index();
  self.item_first_.assign(sc.curve_count(), 0);
  std::uint32_t items = 0;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {  // items numbered curve by curve
    self.item_first_[c] = items;
    items += sc.curve(c).segment_count[wide_item_level(sc.curve(c).levels)];
  }
  self.item_up_.assign(items, kNoParent);
  self.wide_up_.assign(wi.nodes.size(), kNoParent);
  if (!wi.nodes.empty()) wi.node_rect(0, &self.wide_root_rect_.lo, &self.wide_root_rect_.hi);
  for (std::uint32_t w = 0; w < wi.nodes.size(); ++w) {
    const WideNode& nd = wi.nodes[w];
    for (std::uint32_t i = 0; i < 4; ++i) {
      const std::uint32_t code = nd.child[i];
      if (code == kWideEmpty) continue;
      if (code & kWideLeaf) {
        const std::uint32_t item = code & ~kWideLeaf;
        const std::uint32_t c = sc.tag_curve(item);
        const std::uint32_t k = item - sc.curve_nodes(c).box_offset[sc.tag_level(item)];
        self.item_up_[self.item_first_[c] + k] = w << 2 | i;
      } else {
        self.wide_up_[code] = w << 2 | i;
      }
    }
  }
}

// The rectangle of section id `id` [m]: a wide node's, its slot's in its parent (the root's, its slots' union); a
// scene node's, Scene::aabb.
Aabb BoundarySection::Ops::entry_rect(const BoundarySection& self, std::uint32_t id) noexcept {
  if (!is_wide_id(self, id)) return self.scene_->aabb(id);
  const std::uint32_t up = self.wide_up_[id - self.wide_base_];
  if (up == kNoParent) return self.wide_root_rect_;
  const WideNode& n = self.scene_->wide_index().nodes[up >> 2];
  const std::uint32_t i = up & 3u;
  return Aabb{{n.lo_x[i], n.lo_y[i]}, {n.hi_x[i], n.hi_y[i]}};
}

// The children of section id `id` in the frontier's hierarchy, written to out (at most kMaxEntryChildren); returns
// their count. A wide node's: its slots' wide nodes and items, empty slots left out; a scene node's: Scene::children
// (the wide frontier never holds a scene node above the items).
std::uint32_t BoundarySection::Ops::entry_children(const BoundarySection& self, std::uint32_t id,
                                                   std::uint32_t* out) noexcept {
  if (is_wide_id(self, id)) {
    const WideNode& nd = self.scene_->wide_index().nodes[id - self.wide_base_];
    std::uint32_t count = 0;
    for (std::uint32_t code : nd.child) {
      if (code == kWideEmpty) continue;
      out[count++] = wide_child_id(self, code);
    }
    return count;
  }
  std::uint32_t first = 0, count = 0;
  self.scene_->children(id, &first, &count);
  for (std::uint32_t i = 0; i < count; ++i) out[i] = first + i;
  return count;
}

// Takes the entry out: the last entry moves into its place (the order of entries is no answer's business).
void BoundarySection::Ops::remove_section_entry(BoundarySection& self, std::size_t entry) noexcept {
  const std::size_t last = self.section_.size() - 1;
  if (entry != last) {
    self.section_rect_.copy(entry, last);
    self.section_[entry] = self.section_[last];
    self.section_parent_[entry] = self.section_parent_[last];
  }
  self.section_.pop_back();
}

// Splits the node at section entry `entry` into its children: the first takes its place, the others are
// appended, so no entry is left to drop. Without room the node stays (a box holds its children's walls).
void BoundarySection::Ops::split(BoundarySection& self, std::uint32_t node, std::size_t entry) noexcept {
  if (is_wide_id(self, node)) {
    split_wide(self, node, entry);
    return;
  }
  std::uint32_t first = 0, count = 0;
  self.scene_->children(node, &first, &count);
  if (count == 0 || !in_section(self, node)) return;
  if (self.section_.size() + count + 8 > self.capacity_) return;  // full: keep the node
  mark_out(self, node, self.section_parent_[entry]);
  set_section_entry(self, entry, first, node);
  for (std::uint32_t i = 1; i < count; ++i) push_section(self, first + i, node);
}

// split for a wide node: its slots' wide nodes and items take its place, each with its slot's rectangle (which
// holds it: the slot is its rectangle padded outward, wide_index.hpp), read from the node itself.
void BoundarySection::Ops::split_wide(BoundarySection& self, std::uint32_t node, std::size_t entry) noexcept {
  const WideNode& n = self.scene_->wide_index().nodes[node - self.wide_base_];
  if (!in_section(self, node) || self.section_.size() + 4 + 8 > self.capacity_) return;  // full: keep the node
  mark_out(self, node, self.section_parent_[entry]);
  bool first = true;
  for (int i = 0; i < 4; ++i) {
    const std::uint32_t code = n.child[i];
    if (code == kWideEmpty) continue;
    const std::size_t at = first ? entry : self.section_.size();
    if (!first) self.section_.push_back(0);  // within the reserved capacity: no allocation (place_entry fills it)
    first = false;
    self.section_rect_.set_floats(at, n.lo_x[i], n.lo_y[i], n.hi_x[i], n.hi_y[i]);
    place_entry(self, at, wide_child_id(self, code), node);
  }
}

// Merges the children (count of them) of `parent`, all in the section, one of them at `entry`: the parent takes
// that entry's place and the others' entries are taken out (found by a scan of the section's parents, a few dozen).
// False, with nothing changed, when they are not all found (never, for a frontier) or there are more than
// kMaxSiblings (never: no node has more than 4 children, scene.hpp and wide_index.hpp).
bool BoundarySection::Ops::merge_children(BoundarySection& self, std::size_t entry, std::uint32_t parent,
                                          const std::uint32_t* children, std::uint32_t count) noexcept {
  constexpr std::size_t kMaxSiblings = 15;
  std::size_t sibling_entry[kMaxSiblings];
  std::size_t k = 0;
  for (std::size_t i = 0; i < self.section_.size(); ++i) {
    if (self.section_parent_[i] != parent || i == entry) continue;
    if (k == kMaxSiblings) return false;
    sibling_entry[k++] = i;  // increasing
  }
  if (k + 1 != count) return false;
  for (std::uint32_t i = 0; i < count; ++i) clear_state(self, children[i], kInSection);
  clear_state(self, parent, kChildrenInMask);
  set_section_entry(self, entry, parent, parent_or_none(self, parent));
  while (k > 0) remove_section_entry(self, sibling_entry[--k]);  // highest first: a later one is never the last moved
  return true;
}

// The frontier's parent of an entry, for tests (collision_query.hpp).
std::uint32_t BoundarySection::entry_parent(std::uint32_t id) const noexcept { return Ops::parent_or_none(*this, id); }

}  // namespace hk
