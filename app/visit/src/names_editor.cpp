// The Names tab's logic (names_editor.hpp).
#include "visit/names_editor.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <system_error>

#include "config/load.hpp"
#include "hk/text.hpp"
#include "pictures/picture_names.hpp"
#include "visit/describe.hpp"

namespace hk::app {
namespace {

/// Distance from `p` to the segment a–b [m].
double segment_distance_m(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double len2 = dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return length(p - (a + ab * t));
}

/// Distance from `p` to the curve `c` (its closing segment included when closed) [m]; infinity for no points.
double curve_distance_m(const Polyline& c, Vec2 p) {
  const std::vector<Vec2>& q = c.points_m;
  double best = std::numeric_limits<double>::infinity();
  if (q.size() == 1) return length(p - q[0]);
  for (std::size_t i = 0; i + 1 < q.size(); ++i) best = std::min(best, segment_distance_m(p, q[i], q[i + 1]));
  if (c.closed && q.size() > 2) best = std::min(best, segment_distance_m(p, q.back(), q.front()));
  return best;
}

/// "The name is 201 bytes; at most 200." and the like, from annotation_text_problem's phrase.
std::string refusal(const std::string& text, bool description) {
  const std::string why = annotation_text_problem(text, description);
  if (why.empty()) return {};
  const std::size_t max = description ? kMaxRegionDescriptionBytes : kMaxNameBytes;
  if (text.size() > max)
    return std::string(description ? "The description" : "The name") + " is " + std::to_string(text.size()) +
           " bytes; at most " + std::to_string(max) + ".";
  std::string line = why + ".";
  line[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(line[0])));
  return line;
}

}  // namespace

void NamesEditor::open(NamesPicture picture) {
  picture_ = std::move(picture);
  scene_ = ImageScene{};
  set_ = AnnotationSet{};
  selected_ = picked_ = -1;
  name_text_.clear();
  description_text_.clear();
  status_.clear();
  dirty_ = false;
  last_save_ = NamesSaved::none;
  if (!is_open()) {
    refresh();
    return;
  }
  scene_.picture = picture_.picture;
  scene_.polylines = picture_.polylines;
  scene_.faces_m = picture_.faces_m;
  scene_.text_blocks = picture_.text_blocks;
  scene_.px_to_m = picture_.px_to_m;
  scene_.width_px = picture_.picture.cols;
  scene_.height_px = picture_.picture.rows;
  scene_.file_width_px = picture_.file_width_px > 0 ? picture_.file_width_px : picture_.picture.cols;
  scene_.file_height_px = picture_.file_height_px > 0 ? picture_.file_height_px : picture_.picture.rows;
  const std::string file = names_file_for(picture_.picture_path, folder_);
  const std::string file_name = std::filesystem::path(picture_.picture_path).filename().string();
  if (!file.empty()) {
    try {
      set_ = read_annotations(file, file_name);
      if (!set_.problems.empty())
        status_ = std::to_string(set_.problems.size()) + (set_.problems.size() == 1 ? " annotation" : " annotations") +
                  " of " + hk::quoted(file) + " cannot be read (the log says why); saving leaves them out.";
    } catch (const AnnotationError& e) {
      status_ = std::string(e.what()) + "; saving starts a new file.";
    }
  }
  apply_names(scene_, file, file_name, picture_.guesses);
  refresh();
}

void NamesEditor::refresh() {
  drawn_.clear();
  drawn_shape_region_.assign(picture_.polylines.size(), -1);
  entries_.assign(set_.annotations.size(), NamesEntry{});
  for (std::size_t i = 0; i < set_.annotations.size(); ++i) {
    entries_[i].name = set_.annotations[i].name;
    entries_[i].description = set_.annotations[i].description;
  }
  if (!is_open()) return;
  drawn_ = meaning::draw_regions(set_, scene_.picture.cols, scene_.picture.rows, scene_.file_width_px,
                                 scene_.file_height_px, picture_.picture_path, nullptr);
  drawn_shape_region_ = meaning::name_shapes(drawn_, picture_.polylines, picture_.px_to_m);
  for (std::size_t c = 0; c < drawn_shape_region_.size(); ++c) {
    const int r = drawn_shape_region_[c];
    if (r < 0) continue;
    const int a = drawn_[static_cast<std::size_t>(r)].annotation;
    if (a >= 0 && a < static_cast<int>(entries_.size()))
      entries_[static_cast<std::size_t>(a)].curves.push_back(static_cast<int>(c));
  }
}

void NamesEditor::load_texts() {
  if (selected_ >= 0) {
    name_text_ = set_.annotations[static_cast<std::size_t>(selected_)].name;
    description_text_ = set_.annotations[static_cast<std::size_t>(selected_)].description;
  } else {
    name_text_.clear();
    description_text_.clear();
  }
}

void NamesEditor::pick(int curve) {
  if (curve < 0 || curve >= static_cast<int>(picture_.polylines.size())) return;
  picked_ = curve;
  selected_ = -1;
  const int r = drawn_shape_region_[static_cast<std::size_t>(curve)];
  if (r >= 0) selected_ = drawn_[static_cast<std::size_t>(r)].annotation;
  load_texts();
  status_ = "Shape " + std::to_string(curve + 1) + " picked" +
            (selected_ >= 0 ? ": named \"" + hk::one_line(name_text_) + "\"." : ": no name yet.");
}

int NamesEditor::pick_at_hand(Vec2 hand_m, int contact_curve) {
  if (picture_.polylines.empty()) return -1;
  const std::vector<meaning::ShapeDescriptor> none;
  const std::vector<meaning::ShapeDescriptor>& d =
      picture_.descriptors.size() == picture_.polylines.size() ? picture_.descriptors : none;
  const ShapeAtHand at = shape_at_hand(picture_.polylines, d, hand_m, contact_curve);
  pick(at.curve);
  return at.curve;
}

int NamesEditor::pick_near(Vec2 p_m, double within_m) {
  int best = -1;
  double best_m = within_m;
  for (std::size_t c = 0; c < picture_.polylines.size(); ++c) {
    const double d = curve_distance_m(picture_.polylines[c], p_m);
    if (d <= best_m) {
      best_m = d;
      best = static_cast<int>(c);
    }
  }
  pick(best);
  return best;
}

void NamesEditor::select_entry(int index) {
  if (index < 0 || index >= static_cast<int>(entries_.size())) return;
  selected_ = index;
  const std::vector<int>& curves = entries_[static_cast<std::size_t>(index)].curves;
  picked_ = curves.empty() ? -1 : curves.front();
  load_texts();
  status_.clear();
}

std::string NamesEditor::outline_svg(int curve) const {
  // The file's frame: its canvas, else the picture's full-detail pixels. A picture pixel's centre u lies at
  // (u + 0.5) of the drawn picture's pixel grid (meaning/names.cpp draws a frame unit c at c · width / frame).
  const double frame_w = set_.canvas_width_px > 0 ? set_.canvas_width_px : scene_.file_width_px;
  const double frame_h = set_.canvas_height_px > 0 ? set_.canvas_height_px : scene_.file_height_px;
  const double fx = frame_w / scene_.picture.cols, fy = frame_h / scene_.picture.rows;
  const Polyline& c = picture_.polylines[static_cast<std::size_t>(curve)];
  const std::size_t n = c.points_m.size();
  const std::size_t stride = (n + kMaxOutlinePoints - 1) / kMaxOutlinePoints;
  std::string points;
  char xy[64];
  for (std::size_t i = 0; i < n; i += std::max<std::size_t>(stride, 1)) {
    const Vec2 p = c.points_m[i];
    std::snprintf(xy, sizeof xy, "%s%.1f,%.1f", points.empty() ? "" : " ", (picture_.px_to_m.u_px(p.x) + 0.5) * fx,
                  (picture_.px_to_m.v_px(p.y) + 0.5) * fy);
    points += xy;
  }
  // A stroke of 3 picture pixels keeps the outline's own points inside the region.
  char head[256];
  std::snprintf(head, sizeof head,
                "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.10g\" height=\"%.10g\" viewBox=\"0 0 %.10g "
                "%.10g\"><%s points=\"",
                frame_w, frame_h, frame_w, frame_h, c.closed ? "polygon" : "polyline");
  char tail[160];
  std::snprintf(tail, sizeof tail,
                "\" fill=\"%s\" stroke=\"#000\" stroke-width=\"%.3g\" stroke-linejoin=\"round\"/></svg>",
                c.closed ? "#000" : "none", 3.0 * std::max(fx, fy));
  return head + points + tail;
}

std::string NamesEditor::set_name(const std::string& name, const std::string& description) {
  std::string why;
  if (!is_open())
    why = "There is no library picture on show to name.";
  else if (name.empty())
    why = "A name is needed (Delete name removes one).";
  else if (std::string r = refusal(name, false); !r.empty())
    why = r;
  else if (std::string d = refusal(description, true); !d.empty())
    why = d;
  else if (selected_ < 0 && picked_ < 0)
    why = "Pick a shape first.";
  else if (selected_ < 0 && set_.annotations.size() >= kMaxAnnotations)
    why = "The picture has " + std::to_string(kMaxAnnotations) + " names already, the most a file may hold.";
  if (!why.empty()) {
    status_ = why;
    return why;
  }
  if (selected_ >= 0) {
    Annotation& a = set_.annotations[static_cast<std::size_t>(selected_)];
    a.name = name;
    a.description = description;
    status_ = "Renamed \"" + hk::one_line(name) + "\"; not saved yet.";
  } else {
    Annotation a;
    a.name = name;
    a.description = description;
    a.selector.kind = AnnotationSelector::Kind::svg;
    a.selector.svg = outline_svg(picked_);
    set_.annotations.push_back(std::move(a));
    selected_ = static_cast<int>(set_.annotations.size()) - 1;
    status_ = "Shape " + std::to_string(picked_ + 1) + " named \"" + hk::one_line(name) + "\"; not saved yet.";
  }
  dirty_ = true;
  refresh();
  return {};
}

std::string NamesEditor::remove_selected() {
  if (selected_ < 0 || selected_ >= static_cast<int>(set_.annotations.size())) {
    status_ = "Nothing is selected: pick a named shape or click a name in the list.";
    return status_;
  }
  const std::string gone = set_.annotations[static_cast<std::size_t>(selected_)].name;
  set_.annotations.erase(set_.annotations.begin() + selected_);
  selected_ = -1;
  load_texts();
  dirty_ = true;
  refresh();
  status_ = "Deleted \"" + hk::one_line(gone) + "\"; not saved yet.";
  return {};
}

bool NamesEditor::save_typed() {
  const bool typed = selected_ >= 0 || picked_ >= 0 || !name_text_.empty() || !description_text_.empty();
  if (typed && !set_name(name_text_, description_text_).empty()) {
    last_save_ = NamesSaved::failed;
    return false;
  }
  return save();
}

bool NamesEditor::delete_and_save() {
  if (!remove_selected().empty()) {
    last_save_ = NamesSaved::failed;
    return false;
  }
  return save();
}

std::string NamesEditor::target_file() const {
  if (folder_.empty() || picture_.picture_path.empty()) return {};
  return annotations_path_in(folder_, picture_.picture_path);
}

bool NamesEditor::set_guesses(bool on) {
  if (!is_open()) {
    status_ = "There is no library picture on show.";
    return false;
  }
  const std::string sidecar = guesses_sidecar_in(folder_, picture_.picture_path);
  if (sidecar.empty()) {
    status_ = "Could not save the switch: there is no names folder ([kiosk] names_dir is off).";
    return false;
  }
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  try {
    if (ec) throw config::FileWriteError(folder_, ec.value(), ec.message());
    config::write_file_atomic(
        std::string("# Written by the operator panel's Names tab: whether the kiosk's own guesses "
                    "(faces, text) name parts of this picture.\nguesses = ") +
            (on ? "true" : "false") + "\n",
        sidecar, 0644);
  } catch (const config::FileWriteError& e) {
    status_ = "Could not save the switch to " + hk::one_line(sidecar) + ": " +
              hk::one_line(e.error_number() != 0 ? std::strerror(e.error_number()) : e.what());
    return false;
  }
  picture_.guesses = on;
  const std::string file = names_file_for(picture_.picture_path, folder_);
  apply_names(scene_, file, std::filesystem::path(picture_.picture_path).filename().string(), on);
  status_ = on ? "The kiosk's guesses name parts of this picture." : "The kiosk's guesses are off for this picture.";
  spdlog::info("names: guesses {} for {}", on ? "on" : "off", picture_.picture_path);
  return true;
}

bool NamesEditor::save() {
  last_save_ = NamesSaved::failed;
  if (!is_open()) {
    status_ = "There is no library picture on show to name.";
    return false;
  }
  const std::string file = target_file();
  if (file.empty()) {
    status_ = "Could not save names: there is no names folder ([kiosk] names_dir is off).";
    return false;
  }
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  if (ec) {
    status_ = "Could not save names to " + hk::one_line(folder_) + ": " + hk::one_line(ec.message());
    return false;
  }
  const std::string file_name = std::filesystem::path(picture_.picture_path).filename().string();
  try {
    config::write_file_atomic(write_annotation_page(set_, file_name), file, 0644);
  } catch (const config::FileWriteError& e) {
    status_ = "Could not save names to " + hk::one_line(file) + ": " +
              hk::one_line(e.error_number() != 0 ? std::strerror(e.error_number()) : e.what());
    spdlog::warn("names: not saved: {}", e.what());
    return false;
  }
  apply_names(scene_, file, file_name, picture_.guesses);  // what the kiosk reads from now on
  try {
    set_ = read_annotations(file, file_name);  // as the kiosk reads it (the same annotations, in the same order)
  } catch (const AnnotationError& e) {
    spdlog::warn("names: {} does not read back: {}", file, e.what());
  }
  selected_ = std::min(selected_, static_cast<int>(set_.annotations.size()) - 1);
  refresh();
  dirty_ = false;
  last_save_ = NamesSaved::saved;
  status_ = "Saved " + std::to_string(set_.annotations.size()) + (set_.annotations.size() == 1 ? " name" : " names") +
            " to " + hk::one_line(file) + ".";
  spdlog::info("names: saved {} annotations to {}", set_.annotations.size(), file);
  return true;
}

}  // namespace hk::app
