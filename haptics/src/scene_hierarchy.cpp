// The scene hierarchy's build: median splits on the longer axis of the chunk centres, four chunks a leaf.
#include "scene_hierarchy.hpp"

#include <algorithm>

namespace hk {
namespace scene_detail {
namespace {

constexpr std::size_t kChunksPerLeaf = 4;

}  // namespace

void build_hierarchy(std::vector<std::size_t>& order, const std::vector<Vec2>& centre,
                     std::vector<HierarchyNode>& nodes) {
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
    std::nth_element(order.begin() + static_cast<long>(begin), order.begin() + static_cast<long>(mid),
                     order.begin() + static_cast<long>(end), [&](std::size_t a, std::size_t b) {
                       return split_x ? centre[a].x < centre[b].x : centre[a].y < centre[b].y;
                     });
    nodes[i].leaf = false;
    nodes[i].first_child = nodes.size();
    nodes.push_back({begin, mid, 0, true});
    nodes.push_back({mid, end, 0, true});
  }
}

}  // namespace scene_detail
}  // namespace hk
