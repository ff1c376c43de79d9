// Staff names on a built scene (picture_names.hpp).
#include "pictures/picture_names.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <optional>

#include "formats/annotations.hpp"
#include "formats/picture_notes.hpp"
#include "hk/text.hpp"
#include "meaning/names.hpp"
#include "pictures/kiosk_folders.hpp"
#include "vision/ocr.hpp"

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

std::string guesses_sidecar_in(const std::string& names_folder, const std::string& picture_path) {
  if (names_folder.empty()) return {};
  return (std::filesystem::path(names_folder) / std::filesystem::path(picture_path).filename())
      .replace_extension(".toml")
      .string();
}

bool guesses_for(const std::string& picture_path, const std::string& names_folder, bool sidecar_guesses) {
  const std::string file = guesses_sidecar_in(names_folder, picture_path);
  std::error_code ec;
  if (file.empty() || !std::filesystem::exists(file, ec)) return sidecar_guesses;
  try {
    return read_sidecar(file).guesses;
  } catch (const PictureNotesError& e) {
    spdlog::warn("names: {}; the sidecar beside the picture decides", e.what());
    return sidecar_guesses;
  }
}

namespace {

/// The regions staff drew in `names_file` on `is.picture`; none when the file is refused (logged).
std::vector<meaning::NamedRegion> staff_regions(const ImageScene& is, const std::string& names_file,
                                                const std::string& picture_file_name) {
  AnnotationSet set;
  try {
    set = read_annotations(names_file, picture_file_name);
  } catch (const AnnotationError& e) {
    spdlog::warn("names: {}; the picture is shown without them", e.what());
    return {};
  }
  std::vector<std::string> problems = set.problems;
  const int full_w = is.file_width_px > 0 ? is.file_width_px : is.picture.cols;
  const int full_h = is.file_height_px > 0 ? is.file_height_px : is.picture.rows;
  std::vector<meaning::NamedRegion> regions =
      meaning::draw_regions(set, is.picture.cols, is.picture.rows, full_w, full_h, names_file, &problems);
  for (const std::string& p : problems) spdlog::warn("names: {}; left out", p);
  return regions;
}

/// The box on `is.picture` [px] of a box in workspace metres.
cv::Rect box_px_of(const ImageScene& is, Vec2 lo_m, Vec2 hi_m) {
  const double u0 = is.px_to_m.u_px(lo_m.x), u1 = is.px_to_m.u_px(hi_m.x);
  const double v0 = is.px_to_m.v_px(lo_m.y), v1 = is.px_to_m.v_px(hi_m.y);
  const cv::Point a(static_cast<int>(std::floor(std::min(u0, u1))), static_cast<int>(std::floor(std::min(v0, v1))));
  const cv::Point b(static_cast<int>(std::ceil(std::max(u0, u1))) + 1,
                    static_cast<int>(std::ceil(std::max(v0, v1))) + 1);
  return {a, b};
}

/// `text` without the words OCR was not sure of (those holding vision::kUnclearWord).
std::string sure_words(const std::string& text) {
  std::string out, word;
  const auto flush = [&] {
    if (!word.empty() && word.find(vision::kUnclearWord) == std::string::npos) out += (out.empty() ? "" : " ") + word;
    word.clear();
  };
  for (const char c : text) {
    if (c == ' ' || c == '\n' || c == '\t' || c == '\r')
      flush();
    else
      word += c;
  }
  flush();
  return out;
}

/// Adds `guess` to the scene's regions unless staff named that part already.
void add_guess(ImageScene& is, std::optional<meaning::NamedRegion> guess) {
  if (guess && !meaning::covered_by_staff(*guess, is.regions)) is.regions.push_back(std::move(*guess));
}

}  // namespace

void add_guessed_regions(ImageScene& is) {
  if (is.picture.empty()) return;
  const int w = is.picture.cols, h = is.picture.rows;
  for (const Aabb& f : is.faces_m)
    add_guess(
        is, meaning::guessed_region(meaning::RegionSource::face, meaning::kFaceName, box_px_of(is, f.lo, f.hi), w, h));
  if (is.pages > 0) {  // a document page: its text is read as text (Where, Describe), not named as parts
    is.shape_region = meaning::name_shapes(is.regions, is.polylines, is.px_to_m);
    return;
  }
  for (const TextBlockM& b : is.text_blocks) {
    const std::string words = hk::first_words(sure_words(b.text), meaning::kTextNameWords);
    if (!words.empty())
      add_guess(is, meaning::guessed_region(meaning::RegionSource::text, "text: " + words,
                                            box_px_of(is, b.lo_m, b.hi_m), w, h));
  }
  is.shape_region = meaning::name_shapes(is.regions, is.polylines, is.px_to_m);
}

void apply_names(ImageScene& is, const std::string& names_file, const std::string& picture_file_name, bool guesses) {
  is.regions.clear();
  is.shape_region.assign(is.polylines.size(), -1);
  if (is.picture.empty()) return;
  if (!names_file.empty()) is.regions = staff_regions(is, names_file, picture_file_name);
  if (guesses)
    add_guessed_regions(is);
  else
    is.shape_region = meaning::name_shapes(is.regions, is.polylines, is.px_to_m);
}

}  // namespace hk::app
