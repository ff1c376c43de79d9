// Basic colour terms named in CIELAB (colour_name.hpp).
#include "meaning/colour_name.hpp"

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

Lab lab_of_srgb(double r, double g, double b) {
  // IEC 61966-2-1 sRGB: companding undone, then linear RGB to XYZ (D65), then CIE 1976 L*a*b* against D65 white.
  const auto linear = [](double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); };
  const double rl = linear(r), gl = linear(g), bl = linear(b);
  const double x = (0.4124564 * rl + 0.3575761 * gl + 0.1804375 * bl) / 0.95047;
  const double y = 0.2126729 * rl + 0.7151522 * gl + 0.0721750 * bl;
  const double z = (0.0193339 * rl + 0.1191920 * gl + 0.9503041 * bl) / 1.08883;
  const auto f = [](double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0; };
  const double fx = f(x), fy = f(y), fz = f(z);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

bool median_lab(const cv::Mat& bgr, const cv::Mat& mask, Lab* out) {
  if (bgr.empty() || mask.empty() || bgr.size() != mask.size() || bgr.type() != CV_8UC3) return false;
  // Per-channel histograms of the masked pixels, their medians, then one conversion (not the whole patch:
  // OpenCV's BGR→Lab builds its tables on first use, about 0.1 s a process).
  std::array<std::array<std::size_t, 256>, 3> hist{};
  std::size_t n = 0;
  for (int y = 0; y < bgr.rows; ++y) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    const std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < bgr.cols; ++x) {
      if (!m[x]) continue;
      for (std::size_t k = 0; k < 3; ++k) ++hist[k][row[x][static_cast<int>(k)]];
      ++n;
    }
  }
  if (n == 0) return false;
  double median[3];
  for (std::size_t k = 0; k < 3; ++k) {
    std::size_t seen = 0, v = 0;
    while (seen + hist[k][v] <= n / 2) seen += hist[k][v++];
    median[k] = static_cast<double>(v) / 255.0;
  }
  *out = lab_of_srgb(median[2], median[1], median[0]);  // B, G, R order in the Mat
  return true;
}

}  // namespace hk::meaning
