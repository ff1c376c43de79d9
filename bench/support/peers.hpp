#pragma once
// The methods our collision tree is compared with, answering the same queries on the same segments:
// brute force over a flat array, and a Boost.Geometry R-tree (bulk-loaded, R*-style node size 16);
// Embree is the third (embree_peer.hpp).
// First hit = smallest entry parameter among the segments the sweep intersects; closest point =
// the R-tree's `nearest`. Used by bench/first_hit.cpp and by the equal-results tests.
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <boost/iterator/function_output_iterator.hpp>
#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

#include "haptics/collision_query.hpp"
#include "haptics/scene.hpp"
#include "haptics/tolerance_cut.hpp"
#include "peer_hit.hpp"

namespace hk::bench {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;

/// Every segment of `level` (clamped per curve) as a flat array of end-point pairs.
inline std::vector<std::pair<Vec2, Vec2>> flat_segments(const Scene& sc, int level) {
  std::vector<std::pair<Vec2, Vec2>> v;
  v.reserve(sc.total_segments(level));
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const int l = sc.clamp_level(c, level);
    for (std::uint32_t k = 0; k < sc.curve(c).segment_count[l]; ++k) {
      Vec2 a, b;
      sc.segment({static_cast<int>(c), l, static_cast<int>(k)}, &a, &b);
      v.push_back({a, b});
    }
  }
  return v;
}

/// Every piece of the joined tolerance cut at step `step` (kToleranceLadder_m[step]) of every curve, as a flat
/// array of end-point pairs: hk::tolerance_cut, then hk::joined_cut_points, curve by curve (a closed curve's
/// last piece runs back to its first vertex). Built from the cut's own functions, not from the masks that
/// BoundarySection::first_hit walks with at a cut step, so a peer over these checks that walk.
inline std::vector<std::pair<Vec2, Vec2>> cut_segments(const Scene& sc, int step) {
  std::vector<std::pair<Vec2, Vec2>> v;
  std::vector<SegmentRef> cut;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    cut.clear();
    tolerance_cut(sc, c, kToleranceLadder_m[step], &cut);
    const std::vector<Vec2> pts = joined_cut_points(sc, c, cut.data(), cut.size());
    for (std::size_t i = 0; i < cut.size(); ++i) v.push_back({pts[i], pts[(i + 1) % pts.size()]});
  }
  return v;
}

/// Brute force: every segment, every query. Contiguous, branch-light: its best case.
class BruteForce {
 public:
  explicit BruteForce(std::vector<std::pair<Vec2, Vec2>> segs) : segs_(std::move(segs)) {}
  PeerHit first_hit(Vec2 a, Vec2 b) const {
    PeerHit h;
    double best = std::numeric_limits<double>::infinity();
    for (const auto& s : segs_) {
      double t = 0.0;
      if (intersect_sweep_segment(a, b, s.first, s.second, &t) && t < best) best = t;
    }
    if (best <= 1.0) h = {true, best};
    return h;
  }
  double closest_distance(Vec2 p) const {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& s : segs_) best = std::min(best, distance_to_segment(p, s.first, s.second));
    return best;
  }
  std::size_t bytes() const { return segs_.size() * sizeof(segs_[0]); }

 private:
  std::vector<std::pair<Vec2, Vec2>> segs_;
};

/// Counts the bytes an allocator hands out (to report the R-tree's memory per segment).
template <class T>
struct CountingAllocator {
  using value_type = T;
  std::shared_ptr<std::size_t> bytes;
  CountingAllocator() : bytes(std::make_shared<std::size_t>(0)) {}
  template <class U>
  CountingAllocator(const CountingAllocator<U>& o) : bytes(o.bytes) {}
  T* allocate(std::size_t n) {
    *bytes += n * sizeof(T);
    return std::allocator<T>().allocate(n);
  }
  void deallocate(T* p, std::size_t n) {
    *bytes -= n * sizeof(T);
    std::allocator<T>().deallocate(p, n);
  }
  template <class U>
  bool operator==(const CountingAllocator<U>& o) const {
    return bytes == o.bytes;
  }
  template <class U>
  bool operator!=(const CountingAllocator<U>& o) const {
    return bytes != o.bytes;
  }
};

/// Boost.Geometry R-tree over the segments (packing constructor = STR bulk load).
class RtreeIndex {
 public:
  using Point = bg::model::point<double, 2, bg::cs::cartesian>;
  using Segment = bg::model::segment<Point>;
  using Value = std::pair<Segment, std::uint32_t>;
  using Tree = bgi::rtree<Value, bgi::rstar<16>, bgi::indexable<Value>, bgi::equal_to<Value>, CountingAllocator<Value>>;

  explicit RtreeIndex(const std::vector<std::pair<Vec2, Vec2>>& segs) : segs_(segs) {
    std::vector<Value> values;
    values.reserve(segs.size());
    for (std::uint32_t i = 0; i < segs.size(); ++i) {
      values.push_back(
          {Segment(Point(segs[i].first.x, segs[i].first.y), Point(segs[i].second.x, segs[i].second.y)), i});
    }
    tree_ = std::make_unique<Tree>(values.begin(), values.end(), bgi::rstar<16>(), bgi::indexable<Value>(),
                                   bgi::equal_to<Value>(), alloc_);
  }
  /// First hit: every segment `intersects` reports, its entry parameter from the same formula as ours.
  PeerHit first_hit(Vec2 a, Vec2 b) const {
    const Segment q(Point(a.x, a.y), Point(b.x, b.y));
    double best = std::numeric_limits<double>::infinity();
    tree_->query(bgi::intersects(q), boost::make_function_output_iterator([&](const Value& v) {
                   const auto& s = segs_[v.second];
                   double t = 0.0;
                   if (intersect_sweep_segment(a, b, s.first, s.second, &t) && t < best) best = t;
                 }));
    return best <= 1.0 ? PeerHit{true, best} : PeerHit{};
  }
  double closest_distance(Vec2 p) const {
    double best = std::numeric_limits<double>::infinity();
    tree_->query(bgi::nearest(Point(p.x, p.y), 1), boost::make_function_output_iterator([&](const Value& v) {
                   best = distance_to_segment(p, segs_[v.second].first, segs_[v.second].second);
                 }));
    return best;
  }
  std::size_t bytes() const { return *alloc_.bytes; }

 private:
  const std::vector<std::pair<Vec2, Vec2>>& segs_;
  CountingAllocator<Value> alloc_;
  std::unique_ptr<Tree> tree_;
};

}  // namespace hk::bench
