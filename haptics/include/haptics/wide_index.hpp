#pragma once
/// @file wide_index.hpp
/// A spatial 4-wide bounding-volume hierarchy over the collision tree (wide
/// nodes with SIMD box tests). The curve-following tree of error boxes (seed §3) is fat at the top: a
/// chunk of coarsest segments spans hundreds of level-0 segments and its box overlaps its neighbours', so a
/// walk from the root opens many boxes before it gets near the handle. This index sorts the error boxes
/// of one fine level, the item level, by place instead, four to a node, and a walk tests a node's four
/// child rectangles at once.
///
/// Items. One item per segment of level kWideItemLevel of every curve (a curve with fewer levels: its
/// coarsest, wide_item_level). An item's rectangle is its segment's error box's, which holds every finer
/// level's points and the original under it (scene.hpp), and so every segment of the item level or finer
/// under it. So the polylines of every level at or below the items lie in the union of the item rectangles:
/// a walk that opens every rectangle the sweep (or a ball) meets finds every segment of such a level it meets,
/// and at an item tests the segments of the target level under it (at most 2^kWideItemLevel). Coarser levels
/// (a sixteenth of the segments or fewer) are not held: their chords cut across the shapes, and rectangles
/// grown to hold them were 2.4x the area on the tiled benchmark scenes and up to 4.4x on the silhouettes
/// (docs/PERFORMANCE.md, "Why silhouette_6 walks"), widening every prune at the fine levels the servo feels.
/// BoundarySection walks the tree of error boxes for those levels instead.
///
/// Storage. Rectangles are floats rounded outward and grown by a pad of 1 nm + 2⁻¹⁸·(largest
/// coordinate), so float tests, with their rounding, never miss what the exact rectangle holds.
/// Nodes are laid out depth first. A node cuts its items into four runs along the longer axis of their
/// centres (twice: the whole, then each half), in sizes that fill subtrees completely, so nearly every node
/// is full; a node of at most four items takes them in the order they come (walks order a node's slots by
/// distance). A leaf is a child slot that names one item's segment node directly. With an item every 8
/// level-0 segments and a node per ~3 items, the index adds ~3.4 bytes per level-0 segment.

#include <cstdint>
#include <vector>

#include "hk/vec2.hpp"

namespace hk {

class Scene;

/// The level whose error boxes are the index's items (clamped per curve to its coarsest).
inline constexpr int kWideItemLevel = 3;
/// The item level of a curve with `curve_levels` levels (levels 0 … curve_levels − 1): kWideItemLevel, or its
/// coarsest when it has fewer.
constexpr int wide_item_level(int curve_levels) {
  return curve_levels - 1 < kWideItemLevel ? curve_levels - 1 : kWideItemLevel;
}
/// Box tests a walk charges to its QueryBudget per wide node it opens: one per child rectangle.
inline constexpr std::int32_t kWideBoxTestsPerNode = 4;

/// One node: its four children's rectangles [m], structure of arrays so that one SSE instruction tests
/// all four, and what each child is. 80 bytes.
struct alignas(16) WideNode {
  float lo_x[4], lo_y[4], hi_x[4], hi_y[4];  ///< child rectangles [m]; an empty slot is the point (1e30, 1e30)
  std::uint32_t child[4];                    ///< kWideLeaf | segment node of an item; a node index; or kWideEmpty
};
static_assert(sizeof(WideNode) == 80, "WideNode: 80 bytes");

inline constexpr std::uint32_t kWideLeaf = 1u << 31;      ///< child code flag: the slot is an item
inline constexpr std::uint32_t kWideEmpty = 0xffffffffu;  ///< child code of an empty slot (never entered)

/// The index of one scene. Built once with the scene, read-only after.
struct WideIndex {
  std::vector<WideNode> nodes;  ///< depth first; node 0 is the root (empty for a scene without curves)
  int depth = 0;                ///< nodes on the longest path from the root to a leaf's node

  /// Entries a walk's stack needs: three children left behind per level descended, plus the four of the last.
  std::size_t stack_entries() const { return static_cast<std::size_t>(depth) * 3 + 8; }
  /// Bytes of the nodes.
  std::size_t bytes() const { return nodes.size() * sizeof(WideNode); }
  /// The rectangle of node w [m]: the union of its slots' (empty slots left out), so it holds every item under
  /// it. Writes lo and hi; w < nodes.size().
  void node_rect(std::uint32_t w, Vec2* lo, Vec2* hi) const noexcept;
  /// Builds the index of `scene`'s curves (its segments, boxes and levels must be final). Throws
  /// std::bad_alloc only.
  static WideIndex build(const Scene& scene);
};

}  // namespace hk
