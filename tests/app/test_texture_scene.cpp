// Texture out, end to end (a picture of pure texture, such as noise or wood grain, gives few
// shapes): generated texture written as PNG and built into a scene with the default settings, the kiosk's
// summary.json saying why the edges went; and the coins, whose every outline stays and nothing else.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "kiosk_exe.hpp"
#include "pictures/image_scene.hpp"
#include "test_paths.hpp"
#include "textures.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;

constexpr std::size_t kFewShapes = 3;  // "few": what a visitor told "It has 3 shapes" can still hold in mind

TEST(TextureScene, PureTextureGivesFewShapes) {
  const fs::path dir = fresh_dir("texture_scene");
  const config::Settings defaults;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    for (const auto& [name, img] : {std::pair{"noise", hk::test::noise_texture(800, 520, seed)},
                                    std::pair{"wood", hk::test::wood_texture(800, 520, seed)}}) {
      const fs::path file = dir / (std::string(name) + std::to_string(seed) + ".png");
      ASSERT_TRUE(cv::imwrite(file.string(), img));
      SCOPED_TRACE(file.filename().string());
      const ImageScene is = build_image_scene(file.string(), defaults);
      EXPECT_EQ(is.detector, vision::Detector::Surround) << "a photograph-like picture goes to the texture test";
      EXPECT_LE(is.polylines.size(), kFewShapes);
      EXPECT_GT(is.chains_texture, 100u) << "and it is the texture test that dropped the edges";
      config::Settings canny = defaults;
      canny.vision.detector = "canny";
      EXPECT_EQ(build_image_scene(file.string(), canny).polylines.size(),
                static_cast<std::size_t>(defaults.vision.max_shapes))
          << "Canny alone fills the shape budget with texture";
    }
  }
  fs::remove_all(dir);
}

TEST(TextureScene, SummarySaysHowManyEdgesWereTexture) {
  const fs::path dir = fresh_dir("texture_summary");
  const fs::path file = dir / "wood.png";
  ASSERT_TRUE(cv::imwrite(file.string(), hk::test::wood_texture(640, 400, 11)));
  const auto r = test::run_kiosk(
      "explore " + test::quoted(file.string()) + " --out " + test::quoted((dir / "out").string()) + " --duration 0.05",
      dir);
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream in(dir / "out" / "summary.json");
  const nlohmann::json sj = nlohmann::json::parse(in);
  EXPECT_EQ(sj["detector"], "surround");
  EXPECT_GT(sj["chains"]["texture"].get<int>(), 50);
  EXPECT_LE(sj["curves"].get<std::size_t>(), kFewShapes);
  fs::remove_all(dir);
}

TEST(TextureScene, EveryCoinStaysAndNothingElse) {
  // coins.png (scikit-image's data.coins) shows 24 coins in four rows of six on a plain dark background. With
  // the defaults the scene is their outlines, one each: 24 curves, each as large as a coin, whose centres fall
  // in four rows of six distinct places — the scribbles Canny finds on the coins' faces are texture.
  const ImageScene is = build_image_scene(std::string(HK_TEST_DATA_DIR) + "/images/coins.png", config::Settings{});
  ASSERT_EQ(is.polylines.size(), 24u) << "one curve per coin, nothing else";
  std::vector<Vec2> centres;
  for (const Polyline& p : is.polylines) {
    Vec2 lo = p.points_m.front(), hi = lo, sum{};
    for (const Vec2& q : p.points_m) {
      lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
      hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
      sum += q;
    }
    EXPECT_GE(std::min(hi.x - lo.x, hi.y - lo.y), 0.008)
        << "as large as a coin (the smallest is about 10 mm across here)";
    centres.push_back(sum * (1.0 / static_cast<double>(p.points_m.size())));
  }
  std::sort(centres.begin(), centres.end(), [](Vec2 a, Vec2 b) { return a.y > b.y; });  // top row first
  for (int row = 0; row < 4; ++row) {
    std::vector<Vec2> r(centres.begin() + 6 * row, centres.begin() + 6 * row + 6);
    const double spread = r.front().y - r.back().y;
    if (row < 3) {
      EXPECT_LT(spread, r.back().y - centres[6 * row + 6].y) << "row " << row << " lies apart from the next";
    }
    std::sort(r.begin(), r.end(), [](Vec2 a, Vec2 b) { return a.x < b.x; });
    for (int i = 1; i < 6; ++i) EXPECT_GT(r[i].x - r[i - 1].x, 0.01) << "row " << row << ": six distinct coins";
  }
}

}  // namespace
}  // namespace hk::app
