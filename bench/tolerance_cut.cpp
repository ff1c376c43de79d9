// Vertices per error: a tolerance cut through our collision tree against
// Douglas–Peucker on every test picture.
//
// Usage: bench_tolerance_cut [--out FILE.json] [--max-levels N]    (prints a markdown table)
//   --max-levels N  build every scene with N levels above level 0 instead of [haptics] max_levels (6), to see
//                   what coarser levels would buy a long curve at a large T (it stops at length / 2^N
//                   otherwise); the pictures' curves are chosen as with the default
//
// For a target error T, each method keeps every original vertex within T, measured:
//   cut  hk::tolerance_cut on every curve (refine a segment while its box's error bound exceeds the
//        tolerance; seed §3), drawn joined (hk::joined_cut_points: where the cut changes level, both pieces
//        meet at the finer segment's end). Joining moves a coarser segment's end a little, so the cut's
//        tolerance is searched per curve: the largest T·0.97^i (i = 0…79) whose joined polyline keeps
//        every original vertex within T. Curves whose level-0 error bound exceeds T are counted apart
//        (the cut stops at level 0 there).
//   dp   Douglas & Peucker (1973), cv::approxPolyDP on the original vertices with epsilon = T (closed flag
//        kept): every original vertex within T of the chord that replaced it.
//   curve levels  each curve at the coarsest of its levels whose error bound is ≤ T (Scene::
//        coarsest_level_within; what the level policy's tolerance steps render, level_mode = "tolerance").
// Vertices: dp's count; the joined cut's (CutStats::vertices: segments, + 1 when open); curve levels':
// that level's points. Measured error, the same way for all: the largest distance of an original vertex
// from the nearest segment of the simplified polyline (OpenCV's closed-curve DP can exceed epsilon there:
// its measured error is printed beside it). The ratio is the cut's vertices over dp's, per picture (all its
// curves); the target is ≤ 1.2 on every picture. A second table runs the same on traced polygons (one
// sharp-cornered shape each), where the structure's limit shows on its own (polygon_table). A third is an
// experiment, not what the kiosk builds: every curve broken at its corners into open pieces with levels of
// their own (cut_broken_at_corners), and the same again with a piece that lies within T of its chord kept as
// that one segment (a Douglas–Peucker step above the piece's coarsest level), with how many pictures each
// keeps within 1.2x DP.
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench_scenes.hpp"
#include "haptics/tolerance_cut.hpp"

using namespace hk;
using namespace hk::bench;

namespace {

// Largest distance of any original vertex from the nearest of `segs` [m].
double max_vertex_error(const std::vector<Vec2>& orig, const std::vector<std::pair<Vec2, Vec2>>& segs) {
  double worst = 0.0;
  for (const Vec2& p : orig) {
    double d = std::numeric_limits<double>::infinity();
    for (const auto& s : segs) d = std::min(d, distance_to_segment(p, s.first, s.second));
    worst = std::max(worst, d);
  }
  return worst;
}

struct Tally {
  std::size_t cut_vertices = 0, cut_breaks = 0, dp_vertices = 0, curves_below_level0 = 0, level_vertices = 0;
  double cut_error_m = 0.0, dp_error_m = 0.0, level_error_m = 0.0;
};

void curve_level(const Scene& sc, std::size_t c, const Polyline& src, double tol_m, Tally& t) {
  const int l = sc.coarsest_level_within(c, tol_m);
  const CurveInfo& ci = sc.curve(c);
  std::vector<std::pair<Vec2, Vec2>> segs;
  for (std::uint32_t k = 0; k < ci.segment_count[l]; ++k) {
    Vec2 a, b;
    sc.segment({static_cast<int>(c), l, static_cast<int>(k)}, &a, &b);
    segs.push_back({a, b});
  }
  t.level_vertices += ci.point_count[l];  // distinct points: an open curve's include both ends
  t.level_error_m = std::max(t.level_error_m, max_vertex_error(src.points_m, segs));
}

// The joined cut of curve c at the largest searched tolerance whose measured error is within tol_m.
void cut_curve(const Scene& sc, std::size_t c, const Polyline& src, double tol_m, Tally& t) {
  constexpr int kSearchSteps = 80;
  double tried_m = tol_m;
  for (int i = 0; i < kSearchSteps; ++i, tried_m *= 0.97) {
    std::vector<SegmentRef> cut;
    const CutStats st = tolerance_cut(sc, c, tried_m, &cut);
    const std::vector<Vec2> pts = joined_cut_points(sc, c, cut.data(), cut.size());
    std::vector<std::pair<Vec2, Vec2>> segs;
    for (std::size_t k = 0; k < cut.size(); ++k) segs.push_back({pts[k], pts[(k + 1) % pts.size()]});
    const double error_m = max_vertex_error(src.points_m, segs);
    if (error_m <= tol_m || i + 1 == kSearchSteps) {
      t.cut_vertices += st.vertices;
      t.cut_breaks += st.breaks;
      t.cut_error_m = std::max(t.cut_error_m, error_m);
      break;
    }
  }
  if (sc.curve(c).max_error_bound_m[0] > tol_m) ++t.curves_below_level0;
}

void dp_curve(const Polyline& src, double tol_m, Tally& t) {
  std::vector<cv::Point2f> in, out;  // approxPolyDP takes float or int points; 1e-8 m of rounding
  for (const Vec2& p : src.points_m) in.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
  cv::approxPolyDP(in, out, tol_m, src.closed);
  std::vector<std::pair<Vec2, Vec2>> segs;
  for (std::size_t i = 0; i + 1 < out.size(); ++i) segs.push_back({{out[i].x, out[i].y}, {out[i + 1].x, out[i + 1].y}});
  if (src.closed && out.size() > 1) segs.push_back({{out.back().x, out.back().y}, {out[0].x, out[0].y}});
  if (segs.empty() && !out.empty()) segs.push_back({{out[0].x, out[0].y}, {out[0].x, out[0].y}});
  t.dp_vertices += out.size();
  t.dp_error_m = std::max(t.dp_error_m, max_vertex_error(src.points_m, segs));
}

// Corners of an original polyline: vertices where the direction turns by at least kCornerTurn_rad between the
// chord from the point kCornerReach_m back along the curve and the chord to the point as far ahead (so a
// pixel chain's staircase does not count), the largest turn within that reach on either side. An open
// curve's ends are not corners (they end its pieces anyway). Indices in ascending order.
constexpr double kCornerReach_m = 1.0e-3, kCornerTurn_rad = 40.0 * M_PI / 180.0;
std::vector<std::size_t> corners_of(const Polyline& src) {
  const std::vector<Vec2>& p = src.points_m;
  const std::size_t n = p.size();
  std::vector<double> turn(n, 0.0);
  if (n < 5) return {};
  auto at = [&](long i) -> std::size_t {
    return static_cast<std::size_t>(((i % static_cast<long>(n)) + static_cast<long>(n)) % static_cast<long>(n));
  };
  for (std::size_t i = 0; i < n; ++i) {
    long back = static_cast<long>(i), ahead = static_cast<long>(i);
    bool ok = true;
    do {
      --back;
      if (!src.closed && back < 0) ok = false;
    } while (ok && distance(p[at(back)], p[i]) < kCornerReach_m &&
             static_cast<long>(i) - back < static_cast<long>(n) / 2);
    do {
      ++ahead;
      if (!src.closed && ahead >= static_cast<long>(n)) ok = false;
    } while (ok && distance(p[at(ahead)], p[i]) < kCornerReach_m &&
             ahead - static_cast<long>(i) < static_cast<long>(n) / 2);
    if (!ok) continue;
    const Vec2 u = p[i] - p[at(back)], v = p[at(ahead)] - p[i];
    turn[i] = std::abs(std::atan2(u.x * v.y - u.y * v.x, u.x * v.x + u.y * v.y));
  }
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < n; ++i) {
    if (turn[i] < kCornerTurn_rad) continue;
    bool peak = true;  // the largest turn within the reach (the first of equals)
    for (long d = 1; peak && d < static_cast<long>(n) / 2; ++d) {
      const std::size_t f = at(static_cast<long>(i) + d), b = at(static_cast<long>(i) - d);
      const bool f_in =
          (src.closed || static_cast<long>(i) + d < static_cast<long>(n)) && distance(p[f], p[i]) < kCornerReach_m;
      const bool b_in = (src.closed || static_cast<long>(i) - d >= 0) && distance(p[b], p[i]) < kCornerReach_m;
      if (!f_in && !b_in) break;
      if ((f_in && turn[f] > turn[i]) || (b_in && turn[b] >= turn[i])) peak = false;
    }
    if (peak) out.push_back(i);
  }
  return out;
}

// The curve broken at its corners into open pieces, each from one corner (or end) to the next, sharing it.
std::vector<Polyline> pieces_at_corners(const Polyline& src, const std::vector<std::size_t>& corners) {
  const std::vector<Vec2>& p = src.points_m;
  std::vector<Polyline> out;
  if (corners.empty()) return {src};
  std::vector<std::size_t> cuts = corners;
  if (!src.closed) {
    if (cuts.front() != 0) cuts.insert(cuts.begin(), 0);
    if (cuts.back() != p.size() - 1) cuts.push_back(p.size() - 1);
  }
  const std::size_t m = src.closed ? cuts.size() : cuts.size() - 1;
  for (std::size_t k = 0; k < m; ++k) {
    Polyline piece;
    piece.closed = false;
    const std::size_t a = cuts[k], b = cuts[(k + 1) % cuts.size()];
    for (std::size_t i = a;; i = (i + 1) % p.size()) {
      piece.points_m.push_back(p[i]);
      if (i == b && piece.points_m.size() > 1) break;
    }
    out.push_back(std::move(piece));
  }
  return out;
}

// What a hierarchy broken at corners would keep: each curve cut into pieces at its corners (corners_of), every
// piece its own open curve with its own levels, the joined cut of each piece searched as cut_curve searches it
// (every original vertex of the piece within T), its vertices counted once where two pieces share a corner. Not
// what the kiosk builds (a curve is one curve of the scene): an experiment that measures how much of the gap to
// Douglas–Peucker the corners are. Returns the vertices; adds the pieces' largest measured error to *error_m.
std::size_t cut_broken_at_corners(const Polyline& src, double tol_m, int max_levels, bool chord_roots,
                                  std::size_t* corner_count, double* error_m) {
  const std::vector<std::size_t> corners = corners_of(src);
  *corner_count += corners.size();
  if (corners.empty()) return 0;  // the caller counts the curve's own cut
  const std::vector<Polyline> pieces = pieces_at_corners(src, corners);
  const Scene sc = Scene::build(pieces, max_levels);
  std::size_t vertices = pieces.size() - sc.curve_count();  // a piece without a model (none on the pictures): its chord
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const Polyline& piece = pieces[sc.source_index(c)];
    if (chord_roots) {  // the piece's chord, when it keeps every vertex of the piece within T (one segment)
      const double chord_m = max_vertex_error(piece.points_m, {{piece.points_m.front(), piece.points_m.back()}});
      if (chord_m <= tol_m) {
        vertices += 1;
        *error_m = std::max(*error_m, chord_m);
        continue;
      }
    }
    Tally t;
    cut_curve(sc, c, piece, tol_m, t);
    vertices += t.cut_vertices - 1;  // its last vertex is the next piece's first (closed), or the curve's end
    *error_m = std::max(*error_m, t.cut_error_m);
  }
  return vertices + (src.closed ? 0 : 1);
}

// A closed polygon through `corners` [m], traced with a point every `step_m` along its sides, as an edge
// chain of a drawn shape would be (corners included).
Polyline traced_polygon(const std::vector<Vec2>& corners, double step_m) {
  Polyline out;
  out.closed = true;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    const Vec2 a = corners[i], b = corners[(i + 1) % corners.size()];
    const int n = std::max(1, static_cast<int>(std::lround(distance(a, b) / step_m)));
    for (int k = 0; k < n; ++k) out.points_m.push_back(a + (b - a) * (static_cast<double>(k) / n));
  }
  return out;
}

// Where the target meets the structure: polygons whose sides are straight and whose corners are sharp.
// Douglas–Peucker keeps one vertex a corner at every T. Every level of the wavelet model smooths each
// corner over a few of its segments, and a level's segments are twice as long as the next finer one's, so
// the cut refines dyadic levels around a corner until a level's rounding there is within T: a few vertices
// per corner for each halving from the side's length down to about T. Its count grows with log2(side / T)
// where DP's stays put; no choice of segments in a dyadic smoothing tree avoids that. Printed as a second
// table, each shape on its own (one curve).
void polygon_table(nlohmann::json& out, const std::vector<double>& tolerances_mm, int max_levels) {
  constexpr double kStep_m = 0.25e-3;  // 4 points a millimetre, an edge chain's pixel pitch at 0.25 mm/px
  const std::vector<std::pair<const char*, std::vector<Vec2>>> shapes = {
      {"square 60 mm", {{0.02, 0.02}, {0.08, 0.02}, {0.08, 0.08}, {0.02, 0.08}}},
      {"triangle 70 mm", {{0.02, 0.02}, {0.09, 0.02}, {0.055, 0.0806}}},
      {"L 60 x 40 mm", {{0.02, 0.02}, {0.08, 0.02}, {0.08, 0.04}, {0.04, 0.04}, {0.04, 0.06}, {0.02, 0.06}}},
  };
  std::printf(
      "\n| polygon | corners | T mm | joined cut vertices | dp vertices | cut / dp | cut error mm | dp error mm "
      "|\n|---|---|---|---|---|---|---|---|\n");
  for (const auto& [name, corners] : shapes) {
    const std::vector<Polyline> curves = {traced_polygon(corners, kStep_m)};
    const Scene sc = Scene::build(curves, max_levels);
    for (const double tol_mm : tolerances_mm) {
      Tally t;
      cut_curve(sc, 0, curves[0], tol_mm * 1e-3, t);
      dp_curve(curves[0], tol_mm * 1e-3, t);
      const double ratio =
          static_cast<double>(t.cut_vertices) / static_cast<double>(std::max<std::size_t>(1, t.dp_vertices));
      std::printf("| %s | %zu | %.1f | %zu | %zu | %.2f | %.3f | %.3f |\n", name, corners.size(), tol_mm,
                  t.cut_vertices, t.dp_vertices, ratio, 1e3 * t.cut_error_m, 1e3 * t.dp_error_m);
      out.push_back({{"polygon", name},
                     {"corners", corners.size()},
                     {"tolerance_mm", tol_mm},
                     {"cut_vertices", t.cut_vertices},
                     {"dp_vertices", t.dp_vertices},
                     {"ratio", ratio},
                     {"cut_error_mm", 1e3 * t.cut_error_m},
                     {"dp_error_mm", 1e3 * t.dp_error_m}});
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_path = "docs/bench/tolerance_cut.json";
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--out") == 0) out_path = argv[i + 1];
  }
  config::Settings settings;
  const auto paths = picture_paths();
  const auto pictures = picture_curves(settings);
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--max-levels") == 0) settings.haptics.max_levels = std::atoi(argv[i + 1]);
  }
  if (settings.haptics.max_levels < 0 || settings.haptics.max_levels >= kMaxLevels) {
    std::fprintf(stderr, "bench_tolerance_cut: --max-levels %d is outside [0, %d]\n", settings.haptics.max_levels,
                 kMaxLevels - 1);
    return 2;
  }
  const std::vector<double> tolerances_mm = {0.2, 0.3, 0.5, 1.0, 2.0};
  nlohmann::json rows = nlohmann::json::array();
  std::printf(
      "| picture | curves | T mm | joined cut vertices (breaks joined) | dp vertices | cut / dp | cut error mm | dp "
      "error mm | curves with level-0 error > T | curve levels vertices | curve levels / dp | curve levels error mm "
      "|\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<double> worst_ratio(tolerances_mm.size(), 0.0), worst_level_ratio(tolerances_mm.size(), 0.0);
  std::vector<double> worst_broken_ratio(tolerances_mm.size(), 0.0), worst_broken_error_mm(tolerances_mm.size(), 0.0);
  std::vector<std::string> worst_broken_picture(tolerances_mm.size());
  std::vector<double> worst_chord_ratio(tolerances_mm.size(), 0.0);
  std::vector<int> within_cut(tolerances_mm.size(), 0), within_broken(tolerances_mm.size(), 0),
      within_chord(tolerances_mm.size(), 0);
  nlohmann::json broken_rows = nlohmann::json::array();
  for (std::size_t p = 0; p < paths.size(); ++p) {
    const Scene sc = Scene::build(pictures[p], settings.haptics.max_levels);
    for (std::size_t ti = 0; ti < tolerances_mm.size(); ++ti) {
      const double tol_m = tolerances_mm[ti] * 1e-3;
      Tally t;
      std::size_t broken_vertices = 0, corners = 0, chord_vertices = 0;
      double broken_error_m = 0.0, chord_error_m = 0.0;
      for (std::size_t c = 0; c < sc.curve_count(); ++c) {
        const Polyline& src = pictures[p][sc.source_index(c)];
        Tally own;  // this curve's own cut, which the broken variants keep for a curve without corners
        cut_curve(sc, c, src, tol_m, own);
        t.cut_vertices += own.cut_vertices;
        t.cut_breaks += own.cut_breaks;
        t.cut_error_m = std::max(t.cut_error_m, own.cut_error_m);
        t.curves_below_level0 += own.curves_below_level0;
        dp_curve(src, tol_m, t);
        curve_level(sc, c, src, tol_m, t);
        const std::size_t broken =
            cut_broken_at_corners(src, tol_m, settings.haptics.max_levels, false, &corners, &broken_error_m);
        std::size_t ignored = 0;
        const std::size_t chorded =
            cut_broken_at_corners(src, tol_m, settings.haptics.max_levels, true, &ignored, &chord_error_m);
        if (broken == 0) {
          broken_error_m = std::max(broken_error_m, own.cut_error_m);
          chord_error_m = std::max(chord_error_m, own.cut_error_m);
        }
        broken_vertices += broken > 0 ? broken : own.cut_vertices;
        chord_vertices += chorded > 0 ? chorded : own.cut_vertices;
      }
      const double broken_ratio =
          static_cast<double>(broken_vertices) / static_cast<double>(std::max<std::size_t>(1, t.dp_vertices));
      if (broken_ratio > worst_broken_ratio[ti]) worst_broken_picture[ti] = paths[p].stem().string();
      worst_broken_ratio[ti] = std::max(worst_broken_ratio[ti], broken_ratio);
      worst_broken_error_mm[ti] = std::max(worst_broken_error_mm[ti], 1e3 * broken_error_m);
      const double chord_ratio =
          static_cast<double>(chord_vertices) / static_cast<double>(std::max<std::size_t>(1, t.dp_vertices));
      worst_chord_ratio[ti] = std::max(worst_chord_ratio[ti], chord_ratio);
      within_broken[ti] += broken_ratio <= 1.2;
      within_chord[ti] += chord_ratio <= 1.2;
      broken_rows.push_back({{"picture", paths[p].stem().string()},
                             {"tolerance_mm", tolerances_mm[ti]},
                             {"corners", corners},
                             {"vertices", broken_vertices},
                             {"dp_vertices", t.dp_vertices},
                             {"ratio", broken_ratio},
                             {"error_mm", 1e3 * broken_error_m},
                             {"chord_vertices", chord_vertices},
                             {"chord_ratio", chord_ratio},
                             {"chord_error_mm", 1e3 * chord_error_m}});
      const double dp = static_cast<double>(std::max<std::size_t>(1, t.dp_vertices));
      const double ratio = static_cast<double>(t.cut_vertices) / dp,
                   level_ratio = static_cast<double>(t.level_vertices) / dp;
      worst_ratio[ti] = std::max(worst_ratio[ti], ratio);
      worst_level_ratio[ti] = std::max(worst_level_ratio[ti], level_ratio);
      within_cut[ti] += ratio <= 1.2;
      std::printf("| %s | %zu | %.1f | %zu (%zu) | %zu | %.2f | %.3f | %.3f | %zu | %zu | %.2f | %.3f |\n",
                  paths[p].stem().c_str(), sc.curve_count(), tolerances_mm[ti], t.cut_vertices, t.cut_breaks,
                  t.dp_vertices, ratio, 1e3 * t.cut_error_m, 1e3 * t.dp_error_m, t.curves_below_level0,
                  t.level_vertices, level_ratio, 1e3 * t.level_error_m);
      rows.push_back({{"picture", paths[p].stem().string()},
                      {"curves", sc.curve_count()},
                      {"tolerance_mm", tolerances_mm[ti]},
                      {"cut_vertices", t.cut_vertices},
                      {"cut_breaks", t.cut_breaks},
                      {"dp_vertices", t.dp_vertices},
                      {"ratio", ratio},
                      {"cut_error_mm", 1e3 * t.cut_error_m},
                      {"dp_error_mm", 1e3 * t.dp_error_m},
                      {"curves_below_level0", t.curves_below_level0},
                      {"curve_levels_vertices", t.level_vertices},
                      {"curve_levels_ratio", level_ratio},
                      {"curve_levels_error_mm", 1e3 * t.level_error_m}});
    }
  }
  std::printf("\n| T mm | worst cut / dp over the pictures | worst curve levels / dp |\n|---|---|---|\n");
  nlohmann::json worst = nlohmann::json::array();
  for (std::size_t ti = 0; ti < tolerances_mm.size(); ++ti) {
    std::printf("| %.1f | %.2f | %.2f |\n", tolerances_mm[ti], worst_ratio[ti], worst_level_ratio[ti]);
    worst.push_back({{"tolerance_mm", tolerances_mm[ti]},
                     {"worst_ratio", worst_ratio[ti]},
                     {"worst_curve_levels_ratio", worst_level_ratio[ti]}});
  }
  nlohmann::json polygons = nlohmann::json::array();
  polygon_table(polygons, tolerances_mm, settings.haptics.max_levels);
  std::printf(
      "\n| T mm | pictures <= 1.2x dp: cut | broken at corners: worst cut / dp | its picture | pictures <= 1.2x | "
      "largest measured error mm | "
      "and a piece within T of its chord as one segment: worst / dp | pictures <= 1.2x "
      "|\n|---|---|---|---|---|---|---|---|\n");
  nlohmann::json broken_worst = nlohmann::json::array();
  for (std::size_t ti = 0; ti < tolerances_mm.size(); ++ti) {
    std::printf("| %.1f | %d of %zu | %.2f | %s | %d | %.3f | %.2f | %d |\n", tolerances_mm[ti], within_cut[ti],
                paths.size(), worst_broken_ratio[ti], worst_broken_picture[ti].c_str(), within_broken[ti],
                worst_broken_error_mm[ti], worst_chord_ratio[ti], within_chord[ti]);
    broken_worst.push_back({{"tolerance_mm", tolerances_mm[ti]},
                            {"worst_ratio", worst_broken_ratio[ti]},
                            {"picture", worst_broken_picture[ti]},
                            {"largest_error_mm", worst_broken_error_mm[ti]},
                            {"worst_chord_ratio", worst_chord_ratio[ti]},
                            {"pictures_within_1_2_cut", within_cut[ti]},
                            {"pictures_within_1_2_broken", within_broken[ti]},
                            {"pictures_within_1_2_chord", within_chord[ti]}});
  }
  std::ofstream(out_path) << nlohmann::json{{"rows", rows},
                                            {"worst", worst},
                                            {"polygons", polygons},
                                            {"broken_at_corners", {{"rows", broken_rows}, {"worst", broken_worst}}}}
                                 .dump(1)
                          << "\n";
  return 0;
}
