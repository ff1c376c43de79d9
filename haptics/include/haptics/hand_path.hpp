#pragma once
/// @file hand_path.hpp
/// The model hand's target path (DESIGN.md "Headless runs"): a time-stamped polyline in the workspace
/// frame, linearly interpolated. Built in code (`raster_path`) or read from a hand file
/// (`load_hand_csv`, header `t_s,x_m,y_m`).

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>
#include "hk/error.hpp"

#include "hk/vec2.hpp"

namespace hk {

/// One sample of a hand path: the target position [m] at time t_s [s].
struct HandSample {
  double t_s = 0.0;  ///< time [s], ≥ 0, strictly increasing along a path
  Vec2 target_m;     ///< target position, workspace frame [m]
};

/// A target path: samples at strictly increasing, non-negative times, linearly interpolated between
/// them and held constant before the first and after the last sample. The path starts at t = 0.
class HandPath {
 public:
  /// Takes the samples. Throws hk::ArgumentError (one line) when `samples` is empty, a value is
  /// not finite, a time is negative, or times are not strictly increasing.
  explicit HandPath(std::vector<HandSample> samples);

  /// Time of the last sample [s] (the path runs from t = 0; before the first sample the target waits
  /// at the first point).
  double duration_s() const noexcept { return samples_.back().t_s; }
  /// Target at time t_s [s]: linear interpolation, clamped to the first / last sample outside the
  /// sampled span (also for a NaN time, which gives the first sample). O(log n), no allocation.
  Vec2 at(double t_s) const noexcept;
  /// The samples, in time order (1 ≤ size).
  const std::vector<HandSample>& samples() const noexcept { return samples_; }

 private:
  std::vector<HandSample> samples_;
};

/// A boustrophedon (back-and-forth raster) over the whole rectangle [−w/2, w/2] × [−h/2, h/2] [m]:
/// it starts at the top-left corner (−w/2, +h/2), runs right along the top edge, steps down, runs
/// left, and so on, the last line lying on the bottom edge. The lines are evenly spaced at
/// h / ceil(h / spacing_m) ≤ spacing_m, so every point of the rectangle is within spacing_m/2 of the
/// path and both horizontal edges are traced. Constant speed speed_m_per_s [m/s]: a sample at every
/// corner, timed by arc length, so duration = (n_lines·w + h) / speed.
/// Throws hk::ArgumentError when an argument is not finite and > 0, or the raster would need more
/// than 1,000,000 lines.
HandPath raster_path(double width_m, double height_m, double spacing_m, double speed_m_per_s);

/// The raster of `raster_path`, re-timed so that its lines run at `line_speeds_m_per_s` in turn (line k at
/// speed k mod size) and the steps between lines at `step_speed_m_per_s` [m/s]: a hand that keeps changing
/// pace, for the level policy. Throws hk::ArgumentError (one line) when a speed is not finite
/// and > 0, `line_speeds_m_per_s` is empty, or raster_path refuses its arguments.
HandPath raster_path_with_line_speeds(double width_m, double height_m, double spacing_m,
                                      const std::vector<double>& line_speeds_m_per_s, double step_speed_m_per_s);

/// A bad hand file. what() is one line: `hand file '<path>' line <n>: <problem>` (no line number
/// when the file cannot be opened), naming the limit for limit violations.
class HandFileError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// Limits applied by `load_hand_csv`. The defaults are the kiosk's; tests lower them.
struct HandFileLimits {
  std::size_t max_rows = 10'000'000;  ///< most data rows accepted
  double max_distance_m = 1.0;        ///< farthest target from the workspace origin [m]
  std::size_t max_line_chars = 1024;  ///< longest line accepted (keeps a line-less binary file bounded)
};

/// Reads a hand file: first line exactly `t_s,x_m,y_m`, then one row `t,x,y` per sample (t in s,
/// x and y in workspace metres), at least one row. Accepted leniencies: a UTF-8 byte-order mark before
/// the header, CRLF line ends, spaces or tabs around fields, and blank lines at the very end.
/// Throws HandFileError (see above) for: a file that cannot be opened or is not a regular file, an
/// empty file, a wrong header, a line longer than limits.max_line_chars, a blank line before the
/// last row, a field count other than 3, a non-numeric field, a non-finite value, a negative time, a
/// time not strictly greater than the previous one, a point farther than limits.max_distance_m from the
/// origin, no data rows, more than limits.max_rows rows.
HandPath load_hand_csv(const std::string& path, const HandFileLimits& limits = {});

}  // namespace hk
