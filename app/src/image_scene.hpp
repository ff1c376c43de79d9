#pragma once
/// @file image_scene.hpp
/// Image file → haptic scene: the vision pipeline, the pixel → workspace mapping, the dropping of
/// chains too short to feel, and the multiresolution collision trees (DESIGN.md "Data flow").

#include <memory>
#include <string>
#include <vector>

#include "config/settings.hpp"
#include "haptics/scene.hpp"
#include "vision/mapping.hpp"
#include "vision/pipeline.hpp"

namespace hk::app {

/// Build time of each stage [ms].
struct BuildTimes {
  double load_ms = 0, edges_ms = 0, linking_ms = 0, multires_ms = 0, tree_ms = 0;
};

/// A picture turned into a scene. `polylines[i]` is the curve built into `scene` as the curve whose
/// `source_index` is i.
struct ImageScene {
  std::string image_path;
  int width_px = 0, height_px = 0;
  vision::PxToM px_to_m{};
  std::size_t chains_found = 0;        ///< chains out of edge linking
  std::size_t chains_too_short = 0;    ///< dropped: shorter than vision.min_chain_length_m
  std::size_t chains_over_budget = 0;  ///< dropped: the scene would hold more than vision.max_segments level-0 segments (shortest dropped first)
  double canny_low = 0, canny_high = 0;
  std::vector<Polyline> polylines;     ///< kept chains in workspace metres
  std::unique_ptr<Scene> scene;        ///< collision trees (heap: the servo loop holds a pointer)
  BuildTimes times;
};

/// Chains (pixels) → polylines in workspace metres, dropping chains shorter than min_length_m (a
/// fingertip cannot resolve them). `too_short` (optional) receives the number dropped.
std::vector<Polyline> chains_to_polylines(const std::vector<vision::Chain>& chains, const vision::PxToM& map, double min_length_m,
                                          std::size_t* too_short = nullptr);

/// Loads the image at `path` and builds its scene with `settings`. Throws vision::InputError for bad
/// image files (one line naming the file and the limit).
ImageScene build_image_scene(const std::string& path, const config::Settings& settings);

}  // namespace hk::app
