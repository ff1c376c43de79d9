// Pages made flat: the time per camera frame of vision::find_page and vision::rectify_page at
// 640 x 480, 1280 x 960 and 1920 x 1080, on synthetic photos (tests/support/synthetic_photo.hpp) of four test
// pictures (a photograph, a silhouette, a drawing, a printed page) under two conditions (clean on wood; turned
// 25°, tilted, blurred, noisy and unevenly lit on a cloth), cycled through frame by frame. The photos are made
// before timing starts. Counters: found (share of frames where a page was found), corner_error_pct (mean of the
// largest corner error per frame, % of the page's diagonal).
// Usage: bench_rectify [Google Benchmark flags], e.g. --benchmark_format=json --benchmark_out=FILE
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "synthetic_photo.hpp"
#include "test_paths.hpp"
#include "vision/page.hpp"

namespace {

struct Frame {
  cv::Mat image;
  std::array<cv::Point2d, 4> truth;
};

/// The synthetic photos at one frame size (made once per size).
const std::vector<Frame>& frames(cv::Size size) {
  static std::vector<std::pair<cv::Size, std::vector<Frame>>> cache;
  for (const auto& [s, v] : cache)
    if (s == size) return v;
  std::vector<Frame> out;
  std::uint64_t seed = 1;
  for (const std::string name : {"camera.png", "silhouette_3.png", "pic1.png", "page"}) {
    const cv::Mat picture = name == "page"
                                ? hk::test::text_page()
                                : cv::imread(std::string(HK_TEST_DATA_DIR) + "/images/" + name, cv::IMREAD_COLOR);
    for (int condition = 0; condition < 2; ++condition) {
      hk::test::PhotoConditions c;
      c.seed = seed++;
      if (condition == 0) {
        c.rotation_deg = 8;
        c.perspective = 0.05;
      } else {
        c.rotation_deg = -25;
        c.perspective = 0.12;
        c.blur_sigma_px = 1.2 * size.width / 640.0;
        c.noise_sigma = 5;
        c.uneven_light = true;
        c.backdrop = hk::test::Backdrop::blobs;
      }
      const hk::test::SyntheticPhoto p = hk::test::synthetic_photo(picture, size, c);
      out.push_back({p.frame, p.corners_px});
    }
  }
  cache.emplace_back(size, std::move(out));
  return cache.back().second;
}

double corner_error_pct(const std::array<cv::Point2d, 4>& found, const std::array<cv::Point2d, 4>& truth) {
  double worst = 0.0;
  for (std::size_t i = 0; i < 4; ++i) worst = std::max(worst, cv::norm(found[i] - truth[i]));
  return 100.0 * worst / std::max(cv::norm(truth[2] - truth[0]), cv::norm(truth[3] - truth[1]));
}

void BM_FindAndRectify(benchmark::State& state) {
  const std::vector<Frame>& v = frames({static_cast<int>(state.range(0)), static_cast<int>(state.range(1))});
  std::size_t i = 0, found = 0, n = 0;
  double error = 0.0;
  for (auto _ : state) {
    const Frame& f = v[i++ % v.size()];
    const hk::vision::PageDetection d = hk::vision::find_page(f.image);
    ++n;
    if (d.found) {
      const cv::Mat flat = hk::vision::rectify_page(f.image, d.corners_px);
      benchmark::DoNotOptimize(flat.data);
      ++found;
      error += corner_error_pct(d.corners_px, f.truth);
    }
  }
  state.counters["found"] = static_cast<double>(found) / std::max<std::size_t>(1, n);
  state.counters["corner_error_pct"] = found > 0 ? error / static_cast<double>(found) : -1.0;
}

void BM_FindPage(benchmark::State& state) {
  const std::vector<Frame>& v = frames({static_cast<int>(state.range(0)), static_cast<int>(state.range(1))});
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(hk::vision::find_page(v[i++ % v.size()].image).found);
}

void BM_RectifyPage(benchmark::State& state) {
  const std::vector<Frame>& v = frames({static_cast<int>(state.range(0)), static_cast<int>(state.range(1))});
  std::size_t i = 0;
  for (auto _ : state) {
    const Frame& f = v[i++ % v.size()];
    const cv::Mat flat = hk::vision::rectify_page(f.image, f.truth);
    benchmark::DoNotOptimize(flat.data);
  }
}

void sizes(benchmark::internal::Benchmark* b) {
  b->Args({640, 480})->Args({1280, 960})->Args({1920, 1080})->Unit(benchmark::kMillisecond);
}

BENCHMARK(BM_FindAndRectify)->Apply(sizes);
BENCHMARK(BM_FindPage)->Apply(sizes);
BENCHMARK(BM_RectifyPage)->Apply(sizes);

}  // namespace

BENCHMARK_MAIN();
