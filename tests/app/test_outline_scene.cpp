// Exact on silhouettes: every binary silhouette of tests/data/images and silhouettes made here
// (holes, two blobs, a thin neck, sharp cusps) go through build_image_scene ([vision] detector "auto" chooses
// the traced outline); the scene must hold exactly one closed curve per outline of the mask that does not meet
// the picture's frame, and at level 0 lie within 1.5 px of the mask's true boundary (the crack between dark and
// light pixels, computed here from the mask alone) in both directions. The frame is no boundary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "config/load.hpp"
#include "hk/error.hpp"
#include "kiosk_exe.hpp"
#include "pictures/image_scene.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;
using test::test_images;

/// The crack midpoints of a mask (true = dark): between 4-neighbours of different tone [px].
std::vector<cv::Point2d> cracks(const cv::Mat& dark) {
  std::vector<cv::Point2d> out;
  for (int y = 0; y < dark.rows; ++y)
    for (int x = 0; x < dark.cols; ++x) {
      const bool d = dark.at<std::uint8_t>(y, x) != 0;
      if (x + 1 < dark.cols && d != (dark.at<std::uint8_t>(y, x + 1) != 0))
        out.push_back({x + 0.5, static_cast<double>(y)});
      if (y + 1 < dark.rows && d != (dark.at<std::uint8_t>(y + 1, x) != 0))
        out.push_back({static_cast<double>(x), y + 0.5});
    }
  return out;
}

bool touches_frame(const cv::Mat& labels, int label, const cv::Mat& stats) {
  const int x = stats.at<int>(label, cv::CC_STAT_LEFT), y = stats.at<int>(label, cv::CC_STAT_TOP);
  const int w = stats.at<int>(label, cv::CC_STAT_WIDTH), h = stats.at<int>(label, cv::CC_STAT_HEIGHT);
  return x == 0 || y == 0 || x + w == labels.cols || y + h == labels.rows;
}

/// Outlines of the mask that do not meet the frame: each component of the foreground (8-connected) off the
/// frame has one outer outline, each component of the background (4-connected) off the frame is a hole with
/// one. The foreground is the tone with fewer frame pixels.
int count_outlines(const cv::Mat& dark) {
  const cv::Mat light = 255 - dark;
  auto frame = [](const cv::Mat& m) {
    return cv::countNonZero(m.row(0)) + cv::countNonZero(m.row(m.rows - 1)) + cv::countNonZero(m.col(0)) +
           cv::countNonZero(m.col(m.cols - 1));
  };
  const cv::Mat& fg = frame(light) <= frame(dark) ? light : dark;
  const cv::Mat& bg = &fg == &light ? dark : light;
  int n = 0;
  for (const auto& [m, conn] : {std::pair{fg, 8}, std::pair{bg, 4}}) {
    cv::Mat labels, stats, centroids;
    const int k = cv::connectedComponentsWithStats(m, labels, stats, centroids, conn);
    for (int l = 1; l < k; ++l) {
      n += !touches_frame(labels, l, stats);
    }
  }
  return n;
}

/// Distance from p to the segment ab.
double to_segment(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  const cv::Point2d ab = b - a;
  const double l2 = ab.dot(ab);
  const double t = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return cv::norm(p - (a + t * ab));
}

struct Check {
  int closed = 0;
  double vertex_to_crack_px = 0.0;  // the largest distance of a level-0 vertex to the crack
  double crack_to_curve_px = 0.0;   // the largest distance of a crack (off the frame's band) to a level-0 curve
};

Check check_picture(const fs::path& file) {
  config::Settings s;
  s.vision.min_chain_length_m = 0.0;  // every outline, however small: the count is of the mask's outlines
  const ImageScene is = build_image_scene(file.string(), s);
  EXPECT_EQ(is.detector, vision::Detector::Outline) << file;
  const cv::Mat grey = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat dark = grey < 128;
  // The curves at level 0, in pixels.
  std::vector<std::vector<cv::Point2d>> curves;
  Check r;
  const Scene& sc = *is.scene;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    r.closed += ci.closed;
    std::vector<cv::Point2d> pts;
    for (std::uint32_t i = 0; i < ci.point_count[0]; ++i)
      pts.push_back({is.px_to_m.u_px(sc.points(c, 0)[i].x), is.px_to_m.v_px(sc.points(c, 0)[i].y)});
    if (ci.closed) pts.push_back(pts.front());
    curves.push_back(std::move(pts));
  }
  const std::vector<cv::Point2d> crack = cracks(dark);
  for (const auto& pts : curves)
    for (const cv::Point2d& p : pts) {
      double best = 1e9;
      for (const cv::Point2d& q : crack) best = std::min(best, cv::norm(p - q));
      r.vertex_to_crack_px = std::max(r.vertex_to_crack_px, best);
    }
  // Every crack off the frame's band is near a curve, but those of specks too small to make a curve (fewer
  // than 3 boundary pixels: findContours' smallest) — cleared from the mask first.
  cv::Mat clean = dark.clone();
  for (const bool fill_dark : {false, true}) {
    cv::Mat labels, stats, centroids;
    const cv::Mat m = fill_dark ? cv::Mat(255 - clean) : clean;
    const int k = cv::connectedComponentsWithStats(m, labels, stats, centroids, fill_dark ? 4 : 8);
    for (int l = 1; l < k; ++l)
      if (stats.at<int>(l, cv::CC_STAT_AREA) < 3) clean.setTo(fill_dark ? 255 : 0, labels == l);
  }
  for (const cv::Point2d& q : cracks(clean)) {
    if (q.x < 1.5 || q.y < 1.5 || q.x > dark.cols - 2.5 || q.y > dark.rows - 2.5) continue;
    double best = 1e9;
    for (const auto& pts : curves)
      for (std::size_t i = 1; i < pts.size() && best > 0.5; ++i)
        best = std::min(best, to_segment(q, pts[i - 1], pts[i]));
    r.crack_to_curve_px = std::max(r.crack_to_curve_px, best);
  }
  return r;
}

/// Silhouettes made here, whose outlines are known: name, picture.
std::vector<std::pair<std::string, cv::Mat>> made_silhouettes() {
  std::vector<std::pair<std::string, cv::Mat>> out;
  auto canvas = [] { return cv::Mat(240, 320, CV_8UC1, cv::Scalar(255)); };
  cv::Mat holes = canvas();  // a plate with three holes: 4 outlines
  cv::rectangle(holes, cv::Rect(40, 30, 240, 180), cv::Scalar(0), cv::FILLED);
  cv::circle(holes, {100, 90}, 25, cv::Scalar(255), cv::FILLED);
  cv::circle(holes, {200, 150}, 35, cv::Scalar(255), cv::FILLED);
  cv::rectangle(holes, cv::Rect(80, 150, 40, 30), cv::Scalar(255), cv::FILLED);
  out.emplace_back("holes", holes);
  cv::Mat blobs = canvas();  // two blobs: 2 outlines
  cv::ellipse(blobs, {90, 120}, {60, 40}, 30, 0, 360, cv::Scalar(0), cv::FILLED);
  cv::circle(blobs, {230, 110}, 50, cv::Scalar(0), cv::FILLED);
  out.emplace_back("two_blobs", blobs);
  cv::Mat neck = canvas();  // two disks joined by a neck 8 px wide: 1 outline
  cv::circle(neck, {80, 120}, 50, cv::Scalar(0), cv::FILLED);
  cv::circle(neck, {240, 120}, 50, cv::Scalar(0), cv::FILLED);
  cv::rectangle(neck, cv::Rect(120, 116, 80, 8), cv::Scalar(0), cv::FILLED);
  out.emplace_back("thin_neck", neck);
  cv::Mat cusps = canvas();  // a crescent (two sharp tips) and a 15-degree spike: 2 outlines
  cv::circle(cusps, {110, 120}, 80, cv::Scalar(0), cv::FILLED);
  cv::circle(cusps, {150, 120}, 75, cv::Scalar(255), cv::FILLED);
  const std::vector<cv::Point> spike{{240, 40}, {270, 40}, {300, 200}};
  cv::fillPoly(cusps, std::vector<std::vector<cv::Point>>{spike}, cv::Scalar(0));
  out.emplace_back("cusps", cusps);
  return out;
}

}  // namespace

TEST(OutlineScene, TheSettingsOfferExactlyTheDetectorsVisionKnows) {
  // The settings' choices (config, which does not link vision) and vision's names are two lists: kept equal.
  const config::FieldDescriptor* d = config::find_field("vision", "detector");
  ASSERT_NE(d, nullptr);
  ASSERT_EQ(d->choices.size(), 6u);
  for (const auto& name : d->choices)
    EXPECT_EQ(vision::detector_name(vision::detector_from_name(std::string(name))), name);
  EXPECT_THROW(vision::detector_from_name("sobel"), hk::ArgumentError);
}

TEST(OutlineScene, MadeSilhouettesGiveOneClosedCurvePerOutlineOnTheBoundary) {
  const fs::path dir = fresh_dir("outline_scene");
  const std::vector<int> expected{4, 2, 1, 2};
  const auto made = made_silhouettes();
  for (std::size_t i = 0; i < made.size(); ++i) {
    const auto& [name, img] = made[i];
    const fs::path file = dir / (name + ".png");
    ASSERT_TRUE(cv::imwrite(file.string(), img));
    const int n = count_outlines(img < 128);
    ASSERT_EQ(n, expected[i]) << name << ": the mask's own count (the test's arithmetic)";
    const Check r = check_picture(file);
    EXPECT_EQ(r.closed, n) << name;
    EXPECT_LE(r.vertex_to_crack_px, 1.5) << name;
    EXPECT_LE(r.crack_to_curve_px, 1.5) << name;
  }
  fs::remove_all(dir);
}

TEST(OutlineScene, TheShippedSilhouettesGiveOneClosedCurvePerOutlineOnTheBoundary) {
  int pictures = 0;
  for (const fs::path& file : test_images()) {
    if (file.filename().string().rfind("silhouette_", 0) != 0) continue;
    ++pictures;
    const cv::Mat grey = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    const int n = count_outlines(grey < 128);
    const Check r = check_picture(file);
    EXPECT_EQ(r.closed, n) << file.filename() << ": specks and pinholes of one pixel count too";
    EXPECT_LE(r.vertex_to_crack_px, 1.5) << file.filename();
    EXPECT_LE(r.crack_to_curve_px, 1.5) << file.filename();
  }
  EXPECT_EQ(pictures, 10);
}

}  // namespace hk::app
