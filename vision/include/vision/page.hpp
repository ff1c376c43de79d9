#pragma once
/// @file page.hpp
/// Pages made flat: find the page, card or photo a visitor holds under the camera — the
/// largest convex quadrilateral with enough contrast against the background — and rectify it with a
/// perspective warp to its own aspect ratio, so the scene is built from the picture and not from the
/// table around it.

#include <array>

#include <opencv2/core.hpp>

namespace hk::vision {

/// Settings of find_page.
struct PageParams {
  double min_area_fraction =
      0.08;  ///< a page covers at least this share of the frame (its part inside the frame), (0, 1)
  /// Contrast of the page against its background, [0, 255] grey levels: the mean, over the sides not on the frame's
  /// edge in stretches of an eighth of a side, of |mean grey of a thin band just inside the border − mean grey of
  /// one just outside it| (bands 3 to 6 px off the side for frames up to max_side_px, in proportion for larger
  /// ones) must reach this; and each such side must be set off from its surroundings along most of its length: the
  /// median over its stretches of the colour distance between deeper bands (3 to 11 px off the side, deeper than
  /// the grain of a table or the weave of a cloth) at least 1.5 x this. For a side nearer the frame's edge than
  /// that, the outer bands are cut short at the frame's edge (they must start inside it).
  double min_contrast = 12.0;
  int max_side_px =
      800;  ///< the frame is searched at most this large (longer side) [px], >= 64; corners are refined at full size
};

/// A page found in a frame.
struct PageDetection {
  bool found = false;
  /// Corners in frame pixels (x right, y down, origin at the top-left pixel's centre), in the order top-left,
  /// top-right, bottom-right, bottom-left as seen in the frame: clockwise on screen, starting at the corner where the
  /// top side begins, the top side being the one that faces the frame's top most directly (its outward normal
  /// closest to straight up), so a page turned by less than 45° keeps its corners' names. A side that lies on the
  /// frame's edge (a page cut off there) is that edge, half a pixel beyond the outermost pixel centres (y = −0.5 for
  /// the top); a page cut off at a corner has that corner outside the frame (at most a quarter of the frame's size
  /// beyond it), where its sides meet. Meaningful only when found.
  std::array<cv::Point2d, 4> corners_px{};
  double area_fraction = 0.0;  ///< the area of the quadrilateral's part inside the frame / the frame's area
  double contrast = 0.0;       ///< as PageParams::min_contrast (the mean over the stretches), measured
  /// Per edge of the frame, in the order top, right, bottom, left: the page is cut off there — a corner lies on
  /// that edge or beyond it, as the corners of a side on the frame's edge do, or so near it that the page's
  /// outline cannot be told from the edge: nearer than the contrast test's bands start (PageParams::min_contrast;
  /// 3 px at 640 x 480, 7.6 px at 3264 x 2448, from the frame's outer boundary). A page lying whole in the frame
  /// touches no edge however close to it, as long as its outline is seen between it and the edge.
  std::array<bool, 4> touches_frame{};
};

/// Finds the page in a BGR (CV_8UC3) or grey (CV_8UC1) frame. found = false when no quadrilateral passes, among
/// them a picture that fills the whole frame (no page edge to see): the caller then uses the whole frame.
///
/// Steps. Candidates on a downscaled copy (longer side <= max_side_px) and its half-size copy: Canny edge maps (of
/// the colour where there is one) at three thresholds after two blurs strong enough to wash out a table's grain;
/// quadrilaterals from each map's outlines (cv::findContours, convex hull, cv::approxPolyDP to four corners, or five
/// or six with the shortest sides dropped and their neighbours extended), as in OpenCV's squares.cpp sample; and
/// from the long straight stretches of all maps (cv::HoughLinesP, grouped into lines) taken four at a time, two
/// roughly parallel pairs, the frame's own edges standing in for the sides of a page cut off by them. The 20
/// candidates best backed by edges (and the largest of those well backed) are then refined at full resolution:
/// each side's edge is located to sub-pixel precision along ~64 profiles across it (cv::remap, averaged along the
/// side, derivative peak by a parabola) and a line fitted (cv::fitLine, Huber, then least squares on the inliers);
/// the corners are where adjacent lines meet. A refined quadrilateral passes when it is convex, covers
/// min_area_fraction of the frame, every side is backed by an edge along most of its length (up to the frame's edge
/// where it meets it) and the contrast tests of PageParams::min_contrast hold; a refined side nearer the frame's edge
/// than those tests' bands start is taken as on the frame's edge. Of those that pass, the largest is
/// the page, unless it only runs past a smaller one's corners along a grain of the background, or has sides on the
/// frame's edge and runs past a smaller one's corners over the background to the frame's edge where the smaller one
/// has its own side (a page whole in the frame near its edge, not cut off; see page.cpp).
/// @throws hk::ArgumentError for an empty frame, another type, or bad params.
PageDetection find_page(const cv::Mat& frame, const PageParams& params = {});

/// The aspect ratio (width / height) of the rectangle whose perspective image is the quadrilateral `corners_px`
/// (order as PageDetection), for a pinhole camera with square pixels and its principal point at `centre_px` (the
/// frame's centre): the focal length is estimated from the quadrilateral and the ratio follows from it, after
/// Z. Zhang and L.-W. He, "Whiteboard scanning and image enhancement", Digital Signal Processing 17(2) (2007)
/// 414–432, the section "Determining the physical aspect ratio of a whiteboard" (§3.2 in the technical report
/// MSR-TR-2003-39: k2, k3, n2 = k2·m2 − m1, n3 = k3·m3 − m1, f² from n2ᵀA⁻ᵀA⁻¹n3 = 0, (w/h)² = n2ᵀA⁻ᵀA⁻¹n2 /
/// n3ᵀA⁻ᵀA⁻¹n3). Where that estimate is degenerate — a pair of opposite sides parallel in the image (a fronto-parallel
/// view, or one turned about one axis only), or f² not positive — the ratio of the mean lengths of opposite sides.
/// @throws hk::ArgumentError for corners or centre not finite, or a pair of opposite sides of zero length.
double page_aspect_ratio(const std::array<cv::Point2d, 4>& corners_px, cv::Point2d centre_px);

/// The page warped flat (cv::getPerspectiveTransform, cv::warpPerspective, bilinear, border replicated): a
/// width × height image with width / height = page_aspect_ratio(corners, frame centre) and the quadrilateral's
/// longest side kept at its length in the frame; the page's corners map to the outer corners of the output's
/// corner pixels. Same type as `frame`.
/// @throws hk::ArgumentError for an empty frame, corners not finite, a degenerate quadrilateral (area < 1 px²),
/// or a side longer than 4 times the frame's diagonal.
cv::Mat rectify_page(const cv::Mat& frame, const std::array<cv::Point2d, 4>& corners_px);

}  // namespace hk::vision
