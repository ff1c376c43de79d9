// The spatial 4-wide index over the collision tree's item-level error boxes (wide_index.hpp).
#include "haptics/wide_index.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "haptics/float_round.hpp"
#include "haptics/scene.hpp"

namespace hk {
namespace {

// One item while building: its rectangle's centre, its segment node and where its rectangle (exact, in
// double) is in the builder's rectangle array. 24 bytes: the median splits move these, not the rectangles.
struct Item {
  Vec2 centre;
  std::uint32_t node;
  std::uint32_t rect;
};

void extend(Aabb& r, Vec2 p) {
  r.lo = {std::min(r.lo.x, p.x), std::min(r.lo.y, p.y)};
  r.hi = {std::max(r.hi.x, p.x), std::max(r.hi.y, p.y)};
}

Aabb merged(const Aabb& a, const Aabb& b) {
  return Aabb{{std::min(a.lo.x, b.lo.x), std::min(a.lo.y, b.lo.y)},
              {std::max(a.hi.x, b.hi.x), std::max(a.hi.y, b.hi.y)}};
}

class Builder {
 public:
  Builder(std::vector<Item>& items, const std::vector<Aabb>& rects, double pad_m, WideIndex& out)
      : items_(items), rects_(rects), pad_m_(pad_m), out_(out) {}

  // Builds the node over items [begin, end) at `depth`; returns its rectangle. The items are cut into four
  // runs along the longer axis of their centres, in sizes that are multiples of C, the largest power of 4
  // below their count (the last run takes the rest): every run of C items then makes a full subtree, so the
  // nodes are nearly all full, about one per three items. At most four items take a slot each as they lie:
  // a walk orders a node's slots by distance itself, so sorting them would only cost the build.
  Aabb build_node(std::size_t node, std::size_t begin, std::size_t end, int depth) {
    out_.depth = std::max(out_.depth, depth);
    const std::size_t m = end - begin;
    std::size_t run = 1;  // C
    while (run * 4 < m) run *= 4;
    std::size_t cut[5] = {begin, 0, 0, 0, end};
    if (m <= 4) {
      for (std::size_t i = 1; i < 4; ++i) cut[i] = begin + std::min(i, m);
    } else {  // two cuts on the longer axis, then one in each half on the longer axis of that half
      cut[2] = split(begin, end, begin + std::min(m, 2 * run));
      cut[1] = split(begin, cut[2], begin + std::min(cut[2] - begin, run));
      cut[3] = split(cut[2], end, cut[2] + std::min(end - cut[2], run));
    }
    Aabb whole{{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()},
               {-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}};
    for (int i = 0; i < 4; ++i) {
      const std::size_t b = cut[i], e = cut[i + 1];
      if (b == e) {
        set_slot(node, i, Aabb{{1e30, 1e30}, {1e30, 1e30}}, kWideEmpty, 0.0);
        continue;
      }
      Aabb r;
      std::uint32_t code = 0;
      if (e - b == 1) {
        r = rects_[items_[b].rect];
        code = kWideLeaf | items_[b].node;
      } else {
        const std::size_t child = out_.nodes.size();
        out_.nodes.emplace_back();
        r = build_node(child, b, e, depth + 1);
        code = static_cast<std::uint32_t>(child);
      }
      set_slot(node, i, r, code, pad_m_);
      whole = merged(whole, r);
    }
    return whole;
  }

 private:
  // Partial sort of [begin, end) on the longer axis of its centres so that [begin, mid) holds the lowest;
  // returns mid (begin ≤ mid ≤ end).
  std::size_t split(std::size_t begin, std::size_t end, std::size_t mid) {
    if (mid <= begin || mid >= end) return mid;
    Aabb c{items_[begin].centre, items_[begin].centre};
    for (std::size_t i = begin; i < end; ++i) extend(c, items_[i].centre);
    if (c.hi.x - c.lo.x >= c.hi.y - c.lo.y) {  // one comparison per call, not one per pair
      select(begin, end, mid, [](const Item& it) { return it.centre.x; });
    } else {
      select(begin, end, mid, [](const Item& it) { return it.centre.y; });
    }
    return mid;
  }

  // Quickselect: reorders items [begin, end) so that every item before position k has a key at or below
  // the k-th's and every item after it at or above. Each round splits the range around a median-of-three
  // pivot key with branchless partitions (below the pivot, then equal to it; the item at i is swapped in
  // every step and the boundary advances by the comparison's outcome), so the unpredictable comparisons
  // cost no branch mispredictions; a round always removes the pivot's key from one side, so the range
  // shrinks. Short ranges, and any range still long after 64 rounds, finish with std::nth_element.
  template <class Key>
  void select(std::size_t begin, std::size_t end, std::size_t k, Key key) {
    Item* a = items_.data();
    std::size_t lo = begin, hi = end;
    for (int round = 0; hi - lo > 16 && round < 64; ++round) {
      const double p = median_of_three(key(a[lo]), key(a[lo + (hi - lo) / 2]), key(a[hi - 1]));
      const std::size_t below = partition(a, lo, hi, [&](const Item& it) { return key(it) < p; });
      if (k < below) {
        hi = below;
        continue;
      }
      const std::size_t equal = partition(a, below, hi, [&](const Item& it) { return !(p < key(it)); });
      if (k < equal) return;  // position k holds the pivot's key, as do all of [below, equal)
      lo = equal;
    }
    const auto cmp = [&](const Item& x, const Item& y) { return key(x) < key(y); };
    std::nth_element(a + lo, a + k, a + hi, cmp);
  }
  // Moves the items of [lo, hi) that satisfy `first` to its front, without a branch on the outcome;
  // returns the end of those.
  template <class Pred>
  static std::size_t partition(Item* a, std::size_t lo, std::size_t hi, Pred first) {
    std::size_t store = lo;
    for (std::size_t i = lo; i < hi; ++i) {
      const Item x = a[i];
      a[i] = a[store];
      a[store] = x;
      store += first(x) ? 1u : 0u;
    }
    return store;
  }
  static double median_of_three(double x, double y, double z) {
    return std::max(std::min(x, y), std::min(std::max(x, y), z));
  }
  void set_slot(std::size_t node, int i, const Aabb& r, std::uint32_t code, double pad_m) {
    WideNode& n = out_.nodes[node];
    n.lo_x[i] = float_at_most(r.lo.x - pad_m);
    n.lo_y[i] = float_at_most(r.lo.y - pad_m);
    n.hi_x[i] = float_at_least(r.hi.x + pad_m);
    n.hi_y[i] = float_at_least(r.hi.y + pad_m);
    n.child[i] = code;
  }
  std::vector<Item>& items_;
  const std::vector<Aabb>& rects_;
  double pad_m_;
  WideIndex& out_;
};

}  // namespace

void WideIndex::node_rect(std::uint32_t w, Vec2* lo, Vec2* hi) const noexcept {
  const WideNode& n = nodes[w];
  float lx = std::numeric_limits<float>::infinity(), ly = lx, hx = -lx, hy = -lx;
  for (int i = 0; i < 4; ++i) {
    if (n.child[i] == kWideEmpty) continue;
    lx = std::min(lx, n.lo_x[i]);
    ly = std::min(ly, n.lo_y[i]);
    hx = std::max(hx, n.hi_x[i]);
    hy = std::max(hy, n.hi_y[i]);
  }
  *lo = Vec2{lx, ly};
  *hi = Vec2{hx, hy};
}

WideIndex WideIndex::build(const Scene& sc) {
  WideIndex index;
  std::size_t item_count = 0;
  for (std::size_t c = 0; c < sc.curve_count(); ++c)
    item_count += sc.curve(c).segment_count[wide_item_level(sc.curve(c).levels)];
  std::vector<Item> items;
  std::vector<Aabb> rects;
  items.reserve(item_count);
  rects.reserve(item_count);
  double largest = 0.0;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    const int item = wide_item_level(ci.levels);
    for (std::uint32_t k = 0; k < ci.segment_count[item]; ++k) {
      const Aabb r = sc.aabb(ci.box_offset[item] + k);  // the item's error box's rectangle (wide_index.hpp)
      items.push_back(Item{0.5 * (r.lo + r.hi), ci.box_offset[item] + k, static_cast<std::uint32_t>(rects.size())});
      rects.push_back(r);
      largest = std::max(std::max(largest, std::max(std::abs(r.lo.x), std::abs(r.lo.y))),
                         std::max(std::abs(r.hi.x), std::abs(r.hi.y)));
    }
  }
  if (items.empty()) return index;
  const double pad_m = 1e-9 + std::ldexp(largest, -18);
  index.nodes.reserve(items.size() / 3 + 64);
  index.nodes.emplace_back();
  Builder builder(items, rects, pad_m, index);
  // One item builds a root with three empty slots and a leaf.
  builder.build_node(0, 0, items.size(), 1);
  index.nodes.shrink_to_fit();
  return index;
}

}  // namespace hk
