// A picture library checked before roll-out (library_check.hpp).
#include "pictures/library_check.hpp"

#include <algorithm>
#include <filesystem>
#include <set>

#include "formats/annotations.hpp"
#include "formats/app_error.hpp"
#include "formats/picture_notes.hpp"
#include "pictures/picture_library.hpp"
#include "pictures/picture_params.hpp"
#include "vision/intake.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;

constexpr const char* kSidecarSuffix = ".toml";
constexpr const char* kAnnotationsSuffix = ".annotations.json";

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// `reason` without its opening naming the file ("image '<path>': ", "picture notes '<name>': ", "<path>: "): the
/// readers name the file, the report names it once, first.
std::string without_path(std::string reason, const std::string& path, const std::string& name) {
  for (const std::string& named : {"'" + path + "': ", "'" + name + "': ", path + ": ", name + ": "}) {
    const std::size_t at = reason.find(named);
    if (at != std::string::npos && at <= 20) return reason.substr(at + named.size());
  }
  return reason;
}

/// The picture's own file, decoded within the limits.
void check_picture(const std::string& path, const std::string& name, const vision::ImageLimits& limits,
                   std::vector<LibraryProblem>& out) {
  try {
    (void)vision::load_image(path, limits);
  } catch (const std::exception& e) {
    out.push_back({name, without_path(e.what(), path, name)});
  }
}

/// The picture's sidecar and annotation file, when there are any.
void check_companions(const std::string& path, const std::string& name, std::vector<LibraryProblem>& out) {
  const std::string sidecar = notes_path(path);
  if (fs::exists(sidecar)) {
    try {
      (void)read_sidecar(sidecar);
    } catch (const std::exception& e) {
      const std::string file = fs::path(sidecar).filename().string();
      out.push_back({file, without_path(e.what(), sidecar, file)});
    }
  }
  const std::string names = annotations_path(path);
  if (fs::exists(names)) {
    const std::string file = fs::path(names).filename().string();
    try {
      const AnnotationSet set = read_annotations(names, name);
      for (const std::string& p : set.problems) out.push_back({file, without_path(p, names, file)});
    } catch (const std::exception& e) {
      out.push_back({file, without_path(e.what(), names, file)});
    }
  }
}

}  // namespace

LibraryReport check_library(const std::string& folder, const config::Settings& s) {
  std::error_code ec;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(folder, ec)) names.push_back(e.path().filename().string());
  if (ec) throw AppError("library '" + folder + "': cannot read the folder (" + ec.message() + ")");
  std::sort(names.begin(), names.end());

  const vision::ImageLimits limits = extract_params_from(s).limits;
  LibraryReport r;
  std::set<std::string> stems;  // of the pictures, for the companions' check
  for (const std::string& name : names) {
    if (!is_picture_name(name)) continue;
    const fs::path path = fs::path(folder) / name;
    ++r.pictures;
    stems.insert(path.stem().string());
    check_picture(path.string(), name, limits, r.problems);
    check_companions(path.string(), name, r.problems);
  }
  for (const std::string& name : names) {
    if (name.empty() || name[0] == '.') continue;
    std::string stem;
    if (ends_with(name, kAnnotationsSuffix))
      stem = name.substr(0, name.size() - std::string(kAnnotationsSuffix).size());
    else if (ends_with(name, kSidecarSuffix))
      stem = name.substr(0, name.size() - std::string(kSidecarSuffix).size());
    else
      continue;
    if (stems.count(stem) == 0)
      r.problems.push_back({name, "no picture named '" + stem + ".*' beside it, so it is never used"});
  }
  if (r.pictures == 0) r.problems.push_back({folder, "holds no picture (png, jpg, bmp, tif, webp)"});
  std::stable_sort(r.problems.begin(), r.problems.end(),
                   [](const LibraryProblem& a, const LibraryProblem& b) { return a.file < b.file; });
  return r;
}

}  // namespace hk::app
