// `haptic-kiosk tactile` (tactile_command.hpp).
#include "cli/tactile_command.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "cli/explore.hpp"
#include "config/load.hpp"
#include "copies/tactile_output.hpp"
#include "copies/tactile_scene.hpp"
#include "formats/picture_notes.hpp"
#include "pictures/documents.hpp"
#include "pictures/picture_names.hpp"

namespace hk::app {
namespace {

/// The copy's title: the one asked for, else the picture's own in the language, else its file name.
std::string title_of(const TactileOptions& o, const ImageScene& is, const std::string& language) {
  if (!o.title.empty()) return o.title;
  // A picture file's notes as the library reads them (its sidecar, else what the file itself says); a sidecar that
  // cannot be used is one log line, as in the library.
  PictureNotes notes = is.notes;
  if (is.page == 0) {
    try {
      notes = read_picture_notes(o.picture, &is.file_notes);
    } catch (const PictureNotesError& e) {
      spdlog::warn("tactile: {}", e.what());
    }
  }
  notes = notes_in(notes, language);
  if (!notes.title.empty()) return notes.title;
  if (!is.document_title.empty()) return is.document_title;
  return std::filesystem::path(o.picture).stem().string();
}

}  // namespace

int run_tactile(const TactileOptions& o) {
  try {
    const std::optional<Paper> paper = parse_paper(o.paper);
    if (!paper) throw CopyError("--paper '" + o.paper + "' is not a4, letter or 11x11.5in");
    if (o.grade != 1 && o.grade != 2) throw CopyError("--grade " + std::to_string(o.grade) + " is not 1 or 2");
    if (o.out.empty()) throw CopyError("--out: name at least one file (.pdf, .svg or .brf)");
    for (const std::string& f : o.out)
      if (tactile_format_of(f).empty())
        throw CopyError("--out '" + f + "': the file name must end in .pdf, .svg or .brf");
    const config::Settings s = o.config_path.empty() ? config::Settings{} : config::load_settings(o.config_path);
    const int level = o.level >= 0 ? o.level : s.haptics.level;
    if (level > 12) throw CopyError("--level " + std::to_string(level) + " is outside [0, 12]");
    const std::string language = o.language.empty() ? s.kiosk.language : o.language;

    const auto t0 = std::chrono::steady_clock::now();
    ImageScene is = build_input_scene(o.picture, o.page, s);
    if (is.page == 0)  // a picture file's names, as the library takes them
      apply_names(is, names_file_for(o.picture, names_dir(s)), std::filesystem::path(o.picture).filename().string());
    else
      add_guessed_regions(is);
    const auto t1 = std::chrono::steady_clock::now();
    const BrailleGrade grade = o.grade == 1 ? BrailleGrade::one : BrailleGrade::two;
    const TactileGraphic g =
        lay_out_tactile(tactile_input_of(is, level, *paper, language, title_of(o, is, language), grade), *paper);
    for (const std::string& f : o.out) write_tactile(g, f, grade);
    const auto t2 = std::chrono::steady_clock::now();
    int labelled = 0;
    for (const TactileShape& ts : g.pages.front().shapes) labelled += ts.labelled;
    std::fprintf(stderr, "tactile: %zu shapes (%d labelled, %d left out), %zu pages; scene %.0f ms, copy %.0f ms\n",
                 g.pages.front().shapes.size(), labelled, g.left_out, g.pages.size(),
                 std::chrono::duration<double, std::milli>(t1 - t0).count(),
                 std::chrono::duration<double, std::milli>(t2 - t1).count());
    return 0;
  } catch (const std::exception& e) {
    std::string line = e.what();
    for (char& c : line)
      if (c == '\n' || c == '\r') c = ' ';
    std::fprintf(stderr, "tactile: %s\n", line.c_str());
    return 1;
  }
}

}  // namespace hk::app
