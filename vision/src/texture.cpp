// Surround inhibition at the chain points (see texture.hpp).

#include "vision/texture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"

namespace hk::vision {

cv::Mat surround_mean(const cv::Mat& src, double sigma) {
  if (src.empty() || src.type() != CV_32FC1)
    throw hk::ArgumentError("surround_mean: expected a non-empty CV_32FC1 image");
  if (!(sigma > 0.0) || !std::isfinite(sigma)) throw hk::ArgumentError("surround_mean: sigma must be finite and > 0");
  const double so = kSurroundRatio * sigma;
  const double c = (sigma / so) * (sigma / so);
  cv::Mat outer, inner, out;
  cv::GaussianBlur(src, outer, cv::Size(0, 0), so, so, cv::BORDER_REPLICATE);
  cv::GaussianBlur(src, inner, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE);
  cv::addWeighted(outer, 1.0 / (1.0 - c), inner, -c / (1.0 - c), 0.0, out);
  return out;
}

namespace {

/// The 3x3 Sobel L2 gradient magnitude of `grey` blurred at blur_sigma_px (as detect_edges differentiates), CV_32F.
cv::Mat gradient_magnitude(const cv::Mat& grey, double blur_sigma_px) {
  cv::Mat blurred;  // its own buffer: sharing grey's pixels would blur the caller's image in place
  if (blur_sigma_px > 0.0) {
    cv::GaussianBlur(grey, blurred, cv::Size(0, 0), blur_sigma_px, blur_sigma_px, cv::BORDER_REPLICATE);
  } else {
    blurred = grey;
  }
  cv::Mat gx, gy, m;
  cv::Sobel(blurred, gx, CV_32F, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(blurred, gy, CV_32F, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  cv::magnitude(gx, gy, m);
  return m;
}

}  // namespace

PointValues chain_surround(const cv::Mat& grey, double blur_sigma_px, const std::vector<Chain>& chains) {
  if (grey.empty() || grey.type() != CV_8UC1)
    throw hk::ArgumentError("chain_surround: expected a non-empty CV_8UC1 image");
  if (!std::isfinite(blur_sigma_px) || blur_sigma_px < 0.0)
    throw hk::ArgumentError("chain_surround: blur_sigma_px must be finite and >= 0");
  const cv::Mat m = gradient_magnitude(grey, blur_sigma_px);
  // The annulus is smooth (σo = 4σ): averaged at half resolution (area-averaged, σ halved), enlarged back
  // bilinearly — a quarter of the pixels to blur.
  const double sigma = std::max(blur_sigma_px, 1.0);
  cv::Mat small, surround;
  cv::resize(m, small, cv::Size((m.cols + 1) / 2, (m.rows + 1) / 2), 0, 0, cv::INTER_AREA);
  cv::resize(surround_mean(small, 0.5 * sigma), surround, m.size(), 0, 0, cv::INTER_LINEAR);
  PointValues out(chains.size());
  for (std::size_t k = 0; k < chains.size(); ++k) {
    out[k].reserve(chains[k].points_px.size());
    for (const cv::Point2d& p : chains[k].points_px) {
      const int x = std::clamp(static_cast<int>(p.x), 0, grey.cols - 1),
                y = std::clamp(static_cast<int>(p.y), 0, grey.rows - 1);
      out[k].push_back(surround.at<float>(y, x));
    }
  }
  return out;
}

bool stands_out(const std::vector<double>& strength, const std::vector<double>& surround, double alpha, double low) {
  if (strength.empty()) return true;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < strength.size(); ++i) {
    const double s = i < surround.size() ? surround[i] : 0.0;
    kept += strength[i] - alpha * s >= low;
  }
  return static_cast<double>(kept) >= kStandOutShare * static_cast<double>(strength.size());
}

}  // namespace hk::vision
