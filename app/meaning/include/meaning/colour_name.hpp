#pragma once
/// @file colour_name.hpp
/// The name of a colour among the eleven basic colour terms (Berlin & Kay, "Basic Color Terms", 1969):
/// black, white, grey, red, orange, yellow, green, blue, purple, pink, brown, with "light" or "dark" where
/// it is far from the term's own lightness. Named in CIELAB (D65, from sRGB: lab_of_srgb) by lightness L*,
/// chroma C* = √(a*² + b*²) and hue angle h = atan2(b*, a*):
///
/// | term | when |
/// |---|---|
/// | black / grey / white | C* < 15 (achromatic): L* < 20 black, L* > 88 white, else grey (light > 70, dark < 40) |
/// | pink | h in [345°, 55°) with L* ≥ 60 and C* < 75; h in [315°, 345°) with L* ≥ 70 |
/// | red | h in [345°, 55°), the rest (brown when L* < 45 and C* < 50) |
/// | orange | h in [55°, 85°) (brown when L* < 55 or C* < 35) |
/// | yellow | h in [85°, 115°) (brown when L* < 45) |
/// | green | h in [115°, 190°) |
/// | blue | h in [190°, 315°) (sRGB's pure blue lies at 306°) |
/// | purple | h in [315°, 345°) |
///
/// A chromatic term is "light" when L* is 20 or more above its own lightness (kTermLightness) and "dark" when
/// 20 or more below; yellow, pink and white are never light, black never dark.

#include <opencv2/core.hpp>

#include <string>
#include <string_view>
#include <vector>

#include "hk/vec2.hpp"

namespace hk::meaning {

/// A basic colour term.
enum class BasicColour { black, white, grey, red, orange, yellow, green, blue, purple, pink, brown };

/// Light, dark, or neither.
enum class Shade { plain, light, dark };

/// A colour's name.
struct ColourName {
  BasicColour colour = BasicColour::grey;
  Shade shade = Shade::plain;
};

/// A colour in CIELAB: L* in [0, 100], a*, b* about [−128, 127].
struct Lab {
  double l = 0, a = 0, b = 0;
};

/// The name of `c` (table in the file comment).
ColourName name_of(Lab c);

/// Words for speech and scene.json: "red", "light blue", "dark grey".
std::string colour_words(ColourName name);

/// The term's key: "black", "white", ..., "brown".
std::string_view colour_key(BasicColour colour);

/// The term and shade parsed from colour_words' output; false for anything else.
bool colour_from_words(std::string_view words, ColourName* name);

/// The CIELAB colour (D65) of the sRGB colour (r, g, b), each in [0, 1] (IEC 61966-2-1; CIE 1976 L*a*b*).
Lab lab_of_srgb(double r, double g, double b);

/// The colour, in CIELAB, of the median (per sRGB channel) of the BGR pixels of `bgr` (8-bit, 3 channels) where
/// `mask` (8-bit, same size) is non-zero. False when no pixel is masked, or the images do not match.
bool median_lab(const cv::Mat& bgr, const cv::Mat& mask, Lab* out);

}  // namespace hk::meaning
