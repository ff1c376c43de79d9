#pragma once
/// @file linking.hpp
/// Edge linking: the second half of the seed paper's "edge detection and linking" (§5).
///
/// The haptic core needs each boundary as one ordered polyline, felt as one wall. Contour
/// followers such as cv::findContours trace around a one-pixel-wide open edge and come back along
/// it, which would give the user two coincident walls; this linker walks the edge pixels as a
/// graph instead, so every open edge is a single out-only polyline.

#include <vector>

#include <opencv2/core.hpp>

namespace hk::vision {

/// One linked edge: an ordered polyline through pixel centres.
struct Chain {
  /// Points in pixel coordinates (u right, v down, origin at the centre of the top-left pixel)
  /// [px]. From link_edges: integer-valued, consecutive points 8-adjacent, no pixel twice (from
  /// trace_outlines: the same, but a pixel may come twice where the region is one pixel wide).
  /// A closed chain does NOT repeat its first point at the end; its last point joins the first.
  std::vector<cv::Point2d> points_px;
  bool closed = false;  ///< true when the chain is a loop
};

/// One value per chain point, e.g. edge strength: values[k][i] belongs to chains[k].points_px[i]
/// (same outer size as the chains, same inner size as each chain's points).
using PointValues = std::vector<std::vector<double>>;

/// Links 8-connected edge pixels into ordered chains.
///
/// Algorithm (pixel-graph tracing, as in classic edge linkers, e.g. P. Kovesi's edgelink.m and
/// cleanedgelist.m, "MATLAB and Octave Functions for Computer Vision and Image Processing", and
/// the chain following of the Vista library the seed paper used, Pope & Lowe 1994):
/// 1. Thinning: in raster order, the redundant corner pixel of each staircase step is removed
///    (a pixel whose only 4-neighbours are two perpendicular ones, inner corner empty, and whose
///    curve turns back to its heading right after the step). Canny's output is full of these
///    "L-corners"; a true right-angle corner is kept. Connectivity is unchanged.
/// 2. Adjacency: each edge pixel is joined to its 4-neighbours, and to a diagonal neighbour only
///    when neither of the two pixels 4-adjacent to both is an edge pixel, so remaining L-corners
///    are not taken for junctions. Pixels then have degree 0 (isolated), 1 (end), 2 (on a
///    curve) or >= 3 (junction).
/// 3. Tracing: in raster order, from every pixel of degree != 2, each not yet used link is
///    followed through degree-2 pixels until a pixel of degree != 2: one segment per branch.
///    What is left are cycles without junctions, each traced from its raster-first pixel.
/// 4. Cleaning at junctions (after Kovesi's cleanedgelist.m): segments that are Canny artefacts
///    at corners - spurs to a free end up to 3 px long, all but the shortest of several branches
///    up to 3 px long between the same two junctions, loops up to 5 px from a junction back to
///    itself - are set aside as chains of their own; where exactly two other segment ends then
///    meet at a junction, those two segments are one curve and are joined through it. A joined
///    curve that returns to its first pixel is closed.
/// 5. Chains whose polyline length (including the closing segment of a closed chain) is below
///    min_length_px are dropped. An isolated pixel is a one-point open chain of length 0.
///
/// Guarantees (before the length filter): every edge pixel is in a chain, except the staircase
/// corners removed in step 1, each of which lies next to a chain point; a pixel is in more than
/// one chain only at a junction, where it is an end point of all of them but at most one; no
/// chain contains a pixel twice; consecutive points, and the last and first points of a closed
/// chain, are 8-adjacent; 8-connected components of the edge map are never split or merged.
/// Output order: by raster index (v, then u) of the first point, ties in discovery order;
/// deterministic. Time and memory O(width * height) (plus sorting the chains and the few short
/// segments); the passes after one scan of the map visit only the edge pixels. Each calling
/// thread keeps its scratch buffers (about 3 bytes per pixel) between calls, for edge maps of up
/// to 2^22 pixels; concurrent calls from different threads are safe.
///
/// @param edges         CV_8UC1; non-zero = edge pixel. May be empty (no chains).
/// @param min_length_px smallest polyline length kept [px], >= 0.
/// @throws hk::ArgumentError if edges is not CV_8UC1 or min_length_px is negative or NaN.
std::vector<Chain> link_edges(const cv::Mat& edges, double min_length_px);

/// Polyline length of a chain [px]: sum of its segment lengths, plus the segment from the last
/// point back to the first when closed.
double chain_length_px(const Chain& chain);

}  // namespace hk::vision
