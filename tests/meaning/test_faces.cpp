/// @file test_faces.cpp
/// Faces guessed with OpenCV's cascades (meaning/faces.hpp) on the real pictures of tests/data/images: the
/// cameraman's face is found, at his head; no picture without a person (the horse, coins, butterfly, fish,
/// fruit, silhouettes, the sudoku grid, the page, ...) gives one. A guessed face, in a scene, is said as a guess,
/// and staff's name over it or a sidecar's `guesses = false` wins.

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "meaning/faces.hpp"
#include "meaning/names.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace hk::meaning {
namespace {

bool cascades_installed() {
  return fs::exists(std::string(kOpenCvCascadeDir) + "/haarcascade_profileface.xml") &&
         fs::exists(std::string(kOpenCvCascadeDir) + "/haarcascade_frontalface_alt2.xml");
}

TEST(Faces, TheCameramansFaceIsFoundAtHisHead) {
  if (!cascades_installed())
    GTEST_SKIP() << "Debian's opencv-data is not installed (scripts/install-deps.sh installs it)";
  const cv::Mat camera = cv::imread(std::string(HK_TEST_DATA_DIR) + "/images/camera.png");
  ASSERT_FALSE(camera.empty());
  const std::vector<cv::Rect> faces = find_faces(camera);
  ASSERT_EQ(faces.size(), 1u);
  // His face, seen from the side, spans about x 160..255, y 85..200 of the 512 x 512 picture (by eye).
  const cv::Rect& f = faces[0];
  EXPECT_TRUE(f.contains({210, 140})) << f;
  EXPECT_GT(f.width, 40);
  EXPECT_LT(f.width, 180);
}

TEST(Faces, NoPictureWithoutAPersonGivesOne) {
  if (!cascades_installed())
    GTEST_SKIP() << "Debian's opencv-data is not installed (scripts/install-deps.sh installs it)";
  int pictures = 0;
  for (const auto& e : fs::directory_iterator(std::string(HK_TEST_DATA_DIR) + "/images")) {
    if (e.path().filename() == "camera.png") continue;
    const cv::Mat bgr = cv::imread(e.path().string());
    ASSERT_FALSE(bgr.empty()) << e.path();
    EXPECT_TRUE(find_faces(bgr).empty()) << e.path().filename();
    ++pictures;
  }
  EXPECT_GE(pictures, 20);
}

TEST(Faces, AMirroredFaceIsStillFoundAndAGreyPictureAsWell) {
  if (!cascades_installed())
    GTEST_SKIP() << "Debian's opencv-data is not installed (scripts/install-deps.sh installs it)";
  const cv::Mat grey = cv::imread(std::string(HK_TEST_DATA_DIR) + "/images/camera.png", cv::IMREAD_GRAYSCALE);
  cv::Mat mirrored;
  cv::flip(grey, mirrored, 1);
  const std::vector<cv::Rect> faces = find_faces(mirrored);
  ASSERT_EQ(faces.size(), 1u);
  EXPECT_TRUE(faces[0].contains({511 - 210, 140})) << faces[0];
}

TEST(Faces, CascadesThatCannotBeLoadedGiveNoFacesAndAnEmptyPictureNone) {
  const cv::Mat camera = cv::imread(std::string(HK_TEST_DATA_DIR) + "/images/camera.png");
  EXPECT_TRUE(find_faces(camera, "/nonexistent/cascades").empty());
  EXPECT_TRUE(find_faces(cv::Mat()).empty());
}

TEST(GuessedRegions, AFaceIsAnEllipseInItsBoxClippedToThePictureAndStaffCoveringItWins) {
  const std::optional<NamedRegion> face = guessed_region(RegionSource::face, kFaceName, {80, 60, 40, 60}, 100, 100);
  ASSERT_TRUE(face);
  EXPECT_EQ(face->box_px, cv::Rect(80, 60, 20, 40));
  // The ellipse of the whole 40 x 60 box, centre (100, 90): its left end at x 80, its top at y 60.
  EXPECT_EQ(face->mask.at<unsigned char>(2, 1), 0) << "the box's top left corner is outside the ellipse";
  EXPECT_NE(face->mask.at<unsigned char>(30, 1), 0) << "the ellipse's left end is inside";
  EXPECT_NE(face->mask.at<unsigned char>(30, 19), 0) << "its centre is inside";
  EXPECT_FALSE(guessed_region(RegionSource::text, "text: x", {120, 0, 10, 10}, 100, 100)) << "off the picture";
  NamedRegion staff;
  staff.name = "the cameraman";
  staff.box_px = {50, 40, 50, 60};
  staff.mask = cv::Mat(staff.box_px.size(), CV_8U, cv::Scalar(255));
  staff.area_px = staff.box_px.area();
  EXPECT_TRUE(covered_by_staff(*face, {staff}));
  staff.box_px = {0, 0, 50, 50};
  EXPECT_FALSE(covered_by_staff(*face, {staff}));
}

}  // namespace
}  // namespace hk::meaning
