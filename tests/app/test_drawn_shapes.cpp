/// @file test_drawn_shapes.cpp
/// What each shape is, end to end on a drawn picture of a red circle, a blue square and a green triangle on
/// white, through the whole scene build (edges, linking, simplification, multiresolution):
/// - what the kiosk sees for itself: each shape's descriptor names its form and colour; the same when the
///   picture is scaled, turned and saved as a JPEG at quality 70;
/// - names staff wrote, in files written as the IIIF cookbook's recipes write them (tests/data/annotations):
///   a Manifest whose canvas is twice the picture's size (tagging; FragmentSelector in pixels and in percent;
///   an SvgSelector path drawn as a stroke under a transform), an AnnotationPage in the picture's pixels (an
///   open SVG path along a shape), a Presentation 2 AnnotationList (oa:Choice, oa:Tag); Where and Describe
///   say them.
/// The shapes are found by where they were drawn, not by their order.

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "audio/messages.hpp"
#include "config/settings.hpp"
#include "meaning/faces.hpp"
#include "meaning/shape_descriptors.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_names.hpp"
#include "test_paths.hpp"
#include "vision/ocr.hpp"
#include "visit/answers.hpp"

namespace hk::app {
namespace {

struct Drawn {
  cv::Point2d centre_px;
  meaning::Form form;
  std::string colour;
};

/// A 800 x 520 white picture with a red circle, a blue square and a green triangle, each about `size_px`
/// across, turned by `turn_deg` about its own centre.
cv::Mat draw(double size_px, double turn_deg, std::vector<Drawn>* drawn) {
  cv::Mat bgr(520, 800, CV_8UC3, cv::Scalar(255, 255, 255));
  const double r = size_px / 2, t = turn_deg * std::numbers::pi / 180.0;
  const cv::Point2d c1{170, 260}, c2{400, 260}, c3{630, 260};
  cv::circle(bgr, c1, static_cast<int>(r), cv::Scalar(0, 0, 230), cv::FILLED, cv::LINE_AA);
  auto polygon = [&](cv::Point2d c, int corners, double radius, double start, cv::Scalar colour) {
    std::vector<cv::Point> p;
    for (int i = 0; i < corners; ++i) {
      const double a = start + t + 2 * std::numbers::pi * i / corners;
      p.emplace_back(static_cast<int>(std::lround(c.x + radius * std::cos(a))),
                     static_cast<int>(std::lround(c.y + radius * std::sin(a))));
    }
    cv::fillPoly(bgr, std::vector<std::vector<cv::Point>>{p}, colour, cv::LINE_AA);
  };
  polygon(c2, 4, r * std::sqrt(2.0), std::numbers::pi / 4, cv::Scalar(220, 60, 20));
  polygon(c3, 3, r * 1.1, -std::numbers::pi / 2, cv::Scalar(40, 170, 30));
  *drawn = {
      {c1, meaning::Form::round, "red"}, {c2, meaning::Form::square, "blue"}, {c3, meaning::Form::triangle, "green"}};
  return bgr;
}

cv::Mat as_jpeg(const cv::Mat& bgr, int quality) {
  std::vector<std::uint8_t> bytes;
  cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
  return cv::imdecode(bytes, cv::IMREAD_COLOR);
}

/// The closed shape of `is` (not a speck) whose points' mean lies within 4 mm of picture pixel `centre_px`; −1
/// for none.
int outline_around(const ImageScene& is, cv::Point2d centre_px) {
  const Vec2 c{is.px_to_m.x_m(centre_px.x), is.px_to_m.y_m(centre_px.y)};
  int found = -1;
  for (std::size_t i = 0; i < is.polylines.size(); ++i) {
    const Polyline& p = is.polylines[i];
    if (!p.closed || is.descriptors[i].speck) continue;
    Vec2 mean;
    for (const Vec2& q : p.points_m) mean += q;
    mean = (1.0 / static_cast<double>(p.points_m.size())) * mean;
    if (length(mean - c) < 0.004) found = static_cast<int>(i);
  }
  return found;
}

/// Checks that each drawn shape has a curve around it whose descriptor names its form and colour.
void expect_named(const cv::Mat& bgr, const std::vector<Drawn>& drawn, const std::string& what) {
  const config::Settings s;
  const ImageScene is = build_image_scene_from_picture(bgr, what, s);
  ASSERT_EQ(is.descriptors.size(), is.polylines.size()) << what;
  for (const Drawn& d : drawn) {
    const int found = outline_around(is, d.centre_px);
    ASSERT_GE(found, 0) << what << ": no closed outline around the " << d.colour << " shape";
    const meaning::ShapeDescriptor& desc = is.descriptors[static_cast<std::size_t>(found)];
    EXPECT_EQ(meaning::form_key(desc.form.form), meaning::form_key(d.form)) << what << ", the " << d.colour << " shape";
    ASSERT_TRUE(desc.has_colour) << what;
    EXPECT_EQ(meaning::colour_key(desc.colour.colour), d.colour) << what << ": " << meaning::colour_words(desc.colour);
    EXPECT_GT(desc.size_cm, 1.0) << what;
  }
}

TEST(DrawnShapes, ARedCircleABlueSquareAndAGreenTriangleAreNamedByFormAndColour) {
  std::vector<Drawn> drawn;
  const cv::Mat bgr = draw(160, 0, &drawn);
  expect_named(bgr, drawn, "drawn");
}

TEST(DrawnShapes, ScaledTurnedAndJpegNoisyTheyAreStillNamedRight) {
  for (const double size : {90.0, 180.0})
    for (const double turn : {0.0, 20.0, 35.0}) {
      std::vector<Drawn> drawn;
      const cv::Mat bgr = as_jpeg(draw(size, turn, &drawn), 70);
      expect_named(bgr, drawn,
                   "size " + std::to_string(size) + " px, turned " + std::to_string(turn) + " deg, JPEG 70");
    }
}

/// The picture of ARedCircle... drawn at 160 px, its scene built, and the names of `file` (tests/data/annotations)
/// put on it as the picture "shapes.png".
struct Named {
  std::vector<Drawn> drawn;
  ImageScene is;
  PictureNames names;
  explicit Named(const std::string& file) {
    is = build_image_scene_from_picture(draw(160, 0, &drawn), "shapes.png", config::Settings{});
    apply_names(is, std::string(HK_TEST_DATA_DIR) + "/annotations/" + file, "shapes.png");
    names = picture_names(is.regions, is.shape_region, is.polylines.size(), is.px_to_m);
  }
  /// The name of the closed shape drawn at drawn[k] ("" none).
  std::string name_of(std::size_t k) const {
    const int i = outline_around(is, drawn[k].centre_px);
    return i < 0 || names.shape_name.empty() ? "" : names.shape_name[static_cast<std::size_t>(i)];
  }
  ShownView view() const {
    static const std::vector<TextBlockM> none;
    static const PictureNotes no_notes;
    return {is.polylines, is.descriptors, none, no_notes, {0.07, 0.045}, false, false, &names, &is.regions, is.px_to_m};
  }
};

TEST(StaffNames, AManifestWhoseCanvasIsTwiceThePictureNamesEachShapeAndAnEmptyRegion) {
  const Named n("tagging_manifest.json");
  EXPECT_EQ(n.name_of(0), "the sun");
  EXPECT_EQ(n.name_of(1), "the box");
  EXPECT_EQ(n.name_of(2), "the roof") << "an SVG path drawn as a stroke stands for what it encloses";
  ASSERT_EQ(n.names.parts.size(), 4u);
  EXPECT_EQ(n.names.parts[0].name, "the sky") << "largest first";
  const audio::MessageCatalog& m = audio::MessageCatalog::english();
  // The sky has no shape in it: Where there still names it.
  const Vec2 sky{n.is.px_to_m.x_m(400), n.is.px_to_m.y_m(30)};
  EXPECT_EQ(where_answer(n.view(), m, sky, -1), "In the sky. Your hand is in the far middle.");
  // On the circle's outline: its name.
  const Vec2 rim{n.is.px_to_m.x_m(170), n.is.px_to_m.y_m(180)};
  const std::string on = where_answer(n.view(), m, rim, -1);
  EXPECT_NE(on.find(": the sun."), std::string::npos) << on;
  // Describe: the named parts first, largest first, then nothing unnamed is left.
  const std::string d = describe_answer(n.view(), m, {0, 0}, {0, 0});
  EXPECT_EQ(d.rfind("3 shapes. The sky in the far middle, ", 0), 0u) << d;
  EXPECT_NE(d.find("the sun on the left"), std::string::npos) << d;
  EXPECT_EQ(d.find("Also"), std::string::npos) << d;
}

TEST(StaffNames, AnOpenSvgPathNamesTheShapeAlongItAndPixelBoxesNeedNoCanvas) {
  const Named n("annotation_page_pixels.json");
  EXPECT_EQ(n.name_of(0), "the left shape");
  EXPECT_EQ(n.name_of(1), "") << "no region holds the square";
  EXPECT_EQ(n.name_of(2), "the roof edge");
  const std::string d = describe_answer(n.view(), audio::MessageCatalog::english(), {0, 0}, {0, 0});
  EXPECT_NE(d.find(". Also a medium blue square in the middle."), std::string::npos) << d;
}

TEST(StaffNames, APresentationTwoListNamesByItsTagAndAChoiceTakesTheSvg) {
  const Named n("annotation_list_v2.json");
  EXPECT_EQ(n.name_of(0), "the disc");
  ASSERT_EQ(n.is.regions.size(), 2u);
  EXPECT_EQ(n.is.regions[0].description, "A red disc, the first shape drawn.");
  EXPECT_TRUE(n.is.regions[1].name.empty()) << "a comment alone names nothing";
}

}  // namespace
}  // namespace hk::app

namespace hk::app {
namespace {

// The cameraman: the face the kiosk guesses names the shapes in it, said as a guess; a sidecar's
// `guesses = false` (apply_names' guesses) leaves the picture without it.
TEST(GuessedNames, TheCameramansFaceIsSaidAsAGuessUnlessGuessesAreOff) {
  if (!std::filesystem::exists(std::string(meaning::kOpenCvCascadeDir) + "/haarcascade_profileface.xml"))
    GTEST_SKIP() << "Debian's opencv-data is not installed (scripts/install-deps.sh installs it)";
  const cv::Mat camera = cv::imread(std::string(HK_TEST_DATA_DIR) + "/images/camera.png");
  ImageScene is = build_image_scene_from_picture(camera, "camera.png", config::Settings{});
  ASSERT_EQ(is.faces_m.size(), 1u);
  apply_names(is, "", "camera.png", true);
  ASSERT_EQ(is.regions.size(), 1u);
  EXPECT_EQ(is.regions[0].source, meaning::RegionSource::face);
  const std::size_t named = static_cast<std::size_t>(std::count(is.shape_region.begin(), is.shape_region.end(), 0));
  EXPECT_GE(named, 1u) << "the outlines of his face take its name";
  const PictureNames names = picture_names(is.regions, is.shape_region, is.polylines.size(), is.px_to_m, &is.polylines);
  static const std::vector<TextBlockM> none;
  static const PictureNotes no_notes;
  const ShownView view{is.polylines, is.descriptors, none,   no_notes,    {0.07, 0.045},
                       false,        false,          &names, &is.regions, is.px_to_m};
  const std::string said = describe_answer(view, audio::MessageCatalog::english(), {0.07, -0.045}, {0.07, -0.045});
  EXPECT_NE(said.find("omething that could be a face"), std::string::npos) << said;
  EXPECT_EQ(said.find("the something"), std::string::npos) << "a guess takes no article: " << said;
  apply_names(is, "", "camera.png", false);
  EXPECT_TRUE(is.regions.empty());
  EXPECT_EQ(std::count(is.shape_region.begin(), is.shape_region.end(), -1),
            static_cast<std::ptrdiff_t>(is.polylines.size()));
}

// A block of text read from a picture names the shapes in it by its first sure words; on a document page, whose
// text is read as text, it names nothing.
TEST(GuessedNames, ATextBlockOfAPictureNamesTheShapesInItByItsFirstSureWords) {
  ImageScene is;
  is.picture = cv::Mat(100, 200, CV_8UC3, cv::Scalar(255, 255, 255));
  is.px_to_m = vision::fit_to_workspace(200, 100, 0.14, 0.09);
  Polyline letter{{}, true};
  for (const auto& [u, v] : {std::pair{40.0, 40.0}, {60.0, 40.0}, {60.0, 60.0}, {40.0, 60.0}})
    letter.points_m.push_back({is.px_to_m.x_m(u), is.px_to_m.y_m(v)});
  is.polylines = {letter};
  TextBlockM block;
  block.lo_m = {is.px_to_m.x_m(20), is.px_to_m.y_m(80)};
  block.hi_m = {is.px_to_m.x_m(180), is.px_to_m.y_m(20)};
  block.text = std::string("Emergency ") + std::string(vision::kUnclearWord) + "xit this way out now";
  is.text_blocks = {block};
  add_guessed_regions(is);
  ASSERT_EQ(is.regions.size(), 1u);
  EXPECT_EQ(is.regions[0].name, "text: Emergency this way out");
  EXPECT_EQ(is.regions[0].source, meaning::RegionSource::text);
  EXPECT_EQ(is.shape_region, std::vector<int>{0});
  is.regions.clear();
  is.pages = 1;
  add_guessed_regions(is);
  EXPECT_TRUE(is.regions.empty());
  EXPECT_EQ(is.shape_region, std::vector<int>{-1});
}

}  // namespace
}  // namespace hk::app
