// The scene a visitor felt as a tactile copy's input (tactile_scene.hpp).
#include "copies/tactile_scene.hpp"

#include <algorithm>

#include "hk/error.hpp"
#include "meaning/names.hpp"

namespace hk::app {

TactileInput tactile_input_of(const ImageScene& is, int level, Paper paper, const std::string& language,
                              const std::string& title, BrailleGrade grade) {
  return tactile_input_of(
      SceneToCopy{is.scene.get(), &is.regions, &is.shape_region, is.px_to_m, is.width_px, is.height_px}, level, paper,
      language, title, grade);
}

TactileInput tactile_input_of(const SceneToCopy& is, int level, Paper paper, const std::string& language,
                              const std::string& title, BrailleGrade grade) {
  if (!is.scene) throw hk::ArgumentError("tactile copy: the picture has no scene");
  TactileInput in;
  in.title = title;
  in.language = language;
  in.grade = grade;
  // The picture's rectangle: its pixels' outer edges in the workspace.
  const double u0 = -0.5, u1 = is.width_px - 0.5, v0 = -0.5, v1 = is.height_px - 0.5;
  in.picture_lo_m = {std::min(is.px_to_m.x_m(u0), is.px_to_m.x_m(u1)),
                     std::min(is.px_to_m.y_m(v0), is.px_to_m.y_m(v1))};
  in.picture_hi_m = {std::max(is.px_to_m.x_m(u0), is.px_to_m.x_m(u1)),
                     std::max(is.px_to_m.y_m(v0), is.px_to_m.y_m(v1))};
  const double mm_per_m = tactile_scale_mm_per_m(paper_size(paper), in.picture_lo_m, in.picture_hi_m);
  const double tolerance_m = kTactileToleranceMm / mm_per_m;

  const Scene& scene = *is.scene;
  static const std::vector<int> kNoRegions;
  const std::vector<int>& shape_region = is.shape_region ? *is.shape_region : kNoRegions;
  for (std::size_t c = 0; c < scene.curve_count(); ++c) {
    const CurveInfo& ci = scene.curve(c);
    const int l = std::max(scene.clamp_level(c, level), scene.coarsest_level_within(c, tolerance_m));
    TactileCurve tc;
    tc.closed = ci.closed;
    const Vec2* p = scene.slot_points(ci.point_offset[l]);
    tc.points_m.assign(p, p + ci.point_count[l]);
    const std::size_t source = scene.source_index(c);
    tc.number = static_cast<int>(source) + 1;
    tc.salience = ci.length_m;
    if (is.regions && source < shape_region.size() && shape_region[source] >= 0 &&
        static_cast<std::size_t>(shape_region[source]) < is.regions->size())
      tc.name = meaning::region_name_in((*is.regions)[static_cast<std::size_t>(shape_region[source])], language);
    in.curves.push_back(std::move(tc));
  }
  return in;
}

}  // namespace hk::app
