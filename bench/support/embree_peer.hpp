#pragma once
/// @file embree_peer.hpp
/// Embree 3 as a peer of our collision tree: the same segments in an Embree BVH, queried
/// with the same first-hit and closest-point questions, so its answers can be checked equal and its
/// speed measured on the same streams (bench/first_hit.cpp, tests/haptics/test_peers.cpp).
///
/// Embree has no 2-D segment primitive, so the segments are a user geometry: each one's bounds are a
/// flat 3-D box at z = 0 (grown by a few float ulps, Embree's boxes being float), the sweep a→b is a ray
/// at z = 0 with tnear 0 and tfar 1, and the intersect callback runs our own segment test
/// (`intersect_sweep_segment`, in double, on the double end points) so the answer is bit-identical to
/// brute force's. Closest points use `rtcPointQuery` with the same `distance_to_segment`; the query
/// radius (float) is shrunk to the best distance rounded up, so pruning stays conservative. The scene
/// is built with Embree's robust flag and high build quality, its best single-ray configuration.
///
/// Errors: construction throws std::runtime_error when Embree cannot make a device or commit the
/// scene (with Embree's error text). Queries do not throw; they are not thread-safe on one object.
#include <cstddef>
#include <utility>
#include <vector>

#include "hk/vec2.hpp"
#include "peer_hit.hpp"

namespace hk::bench {

/// Embree BVH over a flat segment array. The array must outlive the index.
class EmbreeIndex {
 public:
  explicit EmbreeIndex(const std::vector<std::pair<Vec2, Vec2>>& segs);
  ~EmbreeIndex();
  EmbreeIndex(const EmbreeIndex&) = delete;
  EmbreeIndex& operator=(const EmbreeIndex&) = delete;

  /// Smallest sweep parameter in [0, 1] at which a→b meets a segment (same rule as BruteForce).
  PeerHit first_hit(Vec2 a, Vec2 b) const;
  /// Distance from p to the nearest segment [m] (infinity for no segments).
  double closest_distance(Vec2 p) const;
  /// Bytes Embree's memory monitor saw allocated for the built scene (its BVH and primitive
  /// references) plus the segment array its callbacks read, as the R-tree's count includes its segments.
  std::size_t bytes() const { return bytes_; }

 private:
  const std::vector<std::pair<Vec2, Vec2>>& segs_;
  void* device_ = nullptr;  // RTCDevice
  void* scene_ = nullptr;   // RTCScene
  std::size_t bytes_ = 0;
};

}  // namespace hk::bench
