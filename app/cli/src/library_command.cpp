// `haptic-kiosk library check` (library_command.hpp).
#include "cli/library_command.hpp"

#include <cstdio>
#include <exception>

#include "config/load.hpp"
#include "pictures/library_check.hpp"

namespace hk::app {
namespace {

/// `s` on one line: line breaks a file name or a reason could carry become spaces.
std::string one_line(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
}

}  // namespace

int run_library_check(const LibraryOptions& o) {
  config::Settings s;
  try {
    if (!o.config_path.empty()) s = config::load_settings(o.config_path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "library check: %s\n", one_line(e.what()).c_str());
    return 2;
  }
  LibraryReport r;
  try {
    r = check_library(o.folder, s);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "library check: %s\n", one_line(e.what()).c_str());
    return 2;
  }
  for (const LibraryProblem& p : r.problems)
    std::printf("%s: %s\n", one_line(p.file).c_str(), one_line(p.reason).c_str());
  std::fflush(stdout);
  std::fprintf(stderr, "library check: %s: %d picture%s, %zu problem%s\n", one_line(o.folder).c_str(), r.pictures,
               r.pictures == 1 ? "" : "s", r.problems.size(), r.problems.size() == 1 ? "" : "s");
  return r.problems.empty() ? 0 : 1;
}

}  // namespace hk::app
