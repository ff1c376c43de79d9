// Staff names on a built scene (picture_names.hpp).
#include "pictures/picture_names.hpp"

#include <spdlog/spdlog.h>

#include <filesystem>

#include "formats/annotations.hpp"
#include "meaning/names.hpp"
#include "pictures/kiosk_folders.hpp"

namespace hk::app {

std::string names_dir(const config::Settings& s) {
  return kiosk_folder(s.kiosk.names_dir, "STATE_DIRECTORY", "XDG_DATA_HOME", ".local/share", "names");
}

std::string names_file_for(const std::string& picture_path, const std::string& names_folder) {
  std::error_code ec;
  if (!names_folder.empty()) {
    const std::string saved = annotations_path_in(names_folder, picture_path);
    if (std::filesystem::is_regular_file(saved, ec)) return saved;
  }
  const std::string beside = annotations_path(picture_path);
  return std::filesystem::is_regular_file(beside, ec) ? beside : std::string();
}

void apply_names(ImageScene& is, const std::string& names_file, const std::string& picture_file_name) {
  is.regions.clear();
  is.shape_region.assign(is.polylines.size(), -1);
  if (names_file.empty() || is.picture.empty()) return;
  AnnotationSet set;
  try {
    set = read_annotations(names_file, picture_file_name);
  } catch (const AnnotationError& e) {
    spdlog::warn("names: {}; the picture is shown without them", e.what());
    return;
  }
  std::vector<std::string> problems = set.problems;
  const int full_w = is.file_width_px > 0 ? is.file_width_px : is.picture.cols;
  const int full_h = is.file_height_px > 0 ? is.file_height_px : is.picture.rows;
  is.regions = meaning::draw_regions(set, is.picture.cols, is.picture.rows, full_w, full_h, names_file, &problems);
  for (const std::string& p : problems) spdlog::warn("names: {}; left out", p);
  is.shape_region = meaning::name_shapes(is.regions, is.polylines, is.px_to_m);
}

}  // namespace hk::app
