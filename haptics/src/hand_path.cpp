/// @file hand_path.cpp
/// Hand paths: interpolation, the raster, and the hand-file reader. See hand_path.hpp.

#include "haptics/hand_path.hpp"
#include "hk/error.hpp"
#include "hk/text.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <system_error>
#include <utility>

namespace hk {

HandPath::HandPath(std::vector<HandSample> samples) : samples_(std::move(samples)) {
  if (samples_.empty()) throw hk::ArgumentError("hand path: no samples");
  for (std::size_t i = 0; i < samples_.size(); ++i) {
    const HandSample& s = samples_[i];
    if (!std::isfinite(s.t_s) || !is_finite(s.target_m)) {
      throw hk::ArgumentError("hand path: sample " + std::to_string(i) + " is not finite");
    }
    if (s.t_s < 0.0) throw hk::ArgumentError("hand path: sample " + std::to_string(i) + " has a negative time");
    if (i > 0 && !(s.t_s > samples_[i - 1].t_s)) {
      throw hk::ArgumentError("hand path: time of sample " + std::to_string(i) + " is not strictly increasing");
    }
  }
}

Vec2 HandPath::at(double t_s) const noexcept {
  // Written so that NaN falls into the first branch (comparisons with NaN are false).
  if (!(t_s > samples_.front().t_s)) return samples_.front().target_m;
  if (t_s >= samples_.back().t_s) return samples_.back().target_m;
  // First sample strictly after t; its predecessor exists because t > front.t.
  const auto hi =
      std::upper_bound(samples_.begin(), samples_.end(), t_s, [](double t, const HandSample& s) { return t < s.t_s; });
  const auto lo = hi - 1;
  const double u = (t_s - lo->t_s) / (hi->t_s - lo->t_s);
  return lerp(lo->target_m, hi->target_m, u);
}

HandPath raster_path(double width_m, double height_m, double spacing_m, double speed_m_per_s) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(width_m) || !positive(height_m) || !positive(spacing_m) || !positive(speed_m_per_s)) {
    throw hk::ArgumentError("raster path: width, height, spacing and speed must be finite and > 0");
  }
  constexpr double kMaxLines = 1'000'000.0;
  // Round the gap count up so the real spacing never exceeds the requested one; the tiny tolerance keeps
  // an exact multiple (0.09 / 0.006 = 15.000000000000002) from gaining a needless extra line.
  const double gaps_real = std::ceil(height_m / spacing_m - 1e-9);
  if (!(gaps_real + 1.0 <= kMaxLines)) {
    throw hk::ArgumentError("raster path: more than 1000000 lines (spacing too small for the height)");
  }
  const int gaps = std::max(1, static_cast<int>(gaps_real));
  const double x0 = -0.5 * width_m;
  const double x1 = 0.5 * width_m;
  const double top = 0.5 * height_m;

  std::vector<HandSample> samples;
  samples.reserve(2 * static_cast<std::size_t>(gaps + 1));
  double t = 0.0;
  Vec2 prev{x0, top};
  samples.push_back({t, prev});
  const auto go = [&](Vec2 next) {
    t += distance(prev, next) / speed_m_per_s;
    samples.push_back({t, next});
    prev = next;
  };
  for (int line = 0; line <= gaps; ++line) {
    // Line k from the top; the last one is placed exactly on the bottom edge (no rounding drift).
    const double y = line == gaps ? -top : top - height_m * line / gaps;
    if (line > 0) go({prev.x, y});  // the short vertical move down to the next line
    go({line % 2 == 0 ? x1 : x0, y});
  }
  return HandPath(std::move(samples));
}

namespace {

/// A double in the shortest form that reads back the same (for messages).
std::string fmt(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t");
  return s.substr(first, last - first + 1);
}

class Reader {
 public:
  explicit Reader(const std::string& path) : path_(path), shown_path_(hk::one_line(path)) {}

  [[noreturn]] void fail(std::size_t line, const std::string& problem) const {
    throw HandFileError("hand file '" + shown_path_ + "' line " + std::to_string(line) + ": " + problem);
  }
  [[noreturn]] void fail_open(const std::string& problem) const {
    throw HandFileError("hand file '" + shown_path_ + "': " + problem);
  }

  HandPath read(const HandFileLimits& limits) {
    std::error_code ec;
    const auto st = std::filesystem::status(path_, ec);
    if (!std::filesystem::exists(st)) fail_open("cannot open: no such file");
    if (!std::filesystem::is_regular_file(st)) fail_open("cannot open: not a regular file");
    std::ifstream in(path_, std::ios::binary);
    if (!in) fail_open("cannot open: permission denied or I/O error");

    std::vector<HandSample> samples;
    std::string line;
    std::size_t line_no = 0;
    std::size_t first_blank = 0;  // line number of a blank line seen so far, 0 if none
    while (next_line(in, line, line_no, limits.max_line_chars)) {
      std::string_view text = line;
      if (line_no == 1) {
        if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
        if (text != "t_s,x_m,y_m") {
          fail(1, "header must be exactly 't_s,x_m,y_m', found '" + hk::one_line(text, 40) + "'");
        }
        continue;
      }
      if (trim(text).empty()) {
        if (first_blank == 0) first_blank = line_no;
        continue;
      }
      if (first_blank != 0) fail(first_blank, "blank line before the end of the data");
      if (samples.size() >= limits.max_rows) {
        fail(line_no, "more than " + std::to_string(limits.max_rows) + " rows (limit)");
      }
      samples.push_back(parse_row(text, line_no, limits, samples.empty() ? nullptr : &samples.back()));
    }
    if (line_no == 0) fail(1, "empty file (expected the header 't_s,x_m,y_m')");
    if (samples.empty()) fail(line_no + 1, "no data rows after the header (at least 1 needed)");
    return HandPath(std::move(samples));
  }

 private:
  /// Reads one line (without its '\n' and a trailing '\r') into `line`; false at end of file.
  /// Reads through the stream buffer (fast enough for the 10-million-row limit) and stops at
  /// max_chars + 1 characters, so a file without line breaks cannot fill memory.
  bool next_line(std::ifstream& in, std::string& line, std::size_t& line_no, std::size_t max_chars) const {
    using traits = std::char_traits<char>;
    std::streambuf* sb = in.rdbuf();
    line.clear();
    if (traits::eq_int_type(sb->sgetc(), traits::eof())) return false;
    ++line_no;
    for (auto c = sb->sbumpc(); !traits::eq_int_type(c, traits::eof()); c = sb->sbumpc()) {
      if (traits::to_char_type(c) == '\n') break;
      // One extra character is allowed through for a '\r' of a CRLF line end.
      if (line.size() > max_chars)
        fail(line_no, "line longer than " + std::to_string(max_chars) + " characters (limit)");
      line += traits::to_char_type(c);
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() > max_chars) fail(line_no, "line longer than " + std::to_string(max_chars) + " characters (limit)");
    return true;
  }

  HandSample parse_row(std::string_view text, std::size_t line_no, const HandFileLimits& limits,
                       const HandSample* prev) const {
    static constexpr const char* kNames[3] = {"t_s", "x_m", "y_m"};
    double v[3] = {0.0, 0.0, 0.0};
    std::size_t count = 0;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = text.find(',', start);
      const std::string_view field =
          trim(text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
      if (count < 3) {
        const char* b = field.data();
        // from_chars takes no leading '+'; a hand-written "+0.01" is still a number.
        if (field.size() > 1 && field[0] == '+' && field[1] != '-' && field[1] != '+') ++b;
        const char* e = field.data() + field.size();
        const auto [ptr, err] = std::from_chars(b, e, v[count]);
        // from_chars reports out-of-range (1e999) as result_out_of_range: that is a non-finite value.
        if (err == std::errc::result_out_of_range && ptr == e) {
          fail(line_no, std::string("field ") + kNames[count] + " '" + hk::one_line(field, 40) +
                            "' is out of the range of a double");
        }
        if (field.empty() || err != std::errc() || ptr != e) {
          fail(line_no, std::string("field ") + kNames[count] + " '" + hk::one_line(field, 40) + "' is not a number");
        }
      }
      ++count;
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    if (count != 3) fail(line_no, "expected 3 fields (t_s,x_m,y_m), found " + std::to_string(count));
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(v[i])) fail(line_no, std::string("field ") + kNames[i] + " is not finite");
    }
    const HandSample s{v[0], {v[1], v[2]}};
    if (s.t_s < 0.0) fail(line_no, "negative time " + fmt(s.t_s) + " s (times start at 0)");
    if (prev && !(s.t_s > prev->t_s)) {
      fail(line_no, "time " + fmt(s.t_s) + " s is not greater than the previous " + fmt(prev->t_s) +
                        " s (times must strictly increase)");
    }
    const double r = length(s.target_m);
    if (r > limits.max_distance_m) {
      fail(line_no, "point (" + fmt(s.target_m.x) + ", " + fmt(s.target_m.y) + ") is " + fmt(r) +
                        " m from the origin, limit " + fmt(limits.max_distance_m) + " m");
    }
    return s;
  }

  std::string path_;
  std::string shown_path_;
};

}  // namespace

HandPath load_hand_csv(const std::string& path, const HandFileLimits& limits) { return Reader(path).read(limits); }

HandPath raster_path_with_line_speeds(double width_m, double height_m, double spacing_m,
                                      const std::vector<double>& line_speeds_m_per_s, double step_speed_m_per_s) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  bool ok = !line_speeds_m_per_s.empty() && positive(step_speed_m_per_s);
  for (double v : line_speeds_m_per_s) ok = ok && positive(v);
  if (!ok) throw hk::ArgumentError("raster path: line speeds (at least one) and step speed must be finite and > 0");
  const HandPath unit = raster_path(width_m, height_m, spacing_m, 1.0);
  const std::vector<HandSample>& in = unit.samples();
  std::vector<HandSample> out;
  out.reserve(in.size());
  out.push_back({0.0, in[0].target_m});
  double t = 0.0;
  std::size_t line = 0;
  for (std::size_t i = 1; i < in.size(); ++i) {
    const Vec2 a = in[i - 1].target_m, b = in[i].target_m;
    const bool along_line = a.y == b.y;  // raster lines are horizontal; the steps between them vertical
    const double v = along_line ? line_speeds_m_per_s[line++ % line_speeds_m_per_s.size()] : step_speed_m_per_s;
    t += distance(a, b) / v;
    out.push_back({t, b});
  }
  return HandPath(std::move(out));
}

}  // namespace hk
