#pragma once
/// @file library_command.hpp
/// `haptic-kiosk library check DIR [--config FILE]`: a picture library checked before it is rolled out to the kiosks
/// (pictures/library_check.hpp). Standard output: one line per problem, `FILE: reason`, nothing when all is well;
/// standard error: one summary line. Exit status 0 all well, 1 something wrong, 2 the folder (or the settings file)
/// cannot be read.

#include <string>

namespace hk::app {

/// What `haptic-kiosk library check` was asked to do.
struct LibraryOptions {
  std::string folder;       ///< the library folder to check
  std::string config_path;  ///< settings file (TOML) whose [vision] limits apply; "" for the built-in settings
};

/// Runs the check and prints as the file comment says; returns the exit status. Never throws.
int run_library_check(const LibraryOptions& options);

}  // namespace hk::app
