// Texture out: the surround annulus, the surround at chain points, the stand-out test, and
// the detectors side by side on generated texture and real pictures.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include <opencv2/imgproc.hpp>

#include "chain_checks.hpp"
#include "hk/error.hpp"
#include "test_paths.hpp"
#include "textures.hpp"
#include "vision/intake.hpp"
#include "vision/pipeline.hpp"
#include "vision/texture.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;

double length_of(const std::vector<Chain>& chains) {
  double l = 0.0;
  for (const Chain& c : chains) l += chain_length_px(c);
  return l;
}

TEST(SurroundMean, IsANormalisedAnnulusThatLeavesThePixelOut) {
  // The response to a unit impulse is the kernel itself: zero at the centre, non-negative, summing to 1, and
  // equal to the closed form (exp(-r²/2σo²) - exp(-r²/2σi²)) / (2π (σo² - σi²)) away from the border.
  const double sigma = 2.0, so = kSurroundRatio * sigma;
  cv::Mat impulse = cv::Mat::zeros(101, 101, CV_32F);
  impulse.at<float>(50, 50) = 1.0f;
  const cv::Mat k = surround_mean(impulse, sigma);
  double sum = 0.0, min = 1.0;
  for (int y = 0; y < k.rows; ++y)
    for (int x = 0; x < k.cols; ++x) {
      sum += k.at<float>(y, x);
      min = std::min(min, static_cast<double>(k.at<float>(y, x)));
    }
  EXPECT_NEAR(sum, 1.0, 1e-3);
  EXPECT_GT(min, -1e-6);
  EXPECT_NEAR(k.at<float>(50, 50), 0.0, 1e-6) << "the pixel itself does not count";
  for (const int r : {2, 4, 8, 12}) {
    const double expected = (std::exp(-r * r / (2 * so * so)) - std::exp(-r * r / (2 * sigma * sigma))) /
                            (2 * std::numbers::pi * (so * so - sigma * sigma));
    EXPECT_NEAR(k.at<float>(50, 50 + r), expected, 0.02 * expected + 1e-6) << "r = " << r;
  }
  // A constant stays that constant.
  const cv::Mat flat = surround_mean(cv::Mat(40, 60, CV_32F, cv::Scalar(7.0)), sigma);
  EXPECT_NEAR(cv::norm(flat - 7.0, cv::NORM_INF), 0.0, 1e-4);
  EXPECT_THROW(surround_mean(cv::Mat(10, 10, CV_8U), sigma), hk::ArgumentError);
  EXPECT_THROW(surround_mean(impulse, 0.0), hk::ArgumentError);
}

TEST(StandsOut, CountsThePointsThatKeepTheLowThreshold) {
  // strength − α·surround >= low at 2 of 5 points = 40 %: kept; at 1 of 5: texture.
  const std::vector<double> strength{100, 100, 100, 60, 60};
  const std::vector<double> surround{20, 20, 60, 20, 20};  // α = 1.5: 70, 70, 10, 30, 30
  EXPECT_TRUE(stands_out(strength, surround, 1.5, 70.0));
  EXPECT_FALSE(stands_out(strength, surround, 1.5, 70.1));
  EXPECT_FALSE(stands_out(strength, {60, 20, 60, 20, 20}, 1.5, 70.0)) << "1 of 5";
  EXPECT_TRUE(stands_out(strength, surround, 0.0, 60.0)) << "alpha 0: every point that reaches low";
  EXPECT_TRUE(stands_out({}, {}, 1.5, 70.0)) << "an empty chain is kept";
}

TEST(ChainSurround, IsLowBesideALoneEdgeAndHighInTextureAndLeavesTheImageAlone) {
  // A lone step edge on a flat background: the annulus sees the edge's own continuation along it only, a
  // small part of the ring; in noise the surround is about as strong as the edge pixels.
  cv::Mat step(200, 200, CV_8U, cv::Scalar(60));
  step(cv::Rect(100, 0, 100, 200)).setTo(180);
  const cv::Mat before = step.clone();
  EdgeParams ep;
  const EdgeMap em = detect_edges(step, ep);
  const std::vector<Chain> chains = link_edges(em.edges, 20.0);
  ASSERT_EQ(chains.size(), 1u);
  const PointValues s = chain_surround(step, ep.blur_sigma_px, chains);
  ASSERT_EQ(s[0].size(), chains[0].points_px.size());
  // The step's magnitude: 8·120/(1.5·√(2π)) ≈ 255 at the edge; away from the ends, the ring sees the edge on
  // two short arcs.
  const double peak = 8.0 * 120.0 / (1.5 * std::sqrt(2.0 * std::numbers::pi));
  for (std::size_t i = 30; i + 30 < s[0].size(); ++i) EXPECT_LT(s[0][i], 0.25 * peak) << i;
  EXPECT_EQ(cv::norm(step, before, cv::NORM_INF), 0.0) << "grey is not blurred in place";

  const cv::Mat noise = hk::test::noise_texture(300, 200, 3);
  const EdgeMap en = detect_edges(noise, ep);
  const std::vector<Chain> nc = link_edges(en.edges, 20.0);
  ASSERT_GT(nc.size(), 10u);
  const PointValues ns = chain_surround(noise, ep.blur_sigma_px, nc);
  double surround = 0.0, n = 0.0;
  for (const auto& v : ns)
    for (const double x : v) surround += x, n += 1;
  EXPECT_GT(surround / n, 0.4 * en.high) << "texture all round";
  EXPECT_THROW(chain_surround(cv::Mat(), 1.5, {}), hk::ArgumentError);
  EXPECT_THROW(chain_surround(step, -1.0, {}), hk::ArgumentError);
}

TEST(Detectors, SurroundKeepsExactlyTheCannyChainsThatStandOut) {
  // The texture test inside the pipeline against one computed here from the same Canny chains: strengths from
  // our own Sobel of the blurred picture, chain_surround on the picture as it came, stands_out with the
  // pipeline's thresholds. (Regression: the strength pass once blurred the grey image in place, so the
  // surround was taken on a picture blurred twice.) Pictures below max_image_side_px: no shrinking.
  for (const auto& [name, img] :
       {std::pair{"noise", hk::test::noise_texture(400, 300, 4)},
        std::pair{"wood", hk::test::wood_texture(400, 300, 4)},
        std::pair{"coins", load_image(std::string(HK_TEST_DATA_DIR) + "/images/coins.png", {})}}) {
    SCOPED_TRACE(name);
    cv::Mat grey;
    if (img.channels() == 3) {
      cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
    } else {
      grey = img;
    }
    ExtractParams p;
    p.detector = Detector::Canny;
    const Extraction canny = extract_chains_from_image(grey, p);
    ASSERT_EQ(canny.px_scale, 1.0);
    p.detector = Detector::Surround;
    const Extraction surround = extract_chains_from_image(grey, p);
    cv::Mat blurred, gx, gy;
    cv::GaussianBlur(grey, blurred, cv::Size(0, 0), p.edges.blur_sigma_px, p.edges.blur_sigma_px, cv::BORDER_REPLICATE);
    cv::Sobel(blurred, gx, CV_64F, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::Sobel(blurred, gy, CV_64F, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    const PointValues around = chain_surround(grey, p.edges.blur_sigma_px, canny.chains);
    std::size_t standing = 0;
    for (std::size_t k = 0; k < canny.chains.size(); ++k) {
      std::vector<double> strength;
      for (const cv::Point2d& q : canny.chains[k].points_px)
        strength.push_back(std::hypot(gx.at<double>(static_cast<int>(q.y), static_cast<int>(q.x)),
                                      gy.at<double>(static_cast<int>(q.y), static_cast<int>(q.x))));
      standing += stands_out(strength, around[k], p.surround_inhibition, canny.edge_map.low);
    }
    EXPECT_EQ(surround.chains.size(), standing);
    EXPECT_EQ(surround.texture_chains, canny.chains.size() - standing);
  }
}

TEST(Detectors, EveryDetectorGivesSaneChainsOnEveryTestPicture) {
  for (const auto& entry : fs::directory_iterator(std::string(HK_TEST_DATA_DIR) + "/images")) {
    for (const Detector d : {Detector::Canny, Detector::Surround, Detector::Bilateral, Detector::Edpf}) {
      SCOPED_TRACE(entry.path().filename().string() + " " + detector_name(d));
      ExtractParams p;
      p.detector = d;
      const Extraction ex = extract_chains(entry.path().string(), p);
      EXPECT_EQ(ex.detector_used, d);
      ASSERT_GE(ex.chains.size(), 1u) << "every test picture has an edge each detector finds";
      ASSERT_EQ(ex.point_strength.size(), ex.chains.size());
      test::expect_chains_sane(ex.chains, ex.width_px, ex.height_px);
      for (const Chain& c : ex.chains) EXPECT_GE(chain_length_px(c) / ex.px_scale, p.min_chain_length_px - 1e-9);
      if (d != Detector::Surround) {
        EXPECT_EQ(ex.texture_chains, 0u);
      }
    }
  }
}

TEST(Detectors, SurroundDropsGeneratedTextureAndKeepsTheCoins) {
  // Pure texture: Canny links thousands of chains in generated noise and follows every grain line of the
  // wood; the surround test keeps a few per cent of that length at most. The coins lie on a plain
  // background: the texture test keeps nearly all of their outlines' length.
  ExtractParams p;  // the defaults: α = 1.5
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    for (const auto& [name, img] : {std::pair{"noise", hk::test::noise_texture(800, 520, seed)},
                                    std::pair{"wood", hk::test::wood_texture(800, 520, seed)}}) {
      SCOPED_TRACE(std::string(name) + " seed " + std::to_string(seed));
      p.detector = Detector::Canny;
      const Extraction canny = extract_chains_from_image(img, p);
      p.detector = Detector::Surround;
      const Extraction surround = extract_chains_from_image(img, p);
      EXPECT_GT(length_of(canny.chains), 20000.0) << "Canny finds the texture";
      EXPECT_LT(length_of(surround.chains), 0.05 * length_of(canny.chains));
      EXPECT_EQ(surround.texture_chains + surround.chains.size(), canny.chains.size()) << "the same chains, tested";
    }
  }
  p.detector = Detector::Canny;
  const std::string coins = std::string(HK_TEST_DATA_DIR) + "/images/coins.png";
  const Extraction canny = extract_chains(coins, p);
  p.detector = Detector::Surround;
  const Extraction surround = extract_chains(coins, p);
  std::size_t closed_canny = 0, closed_surround = 0;
  for (const Chain& c : canny.chains) closed_canny += c.closed;
  for (const Chain& c : surround.chains) closed_surround += c.closed;
  EXPECT_GE(closed_surround, closed_canny - 1) << "the coins' closed outlines stay";
  EXPECT_GE(length_of(surround.chains), 0.7 * length_of(canny.chains));
}

}  // namespace
}  // namespace hk::vision
