// explore --where / --describe: what the kiosk would say of a picture, without a run (explore.hpp).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "audio/messages.hpp"
#include "cli/explore.hpp"
#include "config/load.hpp"
#include "formats/picture_notes.hpp"
#include "pictures/picture_names.hpp"
#include "visit/answers.hpp"

namespace hk::app {
namespace {

std::string metres(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

}  // namespace

Vec2 parse_where(const std::string& text, const config::Settings& s) {
  const auto bad = [&](const std::string& why) { return ExploreError("--where '" + text + "': " + why); };
  const std::size_t comma = text.find(',');
  if (comma == std::string::npos) throw bad("give X_M,Y_M, two numbers in metres separated by a comma");
  const std::string xs = text.substr(0, comma), ys = text.substr(comma + 1);
  char* end = nullptr;
  const double x = std::strtod(xs.c_str(), &end);
  if (xs.empty() || *end != '\0') throw bad("X_M is not a number");
  const double y = std::strtod(ys.c_str(), &end);
  if (ys.empty() || *end != '\0') throw bad("Y_M is not a number");
  const double hw = s.workspace.width_m / 2, hh = s.workspace.height_m / 2;
  if (!std::isfinite(x) || !std::isfinite(y) || std::abs(x) > hw || std::abs(y) > hh)
    throw bad("outside the workspace (|x| <= " + metres(hw) + " m, |y| <= " + metres(hh) + " m)");
  return {x, y};
}

std::string explore_answer(const ExploreOptions& o) {
  const config::Settings s = o.config_path.empty() ? config::Settings{} : config::load_settings(o.config_path);
  const Vec2 hand = o.where.empty() ? Vec2{} : parse_where(o.where, s);  // a bad --where fails before the build
  ImageScene is = build_input_scene(o.image_path, o.page, s);
  const PictureNotes notes = is.page > 0 ? PictureNotes{} : read_picture_notes(o.image_path);
  if (is.page == 0)
    apply_names(is, names_file_for(o.image_path, names_dir(s)), std::filesystem::path(o.image_path).filename().string(),
                guesses_for(o.image_path, names_dir(s), notes.guesses));
  else
    add_guessed_regions(is);
  const PictureNames names = picture_names(is.regions, is.shape_region, is.polylines.size(), is.px_to_m, &is.polylines);
  const ShownView view{
      is.polylines, is.descriptors, is.text_blocks, notes,       {s.workspace.width_m / 2, s.workspace.height_m / 2},
      false,        is.page > 0,    &names,         &is.regions, is.px_to_m};
  const audio::MessageCatalog& m = audio::MessageCatalog::english();
  return o.where.empty() ? describe_answer(view, m, hand, hand) : where_answer(view, m, hand, -1);
}

}  // namespace hk::app
