// Pixel -> workspace mapping: the whole image must land inside the device's usable rectangle,
// undistorted, centred, and the map must invert exactly (the display maps the handle back).

#include <gtest/gtest.h>

#include <cmath>

#include "hk/error.hpp"
#include "vision/mapping.hpp"

namespace hk::vision {
namespace {

constexpr double kW = 0.14;  // default usable rectangle (DESIGN.md) [m]
constexpr double kH = 0.09;

TEST(FitToWorkspace, ImageCornersLandInsideTheUsableRectangle) {
  for (const auto& [w, h] :
       std::vector<std::pair<int, int>>{{400, 328}, {1, 1}, {10000, 3}, {3, 10000}, {512, 512}, {800, 600}}) {
    SCOPED_TRACE(std::to_string(w) + " x " + std::to_string(h));
    const PxToM m = fit_to_workspace(w, h, kW, kH);
    const double eps = 1e-12;
    // Outer edges of the corner pixels, and the corner pixel centres.
    for (const double u : {-0.5, 0.0, w - 1.0, w - 0.5}) {
      EXPECT_LE(std::abs(m.x_m(u)), kW / 2 + eps);
    }
    for (const double v : {-0.5, 0.0, h - 1.0, h - 0.5}) {
      EXPECT_LE(std::abs(m.y_m(v)), kH / 2 + eps);
    }
    // The limiting side fills the rectangle exactly.
    const double span_x = m.x_m(w - 0.5) - m.x_m(-0.5);
    const double span_y = m.y_m(-0.5) - m.y_m(h - 0.5);
    EXPECT_TRUE(std::abs(span_x - kW) < 1e-12 || std::abs(span_y - kH) < 1e-12);
  }
}

TEST(FitToWorkspace, CentreMapsToOriginAndYPointsUp) {
  const PxToM m = fit_to_workspace(401, 301, kW, kH);
  EXPECT_NEAR(m.x_m(200), 0.0, 1e-15);
  EXPECT_NEAR(m.y_m(150), 0.0, 1e-15);
  EXPECT_GT(m.y_m(0), m.y_m(300));  // top row of the image is away from the user
  EXPECT_LT(m.x_m(0), m.x_m(400));
  const PxToM even = fit_to_workspace(400, 300, kW, kH);
  EXPECT_NEAR(even.x_m(199.5), 0.0, 1e-15);
  EXPECT_NEAR(even.y_m(149.5), 0.0, 1e-15);
}

TEST(FitToWorkspace, PreservesAspectRatio) {
  const PxToM m = fit_to_workspace(640, 200, kW, kH);
  const double sx = (m.x_m(640) - m.x_m(0)) / 640;
  const double sy = (m.y_m(0) - m.y_m(200)) / 200;
  EXPECT_DOUBLE_EQ(sx, sy);
  EXPECT_DOUBLE_EQ(m.scale_m_per_px, std::min(kW / 640, kH / 200));
  // A 45-degree diagonal in pixels stays at 45 degrees in metres.
  const double dx = m.x_m(110) - m.x_m(10);
  const double dy = m.y_m(10) - m.y_m(110);
  EXPECT_NEAR(dx, dy, 1e-15);
}

TEST(FitToWorkspace, RoundTripsBetweenPixelsAndMetres) {
  const PxToM m = fit_to_workspace(1234, 567, kW, kH);
  for (const double u : {-3.0, 0.0, 17.25, 616.5, 1233.0}) EXPECT_NEAR(m.u_px(m.x_m(u)), u, 1e-9);
  for (const double v : {-3.0, 0.0, 9.75, 283.0, 566.0}) EXPECT_NEAR(m.v_px(m.y_m(v)), v, 1e-9);
  for (const double x : {-0.07, 0.0, 0.031}) EXPECT_NEAR(m.x_m(m.u_px(x)), x, 1e-15);
  for (const double y : {-0.045, 0.0, 0.02}) EXPECT_NEAR(m.y_m(m.v_px(y)), y, 1e-15);
}

TEST(FitToWorkspace, RejectsNonPositiveSizes) {
  EXPECT_THROW(fit_to_workspace(0, 10, kW, kH), hk::ArgumentError);
  EXPECT_THROW(fit_to_workspace(10, -1, kW, kH), hk::ArgumentError);
  EXPECT_THROW(fit_to_workspace(10, 10, 0.0, kH), hk::ArgumentError);
  EXPECT_THROW(fit_to_workspace(10, 10, kW, -0.1), hk::ArgumentError);
  EXPECT_THROW(fit_to_workspace(10, 10, std::nan(""), kH), hk::ArgumentError);
  EXPECT_THROW(fit_to_workspace(10, 10, kW, INFINITY), hk::ArgumentError);
}

}  // namespace
}  // namespace hk::vision
