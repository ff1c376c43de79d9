// Basic colour terms named in CIELAB (colour_name.hpp).
#include "meaning/colour_name.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace hk::meaning {
namespace {

constexpr std::array<std::string_view, 11> kKeys = {"black", "white", "grey",   "red",  "orange", "yellow",
                                                    "green", "blue",  "purple", "pink", "brown"};
/// Chroma below which a colour is black, grey or white.
constexpr double kAchromaticChroma = 15.0;
/// Each term's own lightness L* (about its focal colour's), what "light" and "dark" are judged against.
constexpr std::array<double, 11> kTermLightness = {10, 95, 55, 50, 70, 90, 55, 40, 40, 80, 40};

BasicColour chromatic_term(Lab c, double chroma) {
  double h = std::atan2(c.b, c.a) * 180.0 / std::numbers::pi;
  if (h < 0) h += 360.0;
  if (h >= 345.0 || h < 55.0) {
    if (c.l >= 60.0 && chroma < 75.0) return BasicColour::pink;
    return c.l < 45.0 && chroma < 50.0 ? BasicColour::brown : BasicColour::red;
  }
  if (h < 85.0) return c.l < 55.0 || chroma < 35.0 ? BasicColour::brown : BasicColour::orange;
  if (h < 115.0) return c.l < 45.0 ? BasicColour::brown : BasicColour::yellow;
  if (h < 190.0) return BasicColour::green;
  if (h < 315.0) return BasicColour::blue;
  return c.l >= 70.0 ? BasicColour::pink : BasicColour::purple;
}

}  // namespace

ColourName name_of(Lab c) {
  const double chroma = std::hypot(c.a, c.b);
  if (chroma < kAchromaticChroma) {
    if (c.l < 20.0) return {BasicColour::black, Shade::plain};
    if (c.l > 88.0) return {BasicColour::white, Shade::plain};
    return {BasicColour::grey, c.l > 70.0 ? Shade::light : c.l < 40.0 ? Shade::dark : Shade::plain};
  }
  const BasicColour term = chromatic_term(c, chroma);
  const double own = kTermLightness[static_cast<std::size_t>(term)];
  const bool never_light = term == BasicColour::yellow || term == BasicColour::pink;
  if (!never_light && c.l >= own + 20.0) return {term, Shade::light};
  if (c.l <= own - 20.0) return {term, Shade::dark};
  return {term, Shade::plain};
}

std::string_view colour_key(BasicColour colour) { return kKeys[static_cast<std::size_t>(colour)]; }

std::string colour_words(ColourName name) {
  const std::string term(colour_key(name.colour));
  return name.shade == Shade::light ? "light " + term : name.shade == Shade::dark ? "dark " + term : term;
}

bool colour_from_words(std::string_view words, ColourName* name) {
  ColourName out;
  if (words.rfind("light ", 0) == 0) {
    out.shade = Shade::light;
    words.remove_prefix(6);
  } else if (words.rfind("dark ", 0) == 0) {
    out.shade = Shade::dark;
    words.remove_prefix(5);
  }
  for (std::size_t i = 0; i < kKeys.size(); ++i)
    if (kKeys[i] == words) {
      out.colour = static_cast<BasicColour>(i);
      *name = out;
      return true;
    }
  return false;
}

bool median_lab(const cv::Mat& bgr, const cv::Mat& mask, Lab* out) {
  if (bgr.empty() || mask.empty() || bgr.size() != mask.size() || bgr.type() != CV_8UC3) return false;
  const cv::Rect box = cv::boundingRect(mask);
  if (box.area() == 0) return false;
  cv::Mat lab;
  bgr(box).convertTo(lab, CV_32FC3, 1.0 / 255.0);
  cv::cvtColor(lab, lab, cv::COLOR_BGR2Lab);
  std::array<std::vector<float>, 3> ch;
  const cv::Mat m = mask(box);
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x)
      if (m.at<std::uint8_t>(y, x)) {
        const cv::Vec3f v = lab.at<cv::Vec3f>(y, x);
        for (int k = 0; k < 3; ++k) ch[static_cast<std::size_t>(k)].push_back(v[k]);
      }
  if (ch[0].empty()) return false;
  double med[3];
  for (std::size_t k = 0; k < 3; ++k) {
    auto mid = ch[k].begin() + static_cast<std::ptrdiff_t>(ch[k].size() / 2);
    std::nth_element(ch[k].begin(), mid, ch[k].end());
    med[k] = *mid;
  }
  *out = {med[0], med[1], med[2]};
  return true;
}

}  // namespace hk::meaning
