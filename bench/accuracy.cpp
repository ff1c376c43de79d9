// Accuracy against size: how far each level of our multiresolution model lies from
// the original curve, compared at equal vertex counts with three other ways of shrinking the same curve.
//
// Usage: bench_accuracy [--images DIR] [--out FILE.json] [--rms-step-mm S] [--tol-mm T] [--threads N]
//   defaults: --images tests/data/images, --out docs/bench/accuracy.json, S = 0.01, T = 0.001
//
// Curves: every chain of every .png/.jpg in DIR through the kiosk's own pipeline with the shipped
// settings (hk::app::build_image_scene, hk::config::Settings{}), in workspace metres. The original
// is the linked pixel chain (one vertex per edge pixel); errors are reported in millimetres.
//
// Methods, per curve and per level l of our model, all with the same vertex count n_l:
//   ours       Reissell's pseudocoiflets (UBC TR 93-17, 1993; seed paper §2): the level-l scaling
//              coefficients of curve c (build_multires; bit for bit the scene's level-l polyline, the one
//              the contact solver uses).
//   dp         Douglas & Peucker (1973), cv::approxPolyDP on the original vertices (closed flag kept),
//              epsilon found by bisection so the vertex count is as close to n_l as it gets (it can
//              stay below n_l at level 0, where n_l exceeds the original count: DP only keeps vertices).
//   uniform    n_l points equally spaced in arc length along the original (hk::resample_arc_length;
//              open curves keep both ends) — decimation with no smoothing at all.
//   linear22   the (2,2) interpolating wavelet by lifting (Sweldens 1996, "The lifting scheme"):
//              predict d_k = x_{2k+1} − (x_{2k} + x_{2k+2})/2, update s_k = x_{2k} + (d_{k−1} + d_k)/4,
//              periodic on closed curves; open curves keep both end samples (missing d = 0), applied to
//              the same level-0 samples (build_multires' scaling[0]) for the same number of levels, so its point
//              counts equal ours exactly. Same lifting structure as ours, two vanishing moments fewer.
//
// Errors of a simplified polyline A against the original O (closed curves include the closing segment):
//   max deviation = symmetric Hausdorff distance max(h(O→A), h(A→O)), where h(X→Y) = max over every
//                   point of X (not only vertices) of its distance to Y, evaluated to within --tol-mm
//                   by Lipschitz stepping (support/accuracy_geometry.hpp) with a segment grid;
//   RMS           = sqrt of the arc-length mean of d(o, A)² over o on O, midpoint rule, pieces ≤ --rms-step-mm.
// Error-box tightness: CurveInfo::max_box_half_width_m[l] (widest box of the level) against our true
// max deviation at that level. The boxes hold the original, so the ratio is ≥ 1 wherever the worst
// point lies beside a segment; the nearer to 1, the less the collision tree over-approximates. The
// half-width is only the extent normal to the segment, so an original point that overshoots a sharp
// corner of a coarse polygon along the segment's axis can lie farther than it (ratio < 1; the box still
// contains it). Curves whose deviation is below --tol-mm (straight chains) have no meaningful ratio and
// are counted apart. CurveInfo::max_error_m[l] (the scene's own error: original vertices to the segment
// standing for them) is compared with the Hausdorff distance too.
//
// Checks that stop the program (exit 2): level 0 of ours must be within half a resampling step of the
// original (it is resampling only); a Hausdorff distance smaller than the exact brute-force one-sided
// distance from a sample of vertices, or grid distances that differ from brute force, mean a bug in the
// distance code; linear22 must produce exactly our point counts.
//
// Aggregates per method and level over all curves of all pictures that have that level: mean vertex
// fraction n/n_orig, median and 90th percentile (linear interpolation between order statistics, as
// numpy's default) of max deviation and RMS. Everything per curve is written too. Plot with
// bench/plot_accuracy.py.
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "accuracy_geometry.hpp"
#include "config/settings.hpp"
#include "haptics/multires.hpp"
#include "haptics/scene.hpp"
#include "pictures/image_scene.hpp"
#include "test_paths.hpp"

using namespace hk;
using namespace hk::bench;
namespace fs = std::filesystem;

namespace {

constexpr int kMethods = 4;
const char* const kMethodKey[kMethods] = {"ours", "dp", "uniform", "linear22"};
const char* const kMethodLabel[kMethods] = {"pseudocoiflet (ours)", "Douglas-Peucker", "uniform arc length",
                                            "linear (2,2) wavelet"};

struct Options {
  fs::path images_dir = fs::path(HK_TEST_DATA_DIR) / "images";
  fs::path out = "docs/bench/accuracy.json";
  double rms_step_m = 0.01e-3;  // RMS integration piece: 10 µm, ≤ 1/17 of the finest pixel at workspace scale
  double tol_m = 0.001e-3;      // Hausdorff underestimate bound: 1 µm, far below any reported error
  unsigned threads = 0;         // 0: hardware concurrency
};

[[noreturn]] void die(const std::string& msg) {
  std::fprintf(stderr, "bench_accuracy: %s\n", msg.c_str());
  std::exit(2);
}

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// ---- The other simplifications ----------------------------------------------------------------

// One forward step of the linear interpolating (2,2) wavelet on one coordinate (Sweldens' lifting):
// the scaling half only, since only the coarser polyline is needed.
std::vector<double> linear22_forward(const std::vector<double>& x, bool closed) {
  const std::size_t n = x.size();
  const std::size_t ne = closed ? n / 2 : (n + 1) / 2, no = n / 2;
  std::vector<double> d(no), s(ne);
  for (std::size_t k = 0; k < no; ++k) {
    const double right = (2 * k + 2 < n) ? x[2 * k + 2] : x[0];  // open: 2k+2 ≤ n−1 always; closed wraps
    d[k] = x[2 * k + 1] - 0.5 * (x[2 * k] + right);
  }
  for (std::size_t k = 0; k < ne; ++k) {
    if (!closed && (k == 0 || k == ne - 1)) {  // ends kept so the curve keeps its end points, as ours
      s[k] = x[2 * k];
      continue;
    }
    const double left = closed ? d[(k + no - 1) % no] : d[k - 1];
    s[k] = x[2 * k] + 0.25 * (left + d[k]);
  }
  return s;
}

// Level-l polylines of the (2,2) wavelet from the same level-0 samples as ours.
std::vector<std::vector<Vec2>> linear22_levels(const CurveMultires& m) {
  std::vector<std::vector<Vec2>> out(static_cast<std::size_t>(m.levels));
  out[0] = m.scaling[0];
  std::vector<double> x, y;
  for (int l = 1; l < m.levels; ++l) {
    const auto& fine = out[static_cast<std::size_t>(l - 1)];
    x.resize(fine.size());
    y.resize(fine.size());
    for (std::size_t i = 0; i < fine.size(); ++i) {
      x[i] = fine[i].x;
      y[i] = fine[i].y;
    }
    const auto sx = linear22_forward(x, m.closed), sy = linear22_forward(y, m.closed);
    auto& coarse = out[static_cast<std::size_t>(l)];
    coarse.resize(sx.size());
    for (std::size_t i = 0; i < sx.size(); ++i) coarse[i] = {sx[i], sy[i]};
  }
  return out;
}

// Douglas–Peucker with the vertex count steered to `target` by bisection on epsilon. OpenCV takes
// float or int points, so coordinates go in as float millimetres relative to the first vertex (float
// resolution there is ~10 nm); the kept vertices are mapped back to the exact double originals.
struct DpCurve {
  std::vector<cv::Point2f> pts_mm;
  std::unordered_map<std::uint64_t, std::size_t> index_of;  // float bit pattern → original index
  double diag_mm = 0.0;
};

std::uint64_t key_of(cv::Point2f p) {
  std::uint32_t bx, by;
  std::memcpy(&bx, &p.x, 4);
  std::memcpy(&by, &p.y, 4);
  return (static_cast<std::uint64_t>(bx) << 32) | by;
}

DpCurve dp_prepare(const Polyline& o) {
  DpCurve d;
  const Vec2 base = o.points_m[0];
  float lox = 1e30f, loy = 1e30f, hix = -1e30f, hiy = -1e30f;
  for (std::size_t i = 0; i < o.points_m.size(); ++i) {
    const cv::Point2f q(static_cast<float>(1e3 * (o.points_m[i].x - base.x)),
                        static_cast<float>(1e3 * (o.points_m[i].y - base.y)));
    d.pts_mm.push_back(q);
    d.index_of.emplace(key_of(q), i);
    lox = std::min(lox, q.x);
    loy = std::min(loy, q.y);
    hix = std::max(hix, q.x);
    hiy = std::max(hiy, q.y);
  }
  d.diag_mm = std::hypot(hix - lox, hiy - loy);
  return d;
}

std::vector<Vec2> dp_simplify(const DpCurve& d, const Polyline& o, std::size_t target, double* eps_mm_out) {
  std::vector<cv::Point2f> out, best_out;
  auto run = [&](double eps_mm) {
    cv::approxPolyDP(d.pts_mm, out, eps_mm, o.closed);
    return out.size();
  };
  double best_eps = 0.0;
  long best_gap = -1;
  auto consider = [&](double eps_mm, std::size_t n) {
    const long gap = std::labs(static_cast<long>(n) - static_cast<long>(target));
    // Ties go to the smaller count: DP must not get more vertices than the others.
    if (best_gap < 0 || gap < best_gap || (gap == best_gap && n < best_out.size())) {
      best_gap = gap;
      best_out = out;
      best_eps = eps_mm;
    }
  };
  const std::size_t n_at_zero = run(0.0);
  consider(0.0, n_at_zero);
  // The count falls (nearly monotonically) as epsilon grows; 60 halvings reach float resolution.
  double lo = 0.0, hi = std::max(d.diag_mm, 1e-6);
  for (int it = 0; it < 60 && best_gap != 0 && n_at_zero > target; ++it) {
    const double mid = 0.5 * (lo + hi);
    const std::size_t n = run(mid);
    consider(mid, n);
    if (n > target)
      lo = mid;
    else
      hi = mid;
    if (hi - lo < 1e-9) break;
  }
  if (eps_mm_out) *eps_mm_out = best_eps;
  std::vector<Vec2> pts;
  pts.reserve(best_out.size());
  for (const cv::Point2f& q : best_out) {
    const auto it = d.index_of.find(key_of(q));
    if (it == d.index_of.end()) die("approxPolyDP returned a point that is not an input vertex");
    pts.push_back(o.points_m[it->second]);
  }
  return pts;
}

// ---- Errors -------------------------------------------------------------------------------------

struct Errors {
  std::size_t n = 0;
  double max_dev_m = 0, rms_m = 0, h_orig_to_approx_m = 0, h_approx_to_orig_m = 0;
  double dp_eps_mm = -1;  // DP only
};

// Vertices of a polyline, thinned to at most `cap` evenly spread ones: the brute-force probes.
std::vector<Vec2> probe_vertices(const std::vector<Vec2>& pts, std::size_t cap) {
  std::vector<Vec2> v;
  const std::size_t stride = std::max<std::size_t>(1, (pts.size() + cap - 1) / cap);
  for (std::size_t i = 0; i < pts.size(); i += stride) v.push_back(pts[i]);
  return v;
}

Errors measure(const std::vector<Vec2>& a, bool closed, const Polyline& o, const SegmentGrid& o_grid,
               const Options& opt, const char* what) {
  Errors e;
  e.n = a.size();
  const SegmentGrid a_grid(a, closed);
  double sampled_max_m = 0.0;
  e.rms_m = rms_distance_m(o.points_m, o.closed, a_grid, opt.rms_step_m, &sampled_max_m);
  e.h_orig_to_approx_m = directed_hausdorff_m(o.points_m, o.closed, a_grid, opt.tol_m, sampled_max_m);
  e.h_approx_to_orig_m = directed_hausdorff_m(a, closed, o_grid, opt.tol_m);
  e.max_dev_m = std::max(e.h_orig_to_approx_m, e.h_approx_to_orig_m);

  // Guard against bugs in the distance code: exact one-sided distances from a sample of vertices, by
  // brute force over every segment. The grid must agree with them, and the Hausdorff distance, a max
  // over all points including these, can never be smaller.
  constexpr std::size_t kProbes = 64;
  double one_sided_m = 0.0;
  for (const Vec2& p : probe_vertices(o.points_m, kProbes)) {
    const double ref = brute_distance_m(p, a, closed), got = a_grid.distance_m(p);
    if (std::abs(ref - got) > 1e-12) die(std::string("grid distance differs from brute force (") + what + ")");
    one_sided_m = std::max(one_sided_m, ref);
  }
  for (const Vec2& p : probe_vertices(a, kProbes)) {
    const double ref = brute_distance_m(p, o.points_m, o.closed), got = o_grid.distance_m(p);
    if (std::abs(ref - got) > 1e-12) die(std::string("grid distance differs from brute force (") + what + ")");
    one_sided_m = std::max(one_sided_m, ref);
  }
  if (e.max_dev_m < one_sided_m - 1e-12) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "Hausdorff %.9g mm < brute-force one-sided %.9g mm (%s)", 1e3 * e.max_dev_m,
                  1e3 * one_sided_m, what);
    die(buf);
  }
  return e;
}

// ---- Per curve ----------------------------------------------------------------------------------

struct LevelResult {
  int level = 0;
  double box_half_width_m = 0, scene_max_error_m = 0;
  Errors m[kMethods];
};

struct CurveResult {
  std::string image;
  std::size_t curve = 0, source = 0, n_orig = 0;
  bool closed = false;
  double length_m = 0, level0_step_m = 0;
  std::vector<LevelResult> levels;
};

double polyline_length_m(const Polyline& o) {
  double len = 0.0;
  const std::size_t ns = polyline_segments(o.points_m, o.closed);
  for (std::size_t k = 0; k < ns; ++k) len += distance(o.points_m[k], o.points_m[(k + 1) % o.points_m.size()]);
  return len;
}

CurveResult analyse_curve(const std::string& image, const Scene& scene, std::size_t c, const Polyline& o,
                          const Options& opt, std::atomic<std::int64_t>* method_ns) {
  CurveResult r;
  r.image = image;
  r.curve = c;
  r.source = scene.source_index(c);
  r.n_orig = o.points_m.size();
  r.closed = o.closed;
  r.length_m = polyline_length_m(o);
  const CurveInfo& ci = scene.curve(c);
  const CurveMultires m =
      build_multires(o, ci.levels - 1);  // the scene keeps the scaling coefficients only; the same model
  r.level0_step_m = m.arc_m.size() > 1 ? m.arc_m[1] - m.arc_m[0] : r.length_m;

  const SegmentGrid o_grid(o.points_m, o.closed);
  const DpCurve dp = dp_prepare(o);
  auto timed = [&](int method, auto&& fn) {
    const auto t0 = std::chrono::steady_clock::now();
    auto v = fn();
    method_ns[method] +=
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count();
    return v;
  };
  const auto l22 = timed(3, [&] { return linear22_levels(m); });

  for (int l = 0; l < m.levels; ++l) {
    const auto& ours = m.scaling[static_cast<std::size_t>(l)];
    const std::size_t n_l = ours.size();
    // The scene's flat copy must be the model's polyline: the contact solver uses the former.
    if (ci.point_count[l] != n_l || !(scene.points(c, l)[0] == ours[0]))
      die("Scene::points differs from build_multires");
    if (l22[static_cast<std::size_t>(l)].size() != n_l) die("linear (2,2) wavelet point count differs from ours");
    LevelResult lr;
    lr.level = l;
    lr.box_half_width_m = ci.max_box_half_width_m[l];
    lr.scene_max_error_m = ci.max_error_m[l];
    const std::string tag = image + " curve " + std::to_string(c) + " level " + std::to_string(l);
    lr.m[0] = timed(0, [&] { return measure(ours, m.closed, o, o_grid, opt, (tag + " ours").c_str()); });
    lr.m[1] = timed(1, [&] {
      double eps_mm = 0;
      const auto pts = dp_simplify(dp, o, n_l, &eps_mm);
      Errors e = measure(pts, o.closed, o, o_grid, opt, (tag + " dp").c_str());
      e.dp_eps_mm = eps_mm;
      return e;
    });
    lr.m[2] = timed(
        2, [&] { return measure(resample_arc_length(o, n_l), o.closed, o, o_grid, opt, (tag + " uniform").c_str()); });
    lr.m[3] = timed(3, [&] {
      return measure(l22[static_cast<std::size_t>(l)], m.closed, o, o_grid, opt, (tag + " linear22").c_str());
    });

    if (l == 0) {
      // Level 0 is the original resampled at step h: every original point is within h/2 of a sample
      // along the curve, and every chord point within h/2 of a chord end, so h/2 bounds the deviation.
      const double bound_m = 0.5 * r.level0_step_m + opt.tol_m + 1e-12;
      if (lr.m[0].max_dev_m > bound_m) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "level 0 of ours deviates %.6g mm > half the resampling step %.6g mm (%s)",
                      1e3 * lr.m[0].max_dev_m, 1e3 * bound_m, tag.c_str());
        die(buf);
      }
    }
    r.levels.push_back(lr);
  }
  return r;
}

// ---- Statistics and output ------------------------------------------------------------------------

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const std::size_t i = static_cast<std::size_t>(pos);
  const double f = pos - static_cast<double>(i);
  return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? std::nan("") : s / static_cast<double>(v.size());
}

// Millimetres rounded to 0.1 nm, so the JSON prints short numbers without losing anything measured.
double mm(double m) { return std::round(m * 1e10) / 1e7; }
double r6(double x) { return std::isfinite(x) ? std::round(x * 1e6) / 1e6 : x; }

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) die("missing value after " + a);
      return argv[++i];
    };
    if (a == "--images")
      o.images_dir = next();
    else if (a == "--out")
      o.out = next();
    else if (a == "--rms-step-mm")
      o.rms_step_m = std::stod(next()) * 1e-3;
    else if (a == "--tol-mm")
      o.tol_m = std::stod(next()) * 1e-3;
    else if (a == "--threads")
      o.threads = static_cast<unsigned>(std::stoul(next()));
    else if (a == "-h" || a == "--help") {
      std::printf(
          "usage: bench_accuracy [--images DIR] [--out FILE.json] [--rms-step-mm S] [--tol-mm T] [--threads N]\n");
      std::exit(0);
    } else
      die("unknown argument " + a);
  }
  if (!(o.rms_step_m > 0) || !(o.tol_m > 0)) die("--rms-step-mm and --tol-mm must be > 0");
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  const double t_start = now_s();
  const config::Settings settings{};

  std::vector<fs::path> paths;
  if (!fs::is_directory(opt.images_dir)) die("not a directory: " + opt.images_dir.string());
  for (const auto& e : fs::directory_iterator(opt.images_dir)) {
    const auto ext = e.path().extension().string();
    if (ext == ".png" || ext == ".jpg") paths.push_back(e.path());
  }
  std::sort(paths.begin(), paths.end());
  if (paths.empty()) die("no .png or .jpg in " + opt.images_dir.string());

  std::vector<app::ImageScene> scenes;
  for (const auto& p : paths) scenes.push_back(app::build_image_scene(p.string(), settings));
  const double t_scenes = now_s();

  struct Job {
    std::size_t image, curve;
  };
  std::vector<Job> jobs;
  for (std::size_t i = 0; i < scenes.size(); ++i)
    for (std::size_t c = 0; c < scenes[i].scene->curve_count(); ++c) jobs.push_back({i, c});
  // Longest curves first, so the last thread does not finish alone with a big one.
  std::sort(jobs.begin(), jobs.end(), [&](const Job& a, const Job& b) {
    const auto na = scenes[a.image].scene->curve(a.curve).point_count[0],
               nb = scenes[b.image].scene->curve(b.curve).point_count[0];
    return na != nb ? na > nb : (a.image != b.image ? a.image < b.image : a.curve < b.curve);
  });

  std::vector<CurveResult> results(jobs.size());
  std::atomic<std::size_t> next{0};
  std::atomic<std::int64_t> method_ns[kMethods] = {};
  const unsigned threads = opt.threads ? opt.threads : std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      for (std::size_t j; (j = next++) < jobs.size();) {
        const app::ImageScene& is = scenes[jobs[j].image];
        const std::size_t c = jobs[j].curve;
        results[j] = analyse_curve(fs::path(is.image_path).stem().string(), *is.scene, c,
                                   is.polylines[is.scene->source_index(c)], opt, method_ns);
      }
    });
  }
  for (auto& t : pool) t.join();
  // Back to picture / curve order for the output.
  std::vector<std::size_t> order(jobs.size());
  for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return jobs[a].image != jobs[b].image ? jobs[a].image < jobs[b].image : jobs[a].curve < jobs[b].curve;
  });
  const double t_done = now_s();

  // Aggregates per method and level.
  int max_level = 0;
  for (const auto& r : results) max_level = std::max(max_level, static_cast<int>(r.levels.size()) - 1);
  nlohmann::ordered_json aggregate = nlohmann::ordered_json::array(), boxes = nlohmann::ordered_json::array();
  // Level 0 in pixels too: resampling a pixel staircase cuts its corners, which is a fraction of a pixel.
  std::map<std::string, double> mm_per_px;
  for (const auto& is : scenes) mm_per_px[fs::path(is.image_path).stem().string()] = 1e3 * is.px_to_m.scale_m_per_px;
  double level0_worst_mm = 0.0, level0_worst_px = 0.0;
  for (const auto& r : results) {
    level0_worst_mm = std::max(level0_worst_mm, 1e3 * r.levels[0].m[0].max_dev_m);
    level0_worst_px = std::max(level0_worst_px, 1e3 * r.levels[0].m[0].max_dev_m / mm_per_px[r.image]);
  }

  std::printf("%-22s %5s %6s %9s %12s %12s %12s %12s\n", "method", "level", "curves", "vfrac", "max med mm",
              "max p90 mm", "rms med mm", "rms p90 mm");
  for (int mth = 0; mth < kMethods; ++mth) {
    for (int l = 0; l <= max_level; ++l) {
      std::vector<double> frac, maxd, rms, cnt;
      for (const auto& r : results) {
        if (l >= static_cast<int>(r.levels.size())) continue;
        const Errors& e = r.levels[static_cast<std::size_t>(l)].m[mth];
        frac.push_back(static_cast<double>(e.n) / static_cast<double>(r.n_orig));
        cnt.push_back(static_cast<double>(e.n));
        maxd.push_back(1e3 * e.max_dev_m);
        rms.push_back(1e3 * e.rms_m);
      }
      if (frac.empty()) continue;
      std::size_t same_count = 0;
      for (const auto& r : results)
        if (l < static_cast<int>(r.levels.size())) same_count += r.levels[l].m[mth].n == r.levels[l].m[0].n;
      aggregate.push_back(
          {{"method", kMethodKey[mth]},
           {"curves_with_vertex_count_of_ours", same_count},
           {"level", l},
           {"curves", frac.size()},
           {"mean_vertex_fraction", r6(mean(frac))},
           {"mean_vertex_count", r6(mean(cnt))},
           {"max_dev_mm",
            {{"median", r6(percentile(maxd, 0.5))}, {"p90", r6(percentile(maxd, 0.9))}, {"mean", r6(mean(maxd))}}},
           {"rms_mm",
            {{"median", r6(percentile(rms, 0.5))}, {"p90", r6(percentile(rms, 0.9))}, {"mean", r6(mean(rms))}}}});
      std::printf("%-22s %5d %6zu %9.4f %12.4f %12.4f %12.4f %12.4f\n", kMethodLabel[mth], l, frac.size(), mean(frac),
                  percentile(maxd, 0.5), percentile(maxd, 0.9), percentile(rms, 0.5), percentile(rms, 0.9));
    }
  }
  std::printf("\nbox half-width / true max deviation (ours); scene max_error / true max deviation\n");
  std::printf("%5s %6s %8s %11s %11s %9s %9s %9s %9s %8s %10s %10s\n", "level", "curves", "straight", "box med mm",
              "dev med mm", "ratio min", "ratio med", "ratio p90", "ratio max", "ratio<1", "err/dev lo", "err/dev hi");
  for (int l = 0; l <= max_level; ++l) {
    std::vector<double> half, dev, ratio, scene_err, err_ratio;
    std::size_t below = 0, straight = 0;
    for (const auto& r : results) {
      if (l >= static_cast<int>(r.levels.size())) continue;
      const LevelResult& lr = r.levels[static_cast<std::size_t>(l)];
      half.push_back(1e3 * lr.box_half_width_m);
      dev.push_back(1e3 * lr.m[0].max_dev_m);
      scene_err.push_back(1e3 * lr.scene_max_error_m);
      if (lr.m[0].max_dev_m < opt.tol_m) {  // a straight chain: both numbers are rounding noise
        ++straight;
        continue;
      }
      const double q = lr.box_half_width_m / lr.m[0].max_dev_m;
      ratio.push_back(q);
      err_ratio.push_back(lr.scene_max_error_m / lr.m[0].max_dev_m);
      below += (q < 1.0);
    }
    if (half.empty()) continue;
    auto lo_of = [](const std::vector<double>& v) {
      return v.empty() ? std::nan("") : *std::min_element(v.begin(), v.end());
    };
    auto hi_of = [](const std::vector<double>& v) {
      return v.empty() ? std::nan("") : *std::max_element(v.begin(), v.end());
    };
    boxes.push_back(
        {{"level", l},
         {"curves", half.size()},
         {"straight_curves_excluded", straight},
         {"box_half_width_mm", {{"median", r6(percentile(half, 0.5))}, {"p90", r6(percentile(half, 0.9))}}},
         {"max_dev_mm", {{"median", r6(percentile(dev, 0.5))}, {"p90", r6(percentile(dev, 0.9))}}},
         {"scene_max_error_mm", {{"median", r6(percentile(scene_err, 0.5))}, {"p90", r6(percentile(scene_err, 0.9))}}},
         {"ratio",
          {{"min", r6(lo_of(ratio))},
           {"median", r6(percentile(ratio, 0.5))},
           {"p90", r6(percentile(ratio, 0.9))},
           {"max", r6(hi_of(ratio))}}},
         {"curves_ratio_below_1", below},
         {"scene_error_over_dev",
          {{"min", r6(lo_of(err_ratio))}, {"median", r6(percentile(err_ratio, 0.5))}, {"max", r6(hi_of(err_ratio))}}}});
    std::printf("%5d %6zu %8zu %11.4f %11.4f %9.3f %9.3f %9.3f %9.3f %8zu %10.3f %10.3f\n", l, half.size(), straight,
                percentile(half, 0.5), percentile(dev, 0.5), lo_of(ratio), percentile(ratio, 0.5),
                percentile(ratio, 0.9), hi_of(ratio), below, lo_of(err_ratio), hi_of(err_ratio));
  }

  nlohmann::ordered_json curves = nlohmann::ordered_json::array();
  for (std::size_t j : order) {
    const CurveResult& r = results[j];
    nlohmann::ordered_json lv = nlohmann::ordered_json::array();
    for (const LevelResult& lr : r.levels) {
      nlohmann::ordered_json ms = nlohmann::ordered_json::object();
      for (int mth = 0; mth < kMethods; ++mth) {
        const Errors& e = lr.m[mth];
        nlohmann::ordered_json x = {{"n", e.n},
                                    {"vertex_fraction", r6(static_cast<double>(e.n) / static_cast<double>(r.n_orig))},
                                    {"max_dev_mm", mm(e.max_dev_m)},
                                    {"rms_mm", mm(e.rms_m)},
                                    {"h_orig_to_approx_mm", mm(e.h_orig_to_approx_m)},
                                    {"h_approx_to_orig_mm", mm(e.h_approx_to_orig_m)}};
        if (mth == 1) x["dp_epsilon_mm"] = r6(e.dp_eps_mm);
        ms[kMethodKey[mth]] = x;
      }
      lv.push_back({{"level", lr.level},
                    {"box_half_width_mm", mm(lr.box_half_width_m)},
                    {"scene_max_error_mm", mm(lr.scene_max_error_m)},
                    {"methods", ms}});
    }
    curves.push_back({{"image", r.image},
                      {"curve", r.curve},
                      {"source_index", r.source},
                      {"closed", r.closed},
                      {"n_orig", r.n_orig},
                      {"length_mm", r6(1e3 * r.length_m)},
                      {"level0_step_mm", r6(1e3 * r.level0_step_m)},
                      {"levels", lv}});
  }

  nlohmann::ordered_json images = nlohmann::ordered_json::array();
  for (const auto& is : scenes) {
    images.push_back({{"image", fs::path(is.image_path).filename().string()},
                      {"width_px", is.width_px},
                      {"height_px", is.height_px},
                      {"mm_per_px", r6(1e3 * is.px_to_m.scale_m_per_px)},
                      {"curves", is.scene->curve_count()},
                      {"skipped_curves", is.scene->skipped_curves()}});
  }
  nlohmann::ordered_json methods = nlohmann::ordered_json::array();
  for (int mth = 0; mth < kMethods; ++mth) methods.push_back({{"key", kMethodKey[mth]}, {"label", kMethodLabel[mth]}});

  const double t_end = now_s();
  nlohmann::ordered_json timing = {{"total_s", r6(t_end - t_start)},
                                   {"build_scenes_s", r6(t_scenes - t_start)},
                                   {"analysis_wall_s", r6(t_done - t_scenes)},
                                   {"threads", threads}};
  for (int mth = 0; mth < kMethods; ++mth)
    timing["thread_s_" + std::string(kMethodKey[mth])] = r6(1e-9 * static_cast<double>(method_ns[mth].load()));

  const nlohmann::ordered_json doc = {
      {"what",
       "accuracy against size: each level of the pseudocoiflet model vs Douglas-Peucker, uniform arc-length "
       "resampling and the linear (2,2) wavelet at equal vertex counts; errors against the original pixel chain"},
      {"settings",
       {{"max_levels", settings.haptics.max_levels},
        {"min_chain_length_m", settings.vision.min_chain_length_m},
        {"rms_step_mm", r6(1e3 * opt.rms_step_m)},
        {"hausdorff_tolerance_mm", r6(1e3 * opt.tol_m)},
        {"uniform", "n_l points equally spaced in arc length (hk::resample_arc_length), ends kept on open curves"},
        {"percentile", "linear interpolation between order statistics"}}},
      {"timing", timing},
      {"level0_ours_max_dev_worst", {{"mm", r6(level0_worst_mm)}, {"px", r6(level0_worst_px)}}},
      {"methods", methods},
      {"images", images},
      {"aggregate", aggregate},
      {"box_tightness", boxes},
      {"curves", curves}};

  if (opt.out.has_parent_path()) fs::create_directories(opt.out.parent_path());
  std::ofstream f(opt.out);
  if (!f) die("cannot write " + opt.out.string());
  // One line per top-level key and per array element: small enough to keep in git (~3 MB), and a
  // changed curve shows up as one changed line in a diff.
  f << "{\n";
  bool first_key = true;
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    f << (first_key ? "" : ",\n") << nlohmann::ordered_json(it.key()).dump() << ": ";
    first_key = false;
    if (it->is_array() && !it->empty()) {
      f << "[\n";
      for (std::size_t i = 0; i < it->size(); ++i) f << "  " << (*it)[i].dump() << (i + 1 < it->size() ? ",\n" : "\n");
      f << "]";
    } else {
      f << it->dump();
    }
  }
  f << "\n}\n";
  if (!f) die("write failed: " + opt.out.string());
  std::printf("\n%zu curves from %zu pictures; level 0 of ours within %.4f mm (%.3f px) of the original everywhere\n",
              results.size(), scenes.size(), level0_worst_mm, level0_worst_px);
  std::printf(
      "time: %.1f s total (scenes %.1f s, analysis %.1f s on %u threads; thread-seconds in ours %.1f dp %.1f uniform "
      "%.1f linear22 %.1f) -> %s\n",
      t_end - t_start, t_scenes - t_start, t_done - t_scenes, threads, 1e-9 * method_ns[0].load(),
      1e-9 * method_ns[1].load(), 1e-9 * method_ns[2].load(), 1e-9 * method_ns[3].load(), opt.out.string().c_str());
  return 0;
}
