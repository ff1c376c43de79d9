#pragma once
/// @file gaps.hpp
/// Closing small gaps in outlines: Canny breaks an object's outline where a highlight or
/// a notch lowers the contrast for a few pixels, and a hand then feels several open strokes where the eye
/// sees one closed shape. Chain ends that face each other across a gap no wider than a fingertip can tell
/// from a join are joined with a straight piece; a real gap, wider than that, stays open.

#include <cstddef>
#include <vector>

#include "vision/linking.hpp"

namespace hk::vision {

/// How close_gaps decides.
struct GapParams {
  double max_gap_px = 0.0;     ///< the widest gap joined [px]; 0 = join nothing. Must be finite and >= 0
  double max_turn_deg = 45.0;  ///< the join may turn from each end's direction by at most this, (0, 90] [deg]
  double direction_span_px =
      6.0;  ///< an end's direction: from the point this far back along the chain to the end [px], > 0
  double min_piece_px =
      0.0;  ///< chains shorter than this are never joined (crumbs of texture are not outlines) [px], >= 0
};

/// What close_gaps did.
struct GapStats {
  std::size_t joins = 0;  ///< gaps bridged
  std::size_t chains_closed =
      0;  ///< chains that came out closed from joining (one chain's two ends, or a ring of several)
};

/// The direction a chain leaves by at one end: the unit vector from the point `span_px` back along the chain
/// (or the far end of a shorter chain) to the end point. `at_start`: the first point's end (pointing out
/// past the first point), else the last point's. (0, 0) for a chain of one point or no extent.
cv::Point2d end_direction(const Chain& c, bool at_start, double span_px);

/// Joins the open chains' ends that face each other across a gap:
/// 1. Candidates: every pair of ends of open chains at least min_piece_px long (two ends of one chain too, if the chain
/// is longer than
///    3 × the gap, so a short stroke is never bent into a loop) at most max_gap_px apart, where the join runs
///    on within max_turn_deg of both ends' directions (end_direction): end a's direction and the join from a
///    to b, and end b's direction and the join from b to a. Ends closer than 1.5 px (adjacent pixels)
///    need only not turn back (within 90°).
/// 2. Greedy, shortest gap first (ties in order of the chains and ends): a join is made when neither end is
///    taken yet; each end joins at most once.
/// 3. The joined chains are walked into new chains, each chain's points in order (reversed where it is
///    entered by its last end), with the gap filled by points on the straight join about 1 px apart; a
///    walk that comes back to where it started is closed.
/// Closed chains and chains with no join pass through unchanged; the output keeps the input's order (a
/// joined chain takes the place of its first member). Values (e.g. edge strength) follow their points; a
/// filled point takes the value interpolated linearly between the two ends'.
/// Source: end-point gap bridging by proximity and good continuation, as in classic edge linkers (e.g.
/// P. Kovesi's edgelink / "linking edge segments" in "MATLAB and Octave Functions for Computer Vision", and
/// the contour completion of R. Nevatia and K. R. Babu, "Linear feature extraction and description",
/// CGIP 13, 1980).
/// @param chains chains in pixel coordinates, each with at least one point.
/// @param values one value per point of each chain, or empty for none; values_out then stays untouched.
/// @throws hk::ArgumentError for bad params, a chain with no point, or values not shaped like chains.
std::vector<Chain> close_gaps(const std::vector<Chain>& chains, const GapParams& p, GapStats* stats = nullptr,
                              const PointValues& values = {}, PointValues* values_out = nullptr);

}  // namespace hk::vision
