// Fuzz harness: hand-path CSV files (haptics/include/haptics/hand_path.hpp).
//
// Entry point: hk::load_hand_csv, which only takes a path: the input is written to a memfd and read as
// /proc/self/fd/N (no file on disk). Limits are lowered (1000 rows, 200-character lines) so that the
// limit checks are reachable with small inputs. Properties:
//  - a refusal is a HandFileError whose what() is one line "hand file '<path>' line <n>: <problem>"
//    (or without the line for open errors), of bounded length;
//  - an accepted path has 1..max_rows samples, all finite, times >= 0 and strictly increasing, every
//    point within max_distance_m of the origin, and at() stays on the samples' hull (finite, within range).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "fuzz_common.hpp"
#include "haptics/hand_path.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static hk::fuzz::MemFile file;
  const std::string& path = file.set(data, size);
  hk::HandFileLimits limits;
  limits.max_rows = 1000;
  limits.max_distance_m = 0.5;
  limits.max_line_chars = 200;
  try {
    const hk::HandPath p = hk::load_hand_csv(path, limits);
    const auto& s = p.samples();
    FUZZ_CHECK(!s.empty() && s.size() <= limits.max_rows, std::to_string(s.size()));
    for (std::size_t i = 0; i < s.size(); ++i) {
      FUZZ_CHECK(std::isfinite(s[i].t_s) && std::isfinite(s[i].target_m.x) && std::isfinite(s[i].target_m.y),
                 std::to_string(i));
      FUZZ_CHECK(s[i].t_s >= 0.0, std::to_string(i));
      FUZZ_CHECK(i == 0 || s[i].t_s > s[i - 1].t_s, std::to_string(i));
      FUZZ_CHECK(std::hypot(s[i].target_m.x, s[i].target_m.y) <= limits.max_distance_m * (1 + 1e-12),
                 std::to_string(i));
    }
    for (const double t : {-1.0, 0.0, p.duration_s() * 0.37, p.duration_s(), p.duration_s() + 1.0,
                           std::numeric_limits<double>::quiet_NaN()}) {
      const hk::Vec2 v = p.at(t);
      FUZZ_CHECK(std::isfinite(v.x) && std::isfinite(v.y), std::to_string(t));
      FUZZ_CHECK(std::hypot(v.x, v.y) <= limits.max_distance_m * (1 + 1e-9), std::to_string(t));
    }
  } catch (const hk::HandFileError& e) {
    const std::string what = e.what();
    FUZZ_CHECK(hk::fuzz::is_one_line(what), what);
    FUZZ_CHECK(what.starts_with("hand file '" + path + "'"), what);
    FUZZ_CHECK(what.size() <= path.size() + 400, what);
  }
  return 0;
}
