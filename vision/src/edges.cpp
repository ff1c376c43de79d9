// Canny edge detection with thresholds chosen from the image (see edges.hpp for the rule).
//
// The Sobel derivatives are computed once and given to cv::Canny, so the threshold statistics
// are taken from exactly the gradient that Canny thresholds (same kernel, border and L2 norm).

#include "vision/edges.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <opencv2/imgproc.hpp>

namespace hk::vision {
namespace {

constexpr double kHighPercentile = 0.90;  // of the non-zero gradient magnitudes
constexpr double kLowRatio = 0.4;         // low = kLowRatio * high (MATLAB's ThresholdRatio)
constexpr double kNoiseSigmas = 5.0;      // high >= this many Rayleigh scales of pure noise
constexpr double kMaxFraction = 0.5;      // high <= this fraction of the strongest gradient

/// Statistics of the non-zero L2 gradient magnitudes, from a histogram of 1-unit bins.
struct GradientStats {
  double percentile = 0.0;  // kHighPercentile quantile (see below)
  double max = 0.0;         // largest magnitude (lower edge of its bin)
};

/// The quantile is returned as the lower edge of its bin minus 0.5, so that the pixels at the
/// quantile count as strong (cv::Canny keeps m > high): on clean synthetic or binary images
/// every ridge pixel of a straight edge has exactly the same magnitude, the quantile itself.
GradientStats gradient_stats(const cv::Mat& dx, const cv::Mat& dy) {
  // |Sobel 3x3| <= 4 * 255 per axis on 8-bit input, so the L2 magnitude is < 1443.
  std::array<std::int64_t, 1448> hist{};
  for (int y = 0; y < dx.rows; ++y) {
    const auto* gx = dx.ptr<std::int16_t>(y);
    const auto* gy = dy.ptr<std::int16_t>(y);
    for (int x = 0; x < dx.cols; ++x) {
      const int m2 = gx[x] * gx[x] + gy[x] * gy[x];
      if (m2 == 0) continue;
      const auto bin = static_cast<std::size_t>(std::sqrt(static_cast<double>(m2)));
      ++hist[std::min(bin, hist.size() - 1)];
    }
  }
  GradientStats st;
  std::int64_t nonzero = 0;
  for (std::size_t b = 0; b < hist.size(); ++b) {
    nonzero += hist[b];
    if (hist[b] > 0) st.max = static_cast<double>(b);
  }
  if (nonzero == 0) return st;
  const auto target = static_cast<std::int64_t>(std::ceil(kHighPercentile * static_cast<double>(nonzero)));
  std::int64_t cumulative = 0;
  for (std::size_t b = 0; b < hist.size(); ++b) {
    cumulative += hist[b];
    if (cumulative >= target) {
      st.percentile = static_cast<double>(b) - 0.5;
      break;
    }
  }
  return st;
}

/// Standard deviation of additive white noise in a grey image, by J. Immerkaer, "Fast Noise
/// Variance Estimation", Computer Vision and Image Understanding 64(2), 1996: the image is
/// filtered with the difference of two Laplacians [1 -2 1; -2 4 -2; 1 -2 1], which cancels
/// image structure up to second order, and sigma = sqrt(pi/2) * mean|response| / 6.
/// Texture and edges add to the estimate, so it over-estimates on busy images (harmless here:
/// it is only a floor).
double noise_sigma(const cv::Mat& grey) {
  if (grey.rows < 3 || grey.cols < 3) return 0.0;
  static const cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat response;
  cv::filter2D(grey, response, CV_32F, kernel);
  const cv::Rect inner(1, 1, grey.cols - 2, grey.rows - 2);
  const double sum_abs = cv::norm(response(inner), cv::NORM_L1);
  return std::sqrt(CV_PI / 2.0) * sum_abs / (6.0 * inner.area());
}

/// Standard deviation of one Sobel component after the pre-blur, per unit of white noise: the
/// L2 norm of the impulse response of GaussianBlur(sigma) followed by Sobel-x.
double gradient_noise_gain(double blur_sigma_px) {
  const int half = static_cast<int>(std::ceil(4.0 * blur_sigma_px)) + 2;
  cv::Mat impulse = cv::Mat::zeros(2 * half + 1, 2 * half + 1, CV_32F);
  impulse.at<float>(half, half) = 1.0f;
  if (blur_sigma_px > 0.0) cv::GaussianBlur(impulse, impulse, cv::Size(0, 0), blur_sigma_px);
  cv::Mat gx;
  cv::Sobel(impulse, gx, CV_32F, 1, 0, 3);
  return cv::norm(gx, cv::NORM_L2);
}

}  // namespace

EdgeMap detect_edges(const cv::Mat& grey, const EdgeParams& p) {
  if (grey.empty() || grey.type() != CV_8UC1) {
    throw std::invalid_argument("detect_edges: expected a non-empty CV_8UC1 image");
  }
  for (const double v : {p.blur_sigma_px, p.canny_low, p.canny_high}) {
    if (!std::isfinite(v) || v < 0.0) {
      throw std::invalid_argument("detect_edges: parameters must be finite and >= 0");
    }
  }
  cv::Mat blurred;  // a new buffer: `cv::Mat blurred = grey` would blur the caller's image in place
  if (p.blur_sigma_px > 0.0) {
    cv::GaussianBlur(grey, blurred, cv::Size(0, 0), p.blur_sigma_px, p.blur_sigma_px, cv::BORDER_REPLICATE);
  } else {
    blurred = grey;
  }
  cv::Mat dx;
  cv::Mat dy;
  cv::Sobel(blurred, dx, CV_16S, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(blurred, dy, CV_16S, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);

  EdgeMap out;
  if (p.canny_high > 0.0) {
    out.high = p.canny_high;
  } else {
    // Pure noise gives a Rayleigh-distributed magnitude with scale sigma_noise * gain, which
    // exceeds kNoiseSigmas scales with probability exp(-kNoiseSigmas^2 / 2) = 4e-6.
    const double noise_floor = kNoiseSigmas * noise_sigma(grey) * gradient_noise_gain(p.blur_sigma_px);
    // On images with few, clean edges (logos, silhouettes) the quantile sits at the strongest
    // edge; an edge half as strong as the strongest one is still a sure edge.
    const GradientStats st = gradient_stats(dx, dy);
    out.high = std::max({std::min(st.percentile, kMaxFraction * st.max), noise_floor, kMinAutoHigh});
  }
  out.low = p.canny_low > 0.0 ? p.canny_low : kLowRatio * out.high;
  if (out.low > out.high) std::swap(out.low, out.high);  // as cv::Canny does; report what it used
  cv::Canny(dx, dy, out.edges, out.low, out.high, /*L2gradient=*/true);
  return out;
}

}  // namespace hk::vision
