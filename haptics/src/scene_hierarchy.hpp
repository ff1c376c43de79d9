#pragma once
// The hierarchy above the scene's chunks while it is built: median splits of the chunk centres (scene_hierarchy.cpp).
#include <cstddef>
#include <vector>

#include "hk/vec2.hpp"

namespace hk {
namespace scene_detail {

// One node of the scene hierarchy while it is built: the chunk range it covers in leaf order and,
// for an inner node, the id of its first child (the second is first + 1).
struct HierarchyNode {
  std::size_t begin = 0, end = 0;
  std::size_t first_child = 0;
  bool leaf = true;
};

// Median split on the longer axis of the chunk centres. `order` is permuted in place into leaf order.
// Children of a node are allocated as a consecutive pair, so they have consecutive ids.
void build_hierarchy(std::vector<std::size_t>& order, const std::vector<Vec2>& centre,
                     std::vector<HierarchyNode>& nodes);

}  // namespace scene_detail
}  // namespace hk
