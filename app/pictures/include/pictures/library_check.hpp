#pragma once
/// @file library_check.hpp
/// A picture library checked before it is rolled out to the kiosks (`haptic-kiosk library check DIR`): every
/// picture the kiosk would list (list_pictures' kinds) decodes within the settings' image limits ([vision]
/// max_file_mb, max_width_px, max_height_px, max_pixels); every sidecar (NAME.toml) and annotation file
/// (NAME.annotations.json) beside a picture loads, and every annotation in it is kept; no sidecar or annotation file
/// is left without its picture (a misspelt name would otherwise never be used). The same readers as the kiosk's, so
/// a library that passes is one the kiosk takes whole.

#include <string>
#include <vector>

#include "config/settings.hpp"

namespace hk::app {

/// One thing wrong in a library: the file (its name in the folder) and why, one line.
struct LibraryProblem {
  std::string file;
  std::string reason;
};

/// What a check found.
struct LibraryReport {
  int pictures = 0;                      ///< pictures listed (whether or not they decode)
  std::vector<LibraryProblem> problems;  ///< in file-name order; empty when all is well
};

/// Checks the library folder `folder` with the limits of `s` (see the file comment). An empty library (no picture)
/// is one problem naming the folder. Hidden files (a name starting with '.', such as a sync tool's temporary file)
/// and files of other kinds (a README, SOURCES.md) are passed over.
/// @throws AppError (one line naming the folder) when the folder cannot be read.
LibraryReport check_library(const std::string& folder, const config::Settings& s);

}  // namespace hk::app
