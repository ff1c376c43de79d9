#pragma once
/// @file tactile_command.hpp
/// `haptic-kiosk tactile PICTURE --out FILE.pdf|FILE.svg|FILE.brf [--level N] [--paper a4|letter|11x11.5in]`:
/// a take-home copy of a picture as the kiosk lets a visitor feel it (copies/tactile_graphic.hpp), for staff and
/// scripts.

#include <string>
#include <vector>

namespace hk::app {

/// What `haptic-kiosk tactile` was asked to do.
struct TactileOptions {
  std::string picture;           ///< a picture file or a PDF
  int page = 0;                  ///< a PDF's page (from 1; 0: the first)
  std::vector<std::string> out;  ///< files to write, each .pdf, .svg or .brf
  int level = -1;                ///< the resolution level (0 finest); −1: [haptics] level of the settings
  std::string paper = "a4";      ///< "a4", "letter" or "11x11.5in"
  std::string language;          ///< BCP 47; "": [kiosk] language of the settings
  int grade = 2;                 ///< braille grade: 1 (uncontracted) or 2 (contracted)
  std::string config_path;       ///< settings file (TOML); "" for the built-in settings
  std::string title;             ///< the copy's title; "": the picture's (its notes), else its file name
};

/// Builds the picture's scene with the settings, names its shapes as the library does (staff's names, then the
/// kiosk's guesses), lays it out and writes every --out file. Returns 0 when all were written, 1 with one line
/// on stderr ("tactile: ...", naming the input and the limit) for a bad option, picture or file. Never throws.
int run_tactile(const TactileOptions& options);

}  // namespace hk::app
