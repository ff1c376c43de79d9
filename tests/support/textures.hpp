#pragma once
/// @file textures.hpp
/// Pictures of pure texture, generated (a picture of pure texture must give few shapes): what a
/// photograph of a gravel path or a wooden table top would be with nothing on it. Deterministic from the seed
/// (cv::RNG), 8-bit grey, written as PNG by bench/textures (docs/bench/textures/).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace hk::test {

/// Smooth random field in [-1, 1]: white noise on a grid `cell_px` coarse, bicubically enlarged to w x h.
inline cv::Mat smooth_field(int w, int h, double cell_px, cv::RNG& rng) {
  const int gw = std::max(2, static_cast<int>(std::ceil(w / cell_px)) + 2);
  const int gh = std::max(2, static_cast<int>(std::ceil(h / cell_px)) + 2);
  cv::Mat grid(gh, gw, CV_32F);
  rng.fill(grid, cv::RNG::UNIFORM, -1.0, 1.0);
  cv::Mat big;
  cv::resize(grid, big, cv::Size(static_cast<int>(gw * cell_px), static_cast<int>(gh * cell_px)), 0, 0,
             cv::INTER_CUBIC);
  return big(cv::Rect(0, 0, w, h)).clone();
}

/// Fine grain noise (gravel, sand, a grainy print): Gaussian white noise of standard deviation 60 grey
/// levels blurred at sigma 1.5 px and stretched back to that deviation, on mid grey, with a slow
/// illumination gradient of +-20 grey levels. w x h, CV_8UC1.
inline cv::Mat noise_texture(int w, int h, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat n(h, w, CV_32F);
  rng.fill(n, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(n, n, cv::Size(0, 0), 1.5);
  cv::Scalar mean, sd;
  cv::meanStdDev(n, mean, sd);
  cv::Mat img = 128.0 + n * (60.0 / sd[0]) + 20.0 * smooth_field(w, h, w / 2.0, rng);
  cv::Mat out;
  img.convertTo(out, CV_8U);
  return out;
}

/// Wood grain (a table top photographed from above): growth rings round a centre far outside the picture,
/// their radius bent by a slow random field of a few periods, each ring a dark late-wood line
/// (0.5 + 0.5 sin)^4 on light early wood, the ring period varying from 7 to 13 px across the board, fibres
/// (noise stretched along the grain) and grain-scale noise on top. w x h, CV_8UC1.
inline cv::Mat wood_texture(int w, int h, std::uint64_t seed) {
  cv::RNG rng(seed);
  const cv::Mat bend = smooth_field(w, h, 120.0, rng);
  const cv::Mat period_var = smooth_field(w, h, 300.0, rng);
  cv::Mat fibre(h, w, CV_32F);
  rng.fill(fibre, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(fibre, fibre, cv::Size(0, 0), 12.0, 0.7);  // stretched along x, the grain's run
  cv::Scalar fm, fs;
  cv::meanStdDev(fibre, fm, fs);
  const double cx = -3.0 * w, cy = 0.5 * h + rng.uniform(-0.3, 0.3) * h;
  cv::Mat img(h, w, CV_32F);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double period = 10.0 + 3.0 * period_var.at<float>(y, x);
      const double r = std::hypot(x - cx, y - cy) * 0.02 + 25.0 * bend.at<float>(y, x);  // rings run along x
      const double ring_y = (y - cy) + 2.0 * r;
      const double phase = 2.0 * std::numbers::pi * ring_y / period;
      const double late = std::pow(0.5 + 0.5 * std::sin(phase), 4.0);
      img.at<float>(y, x) = static_cast<float>(170.0 - 55.0 * late + 8.0 * fibre.at<float>(y, x) / fs[0]);
    }
  }
  cv::Mat grain(h, w, CV_32F);
  rng.fill(grain, cv::RNG::NORMAL, 0.0, 4.0);
  img += grain;
  cv::Mat out;
  img.convertTo(out, CV_8U);
  return out;
}

}  // namespace hk::test
