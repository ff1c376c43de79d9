#pragma once
// The guided tour's test picture: five separate filled shapes, black on white, drawn
// with OpenCV, so each is one closed outline after edge detection. Shared by tests/app/test_guided_tour.cpp
// and bench/tour_time.cpp.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace hk::test {

/// Writes the five-shape picture (700 x 450 px: a disc, a square, a triangle, an ellipse and a tilted
/// rectangle, at least 60 px apart) to `path` (.png). Returns false when it cannot be written.
inline bool write_five_shapes_png(const std::string& path) {
  cv::Mat img(450, 700, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Scalar ink(0, 0, 0);
  cv::circle(img, {120, 110}, 60, ink, cv::FILLED, cv::LINE_AA);
  cv::rectangle(img, cv::Rect(300, 50, 110, 110), ink, cv::FILLED, cv::LINE_AA);
  const std::vector<cv::Point> tri{{520, 190}, {660, 190}, {590, 50}};
  cv::fillConvexPoly(img, tri, ink, cv::LINE_AA);
  cv::ellipse(img, {190, 330}, {110, 55}, 0, 0, 360, ink, cv::FILLED, cv::LINE_AA);
  cv::Point2f corners[4];
  cv::RotatedRect({500.0f, 335.0f}, {150.0f, 70.0f}, 25.0f).points(corners);
  const std::vector<cv::Point> rect{corners[0], corners[1], corners[2], corners[3]};
  cv::fillConvexPoly(img, rect, ink, cv::LINE_AA);
  return cv::imwrite(path, img);
}

}  // namespace hk::test
