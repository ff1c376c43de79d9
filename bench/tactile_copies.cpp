// A take-home copy of every tests/data picture and shipped picture (copies/): the time to lay it out and write it
// as PDF and as SVG (the scene built once beforehand, as the kiosk has it when the Copy key is pressed), and the
// guidelines' checks measured on what was laid out: the closest two distinct shapes' outlines (centre to centre;
// ≥ 4 mm keeps a 3 mm gap between 1 mm lines), the closest a label comes to a line (centre, ≥ 3.5 mm), the
// smallest shape kept (its box's longer side, ≥ 6 mm), line styles used (≤ 5), shapes kept, labelled and left out,
// pages. Each copy is timed N times (--runs, default 5); the figure is the median. Target: ≤ 300 ms a copy (PDF
// and SVG each). Prints a Markdown table on stdout.
// Usage: bench_tactile_copies [--runs N] > docs/bench/tactile_copies.md
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "bench_scenes.hpp"
#include "cli/explore.hpp"
#include "copies/tactile_output.hpp"
#include "copies/tactile_scene.hpp"
#include "pictures/picture_names.hpp"

using namespace hk;
using namespace hk::app;
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kTargetMs = 300.0;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double dist_point_segment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a, ap = p - a;
  const double len2 = ab.x * ab.x + ab.y * ab.y;
  const double t = len2 > 0 ? std::clamp((ap.x * ab.x + ap.y * ab.y) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(p.x - (a.x + t * ab.x), p.y - (a.y + t * ab.y));
}

/// The guidelines' figures of a laid-out copy's picture page.
struct Checks {
  double closest_shapes_mm = INFINITY, closest_label_mm = INFINITY, smallest_mm = INFINITY;
  int styles = 0, kept = 0, labelled = 0;
};

Checks check(const TactileGraphic& g) {
  Checks c;
  const TactilePage& p = g.pages.front();
  c.kept = static_cast<int>(p.shapes.size());
  std::set<LineStyle> styles;
  for (const TactileShape& s : p.shapes) {
    c.labelled += s.labelled;
    styles.insert(s.style);
  }
  c.styles = static_cast<int>(styles.size());
  for (std::size_t i = 0; i < p.strokes.size(); ++i) {
    const TactileStroke& a = p.strokes[i];
    if (a.points_mm.size() <= 2) continue;  // lead lines
    double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
    for (const Vec2& q : a.points_mm)
      x0 = std::min(x0, q.x), x1 = std::max(x1, q.x), y0 = std::min(y0, q.y), y1 = std::max(y1, q.y);
    c.smallest_mm = std::min(c.smallest_mm, std::max(x1 - x0, y1 - y0));
    for (std::size_t j = i + 1; j < p.strokes.size(); ++j) {
      const TactileStroke& b = p.strokes[j];
      if (b.points_mm.size() <= 2 || b.shape == a.shape) continue;
      c.closest_shapes_mm =
          std::min(c.closest_shapes_mm, polyline_distance(a.points_mm, a.closed, b.points_mm, b.closed));
    }
  }
  for (const TactileLabel& l : p.labels) {
    if (l.shape < 0) continue;
    const double w = braille_cell_count(l.cells) * kBrailleCellPitchMm;
    const double h = kBrailleLinePitchMm;
    for (const TactileStroke& s : p.strokes) {
      if (s.shape == l.shape && s.points_mm.size() == 2) continue;  // its own lead line
      for (double y = l.at_mm.y; y <= l.at_mm.y + h; y += 1.0)
        for (double x = l.at_mm.x; x <= l.at_mm.x + w; x += 1.0)
          for (std::size_t k = 0; k + 1 < s.points_mm.size(); ++k)
            c.closest_label_mm =
                std::min(c.closest_label_mm, dist_point_segment({x, y}, s.points_mm[k], s.points_mm[k + 1]));
    }
  }
  return c;
}

std::string mm(double v) {
  char b[32];
  std::snprintf(b, sizeof b, std::isfinite(v) ? "%.1f" : "–", v);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) {
      runs = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_tactile_copies [--runs N]\n");
      return 2;
    }
  }
  spdlog::set_level(spdlog::level::warn);
  const config::Settings s;
  std::vector<fs::path> pictures = bench::picture_paths();
  for (const char* shipped : {"butterfly.jpg", "coins.png", "horse.png", "silhouette_3.png"})
    pictures.push_back(fs::path(HK_DATA_DIR) / "pictures" / shipped);
  const fs::path out = fs::temp_directory_path() / ("hk_bench_tactile_" + std::to_string(::getpid()));
  fs::create_directories(out);
  std::printf(
      "Take-home copies on A4, English contracted braille, default settings; median of %d runs [ms]; "
      "distances on the picture page [mm].\n\n",
      runs);
  std::printf(
      "| picture | lay out | PDF | SVG | closest shapes | closest label | smallest shape | styles | shapes "
      "kept / labelled / left out | pages |\n|---|---|---|---|---|---|---|---|---|---|\n");
  double worst = 0;
  for (const fs::path& p : pictures) {
    ImageScene is = build_input_scene(p.string(), 0, s);
    apply_names(is, names_file_for(p.string(), ""), p.filename().string());
    const TactileInput in = tactile_input_of(is, s.haptics.level, Paper::a4, "en", p.stem().string());
    std::vector<double> layout, pdf, svg;
    TactileGraphic g;
    for (int r = 0; r < runs; ++r) {
      auto t0 = Clock::now();
      g = lay_out_tactile(in, Paper::a4);
      layout.push_back(ms_since(t0));
      t0 = Clock::now();
      write_tactile(g, (out / "copy.pdf").string(), BrailleGrade::two);
      pdf.push_back(ms_since(t0));
      t0 = Clock::now();
      write_tactile(g, (out / "copy.svg").string(), BrailleGrade::two);
      svg.push_back(ms_since(t0));
    }
    const Checks c = check(g);
    const double l = median(layout), a = median(pdf), b = median(svg);
    worst = std::max({worst, l + a, l + b});
    std::printf("| %s | %.1f | %.1f | %.1f | %s | %s | %s | %d | %d / %d / %d | %zu |\n", p.filename().c_str(), l, a, b,
                mm(c.closest_shapes_mm).c_str(), mm(c.closest_label_mm).c_str(), mm(c.smallest_mm).c_str(), c.styles,
                c.kept, c.labelled, g.left_out, g.pages.size());
  }
  std::printf("\nSlowest copy (lay out + PDF, or lay out + SVG): %.1f ms; target ≤ %.0f ms: %s.\n", worst, kTargetMs,
              worst <= kTargetMs ? "met" : "NOT met");
  fs::remove_all(out);
  return 0;
}
