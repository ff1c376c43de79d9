#pragma once
/// @file peer_hit.hpp
/// The answer every peer of the collision tree gives to a first-hit query (bench/support/peers.hpp,
/// bench/support/embree_peer.hpp).

namespace hk::bench {

/// Answer of a peer: hit flag and sweep parameter in [0, 1] (same meaning as hk::SweepHit; t = 1 on a miss).
struct PeerHit {
  bool hit = false;
  double t = 1.0;
};

}  // namespace hk::bench
