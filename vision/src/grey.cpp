// to_grey: colour to one channel, shrunk to the processing size.
//
// Edges are found on luminance only (Canny is defined on a scalar image) and at a bounded size,
// so the edge and linking stages take the same time whatever camera or scanner made the file.

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"
#include "vision/intake.hpp"

namespace hk::vision {

cv::Mat to_grey(const cv::Mat& bgr, int max_side_px, double* px_scale_out) {
  if (bgr.empty()) throw hk::ArgumentError("to_grey: empty image");
  if (max_side_px < 1) throw hk::ArgumentError("to_grey: max_side_px must be >= 1");
  cv::Mat grey;
  switch (bgr.type()) {
    case CV_8UC3:
      cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
      break;
    case CV_8UC4:
      cv::cvtColor(bgr, grey, cv::COLOR_BGRA2GRAY);
      break;
    case CV_8UC1:
      grey = bgr.clone();
      break;
    default:
      throw hk::ArgumentError("to_grey: expected CV_8UC3, CV_8UC4 or CV_8UC1");
  }
  const int long_side = std::max(grey.cols, grey.rows);
  if (long_side <= max_side_px) {
    if (px_scale_out != nullptr) *px_scale_out = 1.0;
    return grey;
  }
  const double scale = static_cast<double>(long_side) / max_side_px;
  const auto shrink = [&](int n) { return std::clamp(static_cast<int>(std::lround(n / scale)), 1, max_side_px); };
  const cv::Size size =
      grey.cols >= grey.rows ? cv::Size(max_side_px, shrink(grey.rows)) : cv::Size(shrink(grey.cols), max_side_px);
  cv::Mat small;
  cv::resize(grey, small, size, 0, 0, cv::INTER_AREA);
  if (px_scale_out != nullptr) *px_scale_out = scale;
  return small;
}

}  // namespace hk::vision
