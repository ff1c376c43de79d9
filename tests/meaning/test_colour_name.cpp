/// @file test_colour_name.cpp
/// Basic colour terms named in CIELAB (meaning/colour_name.hpp). The Lab values are those of named sRGB colours
/// (CSS Color 4's keywords) converted with the sRGB transfer function and D65 white, as colour references
/// publish them, rounded to one decimal; lab_of_srgb is checked against them and against OpenCV's conversion.

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <string>

#include "meaning/colour_name.hpp"

namespace hk::meaning {
namespace {

std::string named(double l, double a, double b) { return colour_words(name_of({l, a, b})); }

TEST(ColourName, TheElevenTermsOfNamedSrgbColours) {
  EXPECT_EQ(named(0.0, 0.0, 0.0), "black");       // black
  EXPECT_EQ(named(100.0, 0.0, 0.0), "white");     // white
  EXPECT_EQ(named(53.6, 0.0, 0.0), "grey");       // gray #808080
  EXPECT_EQ(named(53.2, 80.1, 67.2), "red");      // red #ff0000
  EXPECT_EQ(named(74.9, 23.9, 79.0), "orange");   // orange #ffa500
  EXPECT_EQ(named(97.1, -21.6, 94.5), "yellow");  // yellow #ffff00
  EXPECT_EQ(named(46.2, -51.7, 49.9), "green");   // green #008000
  EXPECT_EQ(named(32.3, 79.2, -107.9), "blue");   // blue #0000ff
  EXPECT_EQ(named(29.8, 58.9, -36.5), "purple");  // purple #800080
  EXPECT_EQ(named(83.6, 24.1, 3.3), "pink");      // pink #ffc0cb
  EXPECT_EQ(named(37.5, 26.4, 41.0), "brown");    // saddlebrown #8b4513
}

TEST(ColourName, LightAndDarkAndTheHardCases) {
  EXPECT_EQ(named(77.7, 0.0, 0.0), "light grey");      // silver #c0c0c0
  EXPECT_EQ(named(27.1, 0.0, 0.0), "dark grey");       // #404040
  EXPECT_EQ(named(13.0, 47.5, -64.7), "dark blue");    // navy #000080
  EXPECT_EQ(named(79.2, -14.8, -21.3), "light blue");  // skyblue #87ceeb
  EXPECT_EQ(named(91.1, -48.1, -14.1), "light blue");  // cyan #00ffff: said blue, as people say it
  EXPECT_EQ(named(28.1, 51.0, 41.3), "dark red");      // darkred #8b0000
  EXPECT_EQ(named(65.5, 64.2, -10.6), "pink");         // hotpink #ff69b4
  EXPECT_EQ(named(75.0, 5.0, 24.4), "light brown");    // tan #d2b48c
  EXPECT_EQ(named(43.8, 29.3, 35.2), "brown");         // sienna #a0522d
  EXPECT_EQ(named(95.9, -4.2, 12.0), "white");         // beige #f5f5dc: too little colour to name
}

TEST(ColourName, WordsParseBack) {
  for (int c = 0; c <= static_cast<int>(BasicColour::brown); ++c)
    for (const Shade s : {Shade::plain, Shade::light, Shade::dark}) {
      const ColourName n{static_cast<BasicColour>(c), s};
      ColourName back;
      ASSERT_TRUE(colour_from_words(colour_words(n), &back)) << colour_words(n);
      EXPECT_EQ(back.colour, n.colour);
      EXPECT_EQ(back.shade, n.shade);
    }
  ColourName n;
  EXPECT_FALSE(colour_from_words("mauve", &n));
  EXPECT_FALSE(colour_from_words("light", &n));
}

TEST(ColourName, LabOfSrgbAgreesWithPublishedValuesAndOpenCv) {
  const Lab red = lab_of_srgb(1, 0, 0), blue = lab_of_srgb(0, 0, 1), white = lab_of_srgb(1, 1, 1);
  EXPECT_NEAR(red.l, 53.24, 0.05);
  EXPECT_NEAR(red.a, 80.09, 0.05);
  EXPECT_NEAR(red.b, 67.20, 0.05);
  EXPECT_NEAR(blue.b, -107.86, 0.05);
  EXPECT_NEAR(white.l, 100.0, 0.01);
  EXPECT_NEAR(white.a, 0.0, 0.01);
  // Every 51st level of each channel against OpenCV's float conversion (same D65 white, same formulae).
  for (int r = 0; r < 256; r += 51)
    for (int g = 0; g < 256; g += 51)
      for (int b = 0; b < 256; b += 51) {
        cv::Mat px(1, 1, CV_32FC3, cv::Scalar(b / 255.0, g / 255.0, r / 255.0)), lab;
        cv::cvtColor(px, lab, cv::COLOR_BGR2Lab);
        const cv::Vec3f want = lab.at<cv::Vec3f>(0, 0);
        const Lab got = lab_of_srgb(r / 255.0, g / 255.0, b / 255.0);
        EXPECT_NEAR(got.l, want[0], 0.2) << r << "," << g << "," << b;
        EXPECT_NEAR(got.a, want[1], 0.3) << r << "," << g << "," << b;
        EXPECT_NEAR(got.b, want[2], 0.3) << r << "," << g << "," << b;
      }
}

TEST(ColourName, MedianLabOfAPatchIsItsColourAndIgnoresWhatIsNotMasked) {
  // Red where the mask is, blue elsewhere: the red's Lab (53.2, 80.1, 67.2), within OpenCV's 8-bit rounding.
  cv::Mat bgr(20, 30, CV_8UC3, cv::Scalar(255, 0, 0));
  bgr(cv::Rect(5, 5, 10, 10)).setTo(cv::Scalar(0, 0, 255));
  cv::Mat mask = cv::Mat::zeros(bgr.size(), CV_8U);
  mask(cv::Rect(5, 5, 10, 10)).setTo(255);
  Lab lab;
  ASSERT_TRUE(median_lab(bgr, mask, &lab));
  EXPECT_NEAR(lab.l, 53.2, 0.5);
  EXPECT_NEAR(lab.a, 80.1, 0.5);
  EXPECT_NEAR(lab.b, 67.2, 0.5);
  EXPECT_FALSE(median_lab(bgr, cv::Mat::zeros(bgr.size(), CV_8U), &lab)) << "no pixel masked";
  EXPECT_FALSE(median_lab(cv::Mat(), mask, &lab)) << "no picture";
}

}  // namespace
}  // namespace hk::meaning
