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

/// What a copy is made of: a built scene, what names its shapes and where its picture lies. Views: what they
/// point to outlives the call.
struct SceneToCopy {
  const Scene* scene = nullptr;                                ///< the multiresolution curves
  const std::vector<meaning::NamedRegion>* regions = nullptr;  ///< named regions (may be null: no names)
  const std::vector<int>* shape_region = nullptr;              ///< per source curve: its region, −1 none
  vision::PxToM px_to_m{1, 0, 0};                              ///< the picture's pixels → workspace [m]
  int width_px = 0, height_px = 0;                             ///< the picture's size [px] (what px_to_m maps)
};

/// The copy's input from `what` (see the ImageScene overload). @throws hk::ArgumentError without a scene.
TactileInput tactile_input_of(const SceneToCopy& what, int level, Paper paper, const std::string& language,
                              const std::string& title, BrailleGrade grade = BrailleGrade::two);

/// `is` (built, with its scene) as the copy's input on `paper`: the picture's rectangle, each curve at `level`
/// (a level id as the kiosk's Finer / Coarser keys set it, clamped per curve) or coarser down to the coarsest
/// within kTactileToleranceMm on the page; each shape's name in `language` (staff's, then the kiosk's guesses;
/// "" when it has none) and its number (its index in `is.polylines` + 1); `title` above it.
/// @throws hk::ArgumentError when `is` has no scene.
TactileInput tactile_input_of(const ImageScene& is, int level, Paper paper, const std::string& language,
                              const std::string& title, BrailleGrade grade = BrailleGrade::two);

}  // namespace hk::app
