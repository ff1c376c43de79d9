// Gap closing end to end: a line drawing whose outlines are cut by gaps of 0.5, 1 and 2 mm
// at the kiosk's scale, through build_image_scene (Canny, thin-line merging, close_gaps). The gaps between
// the chains' ends are not the picture's: Canny's blur pulls the edges back from a stroke's end by up to
// 2.5 px either side of a narrow gap, so the 1 mm gap (4 px) is 10 px between the centre lines' ends and stays
// open; close_gaps itself closes 0.5 and 1 mm and not 2 mm (tests/vision/test_gaps.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "kiosk_exe.hpp"
#include "pictures/image_scene.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;

/// A 560 x 360 picture (0.25 mm per pixel on the default 140 x 90 mm workspace) of three hairline squares,
/// 100 px a side, the top side of each cut by a gap of white_px[k] pixels of white.
cv::Mat three_cut_squares(const int (&white_px)[3]) {
  cv::Mat img(360, 560, CV_8UC1, cv::Scalar(255));
  for (int k = 0; k < 3; ++k) {
    const int x0 = 40 + 180 * k, y0 = 120;
    cv::rectangle(img, cv::Rect(x0, y0, 101, 101), cv::Scalar(0), 1, cv::LINE_8);
    const int mid = x0 + 50;
    for (int x = mid - white_px[k] / 2; x < mid - white_px[k] / 2 + white_px[k]; ++x) img.at<std::uint8_t>(y0, x) = 255;
  }
  return img;
}

TEST(GapScene, ALineDrawingCutByHalfAMillimetreIsClosedAndByTwoIsNot) {
  const fs::path dir = fresh_dir("gap_scene");
  const fs::path file = dir / "cut_squares.png";
  ASSERT_TRUE(cv::imwrite(file.string(), three_cut_squares({2, 4, 8})));  // 0.5, 1 and 2 mm
  config::Settings s;
  ASSERT_DOUBLE_EQ(s.vision.gap_close_m, 0.001);
  const ImageScene is = build_image_scene(file.string(), s);
  ASSERT_NEAR(is.px_to_m.scale_m_per_px, 0.00025, 1e-12);
  EXPECT_TRUE(is.line_drawing);
  ASSERT_EQ(is.polylines.size(), 3u);
  // Which square a curve is: by its mean x.
  std::array<int, 3> closed{-1, -1, -1};
  for (std::size_t c = 0; c < is.scene->curve_count(); ++c) {
    const Polyline& p = is.polylines[is.scene->source_index(c)];
    double x = 0;
    for (const Vec2& q : p.points_m) x += is.px_to_m.u_px(q.x);
    const int k = std::clamp(static_cast<int>((x / static_cast<double>(p.points_m.size()) - 40) / 180), 0, 2);
    closed[static_cast<std::size_t>(k)] = is.scene->curve(c).closed ? 1 : 0;
  }
  EXPECT_EQ(closed[0], 1) << "0.5 mm gap";
  EXPECT_EQ(closed[2], 0) << "2 mm gap";
  EXPECT_EQ(is.gaps_closed, static_cast<std::size_t>(closed[0] + closed[1]));
  EXPECT_EQ(is.chains_closed_by_gaps, is.gaps_closed);
  // With gap closing off, all three stay open.
  s.vision.gap_close_m = 0.0;
  const ImageScene off = build_image_scene(file.string(), s);
  for (std::size_t c = 0; c < off.scene->curve_count(); ++c) EXPECT_FALSE(off.scene->curve(c).closed);
  EXPECT_EQ(off.gaps_closed, 0u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hk::app
