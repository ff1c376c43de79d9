#pragma once
/// @file tactile_scene.hpp
/// The scene a visitor felt, as a tactile copy's input: each curve at the visitor's level, or coarser where the
/// finer detail is below what a fingertip tells apart on the page (kTactileToleranceMm at the page's scale, the
/// curve's own wavelet levels: Pai & Reissell §3, the level whose error bound is within the tolerance), named as the
/// visitor hears it.

#include <string>

#include "copies/tactile_graphic.hpp"
#include "pictures/image_scene.hpp"

namespace hk::app {

/// `is` (built, with its scene) as the copy's input on `paper`: the picture's rectangle, each curve at `level`
/// (a level id as the kiosk's Finer / Coarser keys set it, clamped per curve) or coarser down to the coarsest
/// within kTactileToleranceMm on the page; each shape's name in `language` (staff's, then the kiosk's guesses;
/// "" when it has none) and its number (its index in `is.polylines` + 1); `title` above it.
/// @throws hk::ArgumentError when `is` has no scene.
TactileInput tactile_input_of(const ImageScene& is, int level, Paper paper, const std::string& language,
                              const std::string& title, BrailleGrade grade = BrailleGrade::two);

}  // namespace hk::app
