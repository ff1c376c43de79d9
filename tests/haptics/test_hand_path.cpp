/// @file test_hand_path.cpp
/// Hand paths (hand_path.hpp): interpolation, the raster's coverage and timing, and the hand-file
/// reader on good input and on every bad file under tests/data/bad/hand_*.csv.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "haptics/hand_path.hpp"
#include "hk/error.hpp"
#include "test_paths.hpp"

namespace hk {
namespace {

namespace fs = std::filesystem;

/// Writes `text` to a fresh file under the test temp dir and returns its path.
std::string write_temp(const std::string& name, const std::string& text) {
  const fs::path dir = fs::path(::testing::TempDir()) / "hk_hand_path";
  fs::create_directories(dir);
  const fs::path p = dir / name;
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
  return p.string();
}

/// The message of the HandFileError thrown by load_hand_csv, or "" (and a test failure) if none.
std::string load_error(const std::string& path, const HandFileLimits& limits = {}) {
  try {
    load_hand_csv(path, limits);
  } catch (const HandFileError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": wrong exception type: " << e.what();
    return "";
  }
  ADD_FAILURE() << path << ": no HandFileError";
  return "";
}

double polyline_length(const std::vector<HandSample>& s) {
  double len = 0.0;
  for (std::size_t i = 1; i < s.size(); ++i) len += distance(s[i - 1].target_m, s[i].target_m);
  return len;
}

double distance_to_path(Vec2 p, const std::vector<HandSample>& s) {
  double best = distance(p, s.front().target_m);
  for (std::size_t i = 1; i < s.size(); ++i) {
    best = std::min(best, distance_to_segment(p, s[i - 1].target_m, s[i].target_m));
  }
  return best;
}

// ---------------------------------------------------------------------------------------------
// HandPath

TEST(HandPath, InterpolatesAndClamps) {
  const HandPath path(std::vector<HandSample>{{0.5, {0.0, 0.0}}, {1.5, {0.02, -0.01}}, {2.0, {0.02, 0.03}}});
  EXPECT_DOUBLE_EQ(path.duration_s(), 2.0);
  EXPECT_EQ(path.at(0.0), (Vec2{0.0, 0.0})) << "held at the first point before it";
  EXPECT_EQ(path.at(-3.0), (Vec2{0.0, 0.0}));
  EXPECT_EQ(path.at(NAN), (Vec2{0.0, 0.0}));
  EXPECT_EQ(path.at(9.0), (Vec2{0.02, 0.03})) << "held at the last point after it";
  EXPECT_EQ(path.at(1.5), (Vec2{0.02, -0.01}));
  const Vec2 a = path.at(1.0);
  EXPECT_NEAR(a.x, 0.01, 1e-15);
  EXPECT_NEAR(a.y, -0.005, 1e-15);
  const Vec2 b = path.at(1.875);
  EXPECT_NEAR(b.x, 0.02, 1e-15);
  EXPECT_NEAR(b.y, -0.01 + 0.75 * 0.04, 1e-15);
}

TEST(HandPath, RejectsBadSamples) {
  using V = std::vector<HandSample>;
  EXPECT_THROW(HandPath(V{}), hk::ArgumentError);
  EXPECT_THROW(HandPath(V{{0.0, {}}, {0.0, {}}}), hk::ArgumentError);
  EXPECT_THROW(HandPath(V{{0.0, {}}, {1.0, {}}, {0.5, {}}}), hk::ArgumentError);
  EXPECT_THROW(HandPath(V{{-1.0, {}}}), hk::ArgumentError);
  EXPECT_THROW(HandPath(V{{0.0, {NAN, 0.0}}}), hk::ArgumentError);
  EXPECT_NO_THROW(HandPath(V{{0.0, {}}}));
}

// ---------------------------------------------------------------------------------------------
// Raster

struct RasterCase {
  double width_m, height_m, spacing_m, speed_m_per_s;
};

class Raster : public ::testing::TestWithParam<RasterCase> {};

TEST_P(Raster, CoversTheRectangleEdgeToEdge) {
  const RasterCase c = GetParam();
  const HandPath path = raster_path(c.width_m, c.height_m, c.spacing_m, c.speed_m_per_s);
  const auto& s = path.samples();
  const double hw = 0.5 * c.width_m, hh = 0.5 * c.height_m;

  // Starts at the top-left corner, never leaves the rectangle.
  EXPECT_EQ(s.front().target_m, (Vec2{-hw, hh}));
  EXPECT_EQ(s.front().t_s, 0.0);
  for (const HandSample& x : s) {
    EXPECT_LE(std::abs(x.target_m.x), hw + 1e-12);
    EXPECT_LE(std::abs(x.target_m.y), hh + 1e-12);
  }
  // Every point of a 5 mm grid (plus the far edges) is within half a line spacing of the path.
  std::vector<double> xs, ys;
  for (double x = -hw; x < hw; x += 0.005) xs.push_back(x);
  xs.push_back(hw);
  for (double y = -hh; y < hh; y += 0.005) ys.push_back(y);
  ys.push_back(hh);
  for (const double x : xs) {
    for (const double y : ys) {
      EXPECT_LE(distance_to_path({x, y}, s), 0.5 * c.spacing_m + 1e-9) << "(" << x << ", " << y << ")";
    }
  }
  // The whole bottom and top edges are traced (not just approached within spacing/2).
  for (const double x : xs) {
    EXPECT_LT(distance_to_path({x, hh}, s), 1e-12);
    EXPECT_LT(distance_to_path({x, -hh}, s), 1e-12);
  }
  // Horizontal lines no farther apart than requested.
  std::set<double> line_ys;
  for (const HandSample& x : s) line_ys.insert(x.target_m.y);
  double prev = -hh;
  for (const double y : line_ys) {
    EXPECT_LE(y - prev, c.spacing_m + 1e-12);
    prev = y;
  }
}

TEST_P(Raster, ConstantSpeedAndDurationIsLengthOverSpeed) {
  const RasterCase c = GetParam();
  const HandPath path = raster_path(c.width_m, c.height_m, c.spacing_m, c.speed_m_per_s);
  const double len = polyline_length(path.samples());
  EXPECT_NEAR(path.duration_s(), len / c.speed_m_per_s, 1e-9 * path.duration_s());
  // At least one full-width line per spacing of height, plus the descent.
  EXPECT_GE(len, std::ceil(c.height_m / c.spacing_m - 1e-9) * c.width_m + c.height_m - 1e-12);
  // Sampled every millisecond, the target never moves faster than the speed, and the distance it
  // covers adds up to the path length (corners cut by at most one step each).
  const double dt = 1e-3;
  double covered = 0.0;
  Vec2 last = path.at(0.0);
  for (double t = dt; t < path.duration_s() + dt; t += dt) {
    const Vec2 p = path.at(t);
    const double step = distance(last, p);
    EXPECT_LE(step, c.speed_m_per_s * dt * (1.0 + 1e-9)) << "t = " << t;
    covered += step;
    last = p;
  }
  EXPECT_NEAR(covered, len, 2.0 * static_cast<double>(path.samples().size()) * c.speed_m_per_s * dt);
  EXPECT_EQ(path.at(path.duration_s()), path.samples().back().target_m);
}

INSTANTIATE_TEST_SUITE_P(HandPath, Raster,
                         ::testing::Values(RasterCase{0.14, 0.09, 0.006, 0.08},  // kiosk defaults
                                           RasterCase{0.10, 0.05, 0.007, 0.05},  // spacing not a divisor
                                           RasterCase{0.14, 0.09, 0.2, 0.1},     // spacing > height
                                           RasterCase{0.03, 0.02, 0.0011, 0.3}));

TEST(HandPath, RasterRejectsBadArguments) {
  EXPECT_THROW(raster_path(0.0, 0.09, 0.006, 0.08), hk::ArgumentError);
  EXPECT_THROW(raster_path(0.14, -0.09, 0.006, 0.08), hk::ArgumentError);
  EXPECT_THROW(raster_path(0.14, 0.09, NAN, 0.08), hk::ArgumentError);
  EXPECT_THROW(raster_path(0.14, 0.09, 0.006, 0.0), hk::ArgumentError);
  EXPECT_THROW(raster_path(0.14, 0.09, 1e-12, 0.08), hk::ArgumentError) << "too many lines";
}

TEST(HandPath, RasterWithLineSpeedsTimesEachLineAtItsSpeed) {
  // 0.14 × 0.09 m at 0.03 m spacing: 4 lines (0.14 m each) and 3 steps (0.03 m each).
  const HandPath p = raster_path_with_line_speeds(0.14, 0.09, 0.03, {0.02, 0.2}, 0.05);
  const HandPath same_path = raster_path(0.14, 0.09, 0.03, 1.0);
  ASSERT_EQ(p.samples().size(), same_path.samples().size());
  for (std::size_t i = 0; i < p.samples().size(); ++i)
    EXPECT_EQ(p.samples()[i].target_m, same_path.samples()[i].target_m);
  // Lines alternate 7 s and 0.7 s, steps take 0.6 s: 2·7 + 2·0.7 + 3·0.6 = 17.2 s.
  EXPECT_NEAR(p.duration_s(), 17.2, 1e-9);
  EXPECT_NEAR(p.samples()[1].t_s, 7.0, 1e-9);
  EXPECT_NEAR(p.samples()[3].t_s - p.samples()[2].t_s, 0.7, 1e-9);
  EXPECT_THROW(raster_path_with_line_speeds(0.14, 0.09, 0.03, {}, 0.05), hk::ArgumentError);
  EXPECT_THROW(raster_path_with_line_speeds(0.14, 0.09, 0.03, {0.1, 0.0}, 0.05), hk::ArgumentError);
  EXPECT_THROW(raster_path_with_line_speeds(0.14, 0.09, 0.03, {0.1}, NAN), hk::ArgumentError);
}

// ---------------------------------------------------------------------------------------------
// Hand files

TEST(HandFile, GoodFileRoundTrips) {
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> u(-0.07, 0.07);
  std::vector<HandSample> want;
  std::string text = "t_s,x_m,y_m\n";
  double t = 0.0;
  for (int i = 0; i < 500; ++i) {
    want.push_back({t, {u(rng), u(rng)}});
    char line[128];
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g\n", want.back().t_s, want.back().target_m.x,
                  want.back().target_m.y);
    text += line;
    t += 0.001 + 0.01 * std::abs(u(rng));
  }
  const HandPath path = load_hand_csv(write_temp("good.csv", text));
  ASSERT_EQ(path.samples().size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(path.samples()[i].t_s, want[i].t_s);
    EXPECT_EQ(path.samples()[i].target_m, want[i].target_m);
  }
  EXPECT_EQ(path.duration_s(), want.back().t_s);
}

TEST(HandFile, DocumentedLeniencies) {
  // UTF-8 BOM, CRLF, spaces around fields, a leading '+', blank lines at the end.
  const HandPath path =
      load_hand_csv(write_temp("lenient.csv", "\xEF\xBB\xBFt_s,x_m,y_m\r\n0, 0.01 ,\t-0.02\r\n+0.5,+0.03,0\r\n\r\n\n"));
  ASSERT_EQ(path.samples().size(), 2u);
  EXPECT_EQ(path.samples()[0].target_m, (Vec2{0.01, -0.02}));
  EXPECT_EQ(path.samples()[1].t_s, 0.5);
  EXPECT_EQ(path.samples()[1].target_m, (Vec2{0.03, 0.0}));
  // A single row, no final newline.
  EXPECT_EQ(load_hand_csv(write_temp("one.csv", "t_s,x_m,y_m\n0.25,0,0")).duration_s(), 0.25);
}

/// Every bad hand file, with a fragment its message must contain (so each file fails for the reason it
/// was written for, not for an accident such as a broken header).
const std::map<std::string, std::string>& bad_files() {
  static const std::map<std::string, std::string> files = {
      {"hand_empty.csv", "line 1: empty file"},
      {"hand_header_wrong.csv", "line 1: header must be exactly"},
      {"hand_header_extra_column.csv", "line 1: header must be exactly"},
      {"hand_semicolon.csv", "line 1: header must be exactly"},
      {"hand_no_header.csv", "line 1: header must be exactly"},
      {"hand_header_only.csv", "line 2: no data rows"},
      {"hand_non_numeric.csv", "line 3: field x_m 'abc' is not a number"},
      {"hand_trailing_garbage.csv", "line 3: field x_m '0.01m' is not a number"},
      {"hand_empty_field.csv", "line 3: field x_m '' is not a number"},
      {"hand_too_few_fields.csv", "line 3: expected 3 fields"},
      {"hand_too_many_fields.csv", "line 3: expected 3 fields"},
      {"hand_nan.csv", "line 3: field x_m is not finite"},
      {"hand_inf.csv", "line 3: field y_m is not finite"},
      {"hand_overflow.csv", "line 3: field t_s '1e999' is out of the range"},
      {"hand_time_equal.csv", "line 4: time 0.1 s is not greater than the previous 0.1 s"},
      {"hand_time_decreasing.csv", "line 4: time 0.1 s is not greater than the previous 0.2 s"},
      {"hand_negative_time.csv", "line 2: negative time"},
      {"hand_too_far.csv", "line 3: point (1.5, 0) is 1.5 m from the origin, limit 1 m"},
      {"hand_too_far_diagonal.csv", "line 3: point (0.8, -0.8) is"},
      {"hand_blank_line_in_middle.csv", "line 3: blank line"},
      {"hand_long_line.csv", "line 3: line longer than 1024 characters (limit)"},
      // NUL, control bytes and bytes that are not UTF-8 come out as \\xNN (hk::one_line; a raw NUL would even cut
      // what() short).
      {"hand_binary.csv", "line 2: field t_s '\\x00\\x01\\x02\\xFF\\xFE\\x7F\\x1B[2J\\x00\\x00' is not a number"},
  };
  return files;
}

TEST(HandFile, EveryBadFileThrowsOneLineNamingIt) {
  const fs::path dir = fs::path(HK_TEST_DATA_DIR) / "bad";
  std::set<std::string> seen;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with("hand_") || entry.path().extension() != ".csv") continue;
    seen.insert(name);
    const std::string msg = load_error(entry.path().string());
    EXPECT_NE(msg.find(name), std::string::npos) << name << ": " << msg;
    EXPECT_EQ(msg.find_first_of("\n\r"), std::string::npos) << name << ": not one line: " << msg;
    // Printable ASCII only (the test data paths are ASCII): binary junk is not echoed raw.
    EXPECT_TRUE(std::all_of(msg.begin(), msg.end(),
                            [](char ch) {
                              const auto u = static_cast<unsigned char>(ch);
                              return u >= 0x20 && u < 0x7f;
                            }))
        << name << ": unprintable byte in: " << msg;
    const auto it = bad_files().find(name);
    if (it == bad_files().end()) {
      ADD_FAILURE() << name << " has no expected message in this test; add it to bad_files()";
    } else {
      EXPECT_NE(msg.find(it->second), std::string::npos) << name << ": expected '" << it->second << "' in: " << msg;
    }
  }
  for (const auto& [name, fragment] : bad_files()) EXPECT_TRUE(seen.count(name)) << "missing test file " << name;
}

TEST(HandFile, MissingFileAndDirectory) {
  const std::string missing = (fs::path(HK_TEST_DATA_DIR) / "bad" / "no_such_hand_file.csv").string();
  const std::string msg = load_error(missing);
  EXPECT_NE(msg.find("no_such_hand_file.csv"), std::string::npos) << msg;
  EXPECT_NE(msg.find("cannot open"), std::string::npos) << msg;
  const std::string dir_msg = load_error((fs::path(HK_TEST_DATA_DIR) / "bad").string());
  EXPECT_NE(dir_msg.find("not a regular file"), std::string::npos) << dir_msg;
}

TEST(HandFile, RowAndDistanceLimits) {
  HandFileLimits limits;
  limits.max_rows = 3;
  const std::string three = write_temp("three.csv", "t_s,x_m,y_m\n0,0,0\n1,0,0\n2,0,0\n");
  EXPECT_EQ(load_hand_csv(three, limits).samples().size(), 3u);
  const std::string four = write_temp("four.csv", "t_s,x_m,y_m\n0,0,0\n1,0,0\n2,0,0\n3,0,0\n");
  const std::string msg = load_error(four, limits);
  EXPECT_NE(msg.find("line 5: more than 3 rows (limit)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("four.csv"), std::string::npos) << msg;

  // The distance limit is inclusive and named in the message.
  EXPECT_NO_THROW(load_hand_csv(write_temp("edge.csv", "t_s,x_m,y_m\n0,0,1\n1,-1,0\n")));
  limits = {};
  limits.max_distance_m = 0.5;
  const std::string far = load_error(write_temp("far.csv", "t_s,x_m,y_m\n0,0,0\n1,0.3,0.4000001\n"), limits);
  EXPECT_NE(far.find("limit 0.5 m"), std::string::npos) << far;
}

}  // namespace
}  // namespace hk
