// Two-tone pictures traced from a threshold: classify_two_tone and trace_outlines.
#include "vision/outline.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"

namespace hk::vision {
namespace {

void check_grey(const cv::Mat& grey, const char* who) {
  if (grey.empty() || grey.type() != CV_8UC1)
    throw hk::ArgumentError(std::string(who) + ": the image must be CV_8UC1 and not empty");
}

bool on_frame(const cv::Point& p, int w, int h) { return p.x == 0 || p.y == 0 || p.x == w - 1 || p.y == h - 1; }

/// Pixels of `mask` (0 / 255) on the picture's frame that are set.
long frame_count(const cv::Mat& mask) {
  long n = 0;
  const int w = mask.cols, h = mask.rows;
  for (int x = 0; x < w; ++x) n += (mask.at<std::uint8_t>(0, x) != 0) + (h > 1 && mask.at<std::uint8_t>(h - 1, x) != 0);
  for (int y = 1; y + 1 < h; ++y)
    n += (mask.at<std::uint8_t>(y, 0) != 0) + (w > 1 && mask.at<std::uint8_t>(y, w - 1) != 0);
  return n;
}

/// The foreground of `grey` split at `threshold`: the tone (0 / 255 mask) that covers less of the frame.
cv::Mat foreground(const cv::Mat& grey, double threshold) {
  cv::Mat light;
  cv::threshold(grey, light, threshold, 255, cv::THRESH_BINARY);
  cv::Mat dark = 255 - light;
  return frame_count(light) <= frame_count(dark) ? light : dark;
}

/// 2 · area / boundary length of the foreground (see TwoTone::ink_width_px) [px].
double ink_width(const cv::Mat& grey, double threshold) {
  const cv::Mat fg = foreground(grey, threshold);
  const double area = cv::countNonZero(fg);
  cv::Mat across;
  double crack = 0.0;
  if (fg.cols > 1) {
    cv::bitwise_xor(fg.colRange(1, fg.cols), fg.colRange(0, fg.cols - 1), across);
    crack += cv::countNonZero(across);
  }
  if (fg.rows > 1) {
    cv::bitwise_xor(fg.rowRange(1, fg.rows), fg.rowRange(0, fg.rows - 1), across);
    crack += cv::countNonZero(across);
  }
  return crack > 0 ? 2.0 * area / crack : 0.0;
}

/// A walk of the boundary → one chain of it (dropped under min_points).
void emit(const std::vector<cv::Point>& walk, bool closed, int min_points, std::vector<Chain>& out) {
  if (static_cast<int>(walk.size()) < min_points) return;
  Chain c;
  c.closed = closed;
  c.points_px.reserve(walk.size());
  for (const cv::Point& p : walk) c.points_px.emplace_back(p.x, p.y);
  out.push_back(std::move(c));
}

/// One contour → chains: closed if it never touches the frame, else the stretches between frame points.
void split_at_frame(const std::vector<cv::Point>& contour, int w, int h, int min_points, std::vector<Chain>& out) {
  const std::size_t n = contour.size();
  std::size_t first_frame = n;
  for (std::size_t i = 0; i < n; ++i)
    if (on_frame(contour[i], w, h)) {
      first_frame = i;
      break;
    }
  if (first_frame == n) {
    emit(contour, true, min_points, out);
    return;
  }
  // Walk once round from a frame point: every stretch of points off the frame is an open chain.
  std::vector<cv::Point> stretch;
  for (std::size_t k = 1; k <= n; ++k) {
    const cv::Point& p = contour[(first_frame + k) % n];
    if (on_frame(p, w, h)) {
      emit(stretch, false, min_points, out);
      stretch.clear();
    } else {
      stretch.push_back(p);
    }
  }
  emit(stretch, false, min_points, out);
}

}  // namespace

TwoTone classify_two_tone(const cv::Mat& grey) {
  check_grey(grey, "classify_two_tone");
  TwoTone t;
  cv::Mat bin;
  t.threshold = cv::threshold(grey, bin, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  double sum[2] = {0, 0};
  long count[2] = {0, 0};
  long hist[256] = {};
  for (int y = 0; y < grey.rows; ++y) {
    const std::uint8_t* r = grey.ptr<std::uint8_t>(y);
    for (int x = 0; x < grey.cols; ++x) ++hist[r[x]];
  }
  for (int g = 0; g < 256; ++g) {
    const int k = g > t.threshold ? 1 : 0;
    sum[k] += static_cast<double>(g) * static_cast<double>(hist[g]);
    count[k] += hist[g];
  }
  if (count[0] == 0 || count[1] == 0) return t;  // one tone only: nothing to trace
  t.dark_mean = sum[0] / static_cast<double>(count[0]);
  t.light_mean = sum[1] / static_cast<double>(count[1]);
  long near = 0;
  for (int g = 0; g < 256; ++g) {
    const double m = g > t.threshold ? t.light_mean : t.dark_mean;
    if (std::abs(static_cast<double>(g) - m) <= kToneSpreadLevels) near += hist[g];
  }
  t.near_share = static_cast<double>(near) / static_cast<double>(count[0] + count[1]);
  t.two_tone = t.light_mean - t.dark_mean >= kMinToneGapLevels && t.near_share >= kMinNearShare;
  t.ink_width_px = ink_width(grey, t.threshold);
  return t;
}

std::vector<Chain> trace_outlines(const cv::Mat& grey, double threshold, int min_points) {
  check_grey(grey, "trace_outlines");
  if (min_points < 1) throw hk::ArgumentError("trace_outlines: min_points must be >= 1");
  const cv::Mat fg = foreground(grey, threshold);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(fg, contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
  std::vector<Chain> out;
  for (const auto& c : contours) split_at_frame(c, grey.cols, grey.rows, min_points, out);
  return out;
}

}  // namespace hk::vision
