#pragma once
/// @file explore.hpp
/// The headless `explore` run (DESIGN.md "Headless runs"): the whole pipeline on the simulated
/// pantograph driven by a model hand, tick by tick as fast as it can, writing scene.json, trace.csv,
/// summary.json and overlay.png into the output folder.

#include <cstdint>
#include <stdexcept>
#include <string>
#include "hk/error.hpp"

#include "config/settings.hpp"
#include "pictures/image_scene.hpp"
#include "runtime/device_setup.hpp"

namespace hk::app {

/// What `haptic-kiosk explore` was asked to do.
struct ExploreOptions {
  std::string image_path;  ///< picture (PNG, JPEG, BMP, TIFF, WebP) or PDF to explore; empty when `source` is given
  std::string
      source;    ///< a camera capture instead (capture.hpp): "file:PATH" | "libcamera:N" | "v4l2:DEV"; empty: none
  int page = 0;  ///< PDF page (from 1); 0 = not given (a PDF's first page; refused for a picture)
  std::string out_dir;  ///< folder for the four output files (created if missing)
  std::string hand =
      "raster";  ///< "raster", "explorer" (the visitor-like closed-loop hand) or a CSV file with header t_s,x_m,y_m
  std::uint64_t seed = 1;      ///< the explorer's seed (start corner, pass orientation, turning sense); see parse_seed
  double duration_s = 0.0;     ///< run length [s]; ≤ 0: the hand path's duration + 0.5 s, or 120 s for the explorer
  std::string config_path;     ///< TOML settings; empty: defaults
  std::string audio_out;       ///< WAV file for the run's earcons (and cues.csv beside the outputs); empty: none
  std::string device = "sim";  ///< "sim" or "haply-emulator[:FAULT=VALUE,...]" (parse_device_choice)
  /// "X_M,Y_M": print the one line Where would say with the hand there [m, workspace frame], run nothing else
  /// (explore_answer); empty: not asked.
  std::string where;
  bool describe = false;  ///< print what Describe would say (the hand at the centre), run nothing else
};

/// A problem with the run's own arguments or output folder (bad inputs raise their own typed errors:
/// vision::InputError, config::ConfigError, HandFileError).
class ExploreError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// The `--seed` argument: a whole number in [0, 2^63 − 1], decimal digits only. Throws ExploreError
/// ("--seed 'TEXT': ...", one line naming the limit) for anything else (empty, a sign, a fraction, too big).
std::uint64_t parse_seed(const std::string& text);

/// The hand's place of `--where X_M,Y_M` [m]: two finite numbers, comma-separated, within the workspace of `s`
/// (|x| ≤ width_m / 2, |y| ≤ height_m / 2). Throws ExploreError ("--where 'TEXT': ...", one line naming the limit).
Vec2 parse_where(const std::string& text, const config::Settings& s);

/// What the kiosk would say of the input of `o` (its scene built as run_explore builds it, the picture's notes
/// read as the library reads them, English): the Where answer at o.where, or the Describe answer with the hand
/// at the centre when o.describe. No simulation, no output files. Throws as run_explore does for a bad input,
/// and ExploreError for a bad --where.
std::string explore_answer(const ExploreOptions& o);

/// Numbers of a finished run (also written to summary.json).
struct ExploreSummary {
  long ticks = 0;
  long free_ticks = 0, edge_ticks = 0, vertex_ticks = 0;
  double max_force_n = 0.0;
  std::size_t curves = 0;
  std::size_t cues = 0;  ///< audio cues emitted (counted with or without --audio-out)
  DeviceReport device;   ///< the device's name, final status and counters (summary.json "device")
};

/// The scene of the run's input: a picture file, or page `page` of a PDF (drawn in the worker, text
/// masked and kept as text blocks). Throws ExploreError for --page with a picture or a page < 1 given,
/// vision::InputError / vision::PdfError for bad files.
ImageScene build_input_scene(const std::string& path, int page, const config::Settings& s);

/// Runs explore. Throws on bad input with a one-line message naming the input and the limit.
ExploreSummary run_explore(const ExploreOptions& options);

}  // namespace hk::app
