#pragma once
/// @file thin_lines.hpp
/// Thin-line merging: one curve along a thin stroke instead of its two edges.
///
/// Canny finds boundaries, so a thin dark stroke (a line drawing, a grid line, a letter, a road
/// on a map) gives TWO parallel edge chains, one each side of the stroke, usually one closed loop
/// around the whole stroke. Felt with a fingertip, two walls a millimetre apart are a groove
/// that catches the proxy and reads as a double line; the picture means one line. A visitor
/// should feel one curve along the stroke's centre line.

#include <cstddef>
#include <vector>

#include "vision/linking.hpp"

namespace hk::vision {

/// What merge_thin_lines did.
struct ThinLineStats {
  std::size_t pairs_merged = 0;  ///< centre lines made: each replaces a pair of facing sides (after joining pieces)
  std::size_t points_in = 0;     ///< chain points given
  std::size_t points_out = 0;    ///< chain points returned
};

/// Replaces the two edges of every stroke thinner than max_width_px by the stroke's centre line.
///
/// Input and output are chains in one pixel frame (u right, v down) [px]; any chains, e.g.
/// link_edges's (integer, 8-adjacent points) at the resolution edges were found at. Points of
/// the output centre lines are sub-pixel midpoints about 1 px apart (farther, up to 2 w + 2, only
/// across a join, step 5); untouched chains and left-over pieces keep their input points.
///
/// Algorithm (ours; the idea of pairing anti-parallel edge points across a stroke is that of
/// "stroke width" measures, e.g. Epshtein, Ofek & Wexler, "Detecting Text in Natural Scenes with
/// Stroke Width Transform", CVPR 2010, and of medial-axis extraction from edge pairs; we pair on
/// geometry only, because the argument is haptic resolution, not the stroke's polarity: two
/// walls closer than max_width_px cannot be told apart by the fingertip, whatever the grey
/// levels between them):
/// 1. Tangents: at each point, the direction from the point h before to the point h after it on
///    its chain, h = clamp(round(w / 2), 2, 4) points (w = max_width_px; wraps on closed chains,
///    clamped at open ends), which averages the 45-degree steps of pixel chains.
/// 2. Pairs: each point p takes as partner the NEAREST point q (ties: lower index) with
///    1 px <= |pq| <= w, tangents within 30 degrees of parallel or anti-parallel, and the gap pq
///    within 30 degrees of both normals; q is on another chain or on a part of p's own chain at
///    least max(1.5 |pq|, |pq| + 2) px away along it (so a chain never pairs with its own
///    neighbourhood, but a loop around a stroke pairs its two sides). Points closer than 1 px
///    are the same edge (link_edges repeats junction pixels at chain ends). A uniform grid of
///    cells w wide makes this O(points * w) for edges of bounded density, O(points * w^2) at
///    worst, never all pairs.
/// 3. Runs: walking each chain, paired points form a run while their partners stay on one chain
///    and move on by at most 2 * steps + 3 points per step (a partner that leaps is another
///    stroke), at most G = max(2, ceil(w / 2)) unpaired points are skipped (pixel noise), and no
///    partner lies in the run itself (the walk has gone round the end of a stroke and come back
///    along its other side). Runs shorter than 2 w along their chain are dropped: a short
///    stretch of facing edges is a corner or a crossing, not a line (and a centre line that short
///    would be barely longer than the gap it replaces).
/// 4. Centre lines: runs in chain order; a point of a run and its partner, neither yet covered
///    by an earlier run, give their midpoint; maximal sequences of such points give one centre
///    line each (closed when the run is a whole loop, e.g. a ring). The run's points, their
///    partners and the points between consecutive partners are then covered, so the facing run
///    on the other side makes no second centre line. Lightly smoothed ([1 2 1] / 4; ends kept),
///    points closer than 0.2 px to the previous one dropped.
/// 5. Joining: centre-line ends within 2 w + 2 px are joined end to end when each is the other's
///    best (smallest turn, at most about 100 degrees) and the join passes no input point closer
///    than 0.9 px (it stays inside the stroke; a join that crosses an edge would bridge two
///    strokes across the background): the pieces of a stroke broken at a corner (an L) or a
///    crossing (grid lines: straight on through the crossing) become one curve. An end joined
///    to its own start closes the curve. A join that turns by more than 20 degrees goes
///    through the point where the two ends' rays meet (an L's centre line has its corner there;
///    the chord would cut it), when that path is clear and within 2 w + 2 of both ends.
/// 6. What is left: the points no run covered form pieces (maximal runs along their chain). A
///    chain with no point covered is returned as it was. Otherwise, each piece loses its end
///    points that lie within w of a centre line (the cap of a stroke, the outer corner of a
///    bent stroke: felt as part of the centre line), and is kept when it is still more than
///    2 px long.
/// Output order: the pieces of the input chains in input order (each chain's pieces in chain
/// order), then the centre lines in the order they were made. Deterministic; no randomness, no
/// dependence on threads. Time O(points * w) typical (see 2), memory O(points).
///
/// @param chains        pixel chains [px]; finite coordinates. May be empty.
/// @param max_width_px  widest stroke merged: largest distance between its two edges [px],
///                      >= 0 and finite; 0 = off (chains returned unchanged).
/// @param stats         optional; receives the counts.
/// @return the chains with each thin stroke's pair of sides replaced by one centre line.
/// @throws hk::ArgumentError if max_width_px is negative, NaN or infinite, or a point is not
///         finite (one line naming the parameter).
std::vector<Chain> merge_thin_lines(const std::vector<Chain>& chains, double max_width_px,
                                    ThinLineStats* stats = nullptr);

/// merge_thin_lines that also carries one value per point (e.g. edge strength) to the output:
/// a centre-line point gets the mean of the values of its two side points (a corner point added
/// by a join, the mean of the two ends it joins), a kept point its own.
///
/// @param values_in  values of `chains` (see PointValues).
/// @param values_out optional; receives the values of the returned chains.
/// @throws hk::ArgumentError as merge_thin_lines, and if values_in does not match chains in
///         shape.
std::vector<Chain> merge_thin_lines(const std::vector<Chain>& chains, double max_width_px, ThinLineStats* stats,
                                    const PointValues& values_in, PointValues* values_out);

}  // namespace hk::vision
