#pragma once
/// @file page.hpp
/// Pages made flat (issue 16, item 2): find the page, card or photo a visitor holds under the camera — the
/// largest convex quadrilateral with enough contrast against the background — and rectify it with a
/// perspective warp to its own aspect ratio, so the scene is built from the picture and not from the
/// table around it.

#include <array>

#include <opencv2/core.hpp>

namespace hk::vision {

/// Settings of find_page.
struct PageParams {
  double min_area_fraction = 0.08;  ///< a page covers at least this share of the frame, (0, 1)
  double min_contrast = 12.0;       ///< mean grey-level difference between a thin band inside the page's
                                    ///< border and one outside it, [0, 255]
  int max_side_px = 800;            ///< the frame is searched at most this large (longer side) [px], >= 64
};

/// A page found in a frame.
struct PageDetection {
  bool found = false;
  /// Corners in frame pixels (x right, y down, origin at the top-left pixel's centre), in the order
  /// top-left, top-right, bottom-right, bottom-left as seen in the frame (the page's top is the side nearer
  /// the frame's top). Meaningful only when found.
  std::array<cv::Point2d, 4> corners_px{};
  double area_fraction = 0.0;  ///< the quadrilateral's area / the frame's area
  double contrast = 0.0;       ///< as PageParams::min_contrast, measured
  /// Sides of the quadrilateral within 1 % of the frame's diagonal of the frame's edge, in the order top,
  /// right, bottom, left of the frame: the page may be cut off there.
  std::array<bool, 4> touches_frame{};
};

/// Finds the page in a BGR (CV_8UC3) or grey (CV_8UC1) frame; found = false when no quadrilateral passes
/// (then the caller uses the whole frame).
/// @throws std::invalid_argument for an empty frame, another type, or bad params.
PageDetection find_page(const cv::Mat& frame, const PageParams& params = {});

/// The aspect ratio (width / height) of the rectangle whose perspective image is the quadrilateral `corners_px`
/// (order as PageDetection), for a pinhole camera with square pixels and its principal point at the frame
/// centre `centre_px`: Zhang & He, "Whiteboard scanning and image enhancement", Digital Signal Processing 17
/// (2007), §2 (the focal length estimated from the quadrilateral); where that estimate is degenerate (nearly
/// parallel sides: a fronto-parallel view), the ratio of the mean lengths of opposite sides.
double page_aspect_ratio(const std::array<cv::Point2d, 4>& corners_px, cv::Point2d centre_px);

/// The page warped flat: a width × height image with width / height = page_aspect_ratio(corners, frame centre)
/// and the quadrilateral's longer measured side kept at its length in the frame (bilinear, border replicated).
/// Same type as `frame`.
/// @throws std::invalid_argument for an empty frame or a degenerate quadrilateral (area < 1 px²).
cv::Mat rectify_page(const cv::Mat& frame, const std::array<cv::Point2d, 4>& corners_px);

}  // namespace hk::vision
