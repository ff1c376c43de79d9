#pragma once
// Scenes and query streams shared by the benchmarks: real pictures explored by the model hand, and
// synthetic scenes of 10^3 .. 10^6 segments tiled from the curves of real pictures.
#include <algorithm>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "config/settings.hpp"
#include "haptics/hand_path.hpp"
#include "pictures/image_scene.hpp"
#include "runtime/simulation.hpp"
#include "test_paths.hpp"

namespace hk::bench {

/// One swept segment of a query stream: the handle from `a` to `b` in one tick [m].
struct Sweep {
  Vec2 a, b;
};

/// Every .png / .jpg of the test pictures, sorted.
inline std::vector<std::filesystem::path> picture_paths() {
  std::vector<std::filesystem::path> v;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(HK_TEST_DATA_DIR) / "images")) {
    const auto ext = e.path().extension().string();
    if (ext == ".png" || ext == ".jpg") v.push_back(e.path());
  }
  std::sort(v.begin(), v.end());
  return v;
}

/// The handle's sweeps of a default `explore` raster run on `scene` (one per tick).
inline std::vector<Sweep> explore_stream(const Scene& scene, const config::Settings& s) {
  const HandPath path =
      raster_path(s.workspace.width_m, s.workspace.height_m, s.hand.raster_spacing_m, s.hand.raster_speed_m_per_s);
  std::vector<Sweep> out;
  Vec2 prev{};
  bool first = true;
  app::run_simulation(scene, s, path, path.duration_s(), [&](const app::ServoTick& r, const ServoOutput&) {
    if (!first) out.push_back({prev, r.sample.handle_m});
    prev = r.sample.handle_m;
    first = false;
  });
  return out;
}

/// Curves of every picture, in workspace metres (default settings), one vector per picture.
inline std::vector<std::vector<Polyline>> picture_curves(const config::Settings& s) {
  std::vector<std::vector<Polyline>> all;
  for (const auto& p : picture_paths()) all.push_back(app::build_image_scene(p.string(), s).polylines);
  return all;
}

/// A synthetic scene of at least `segments` level-0 segments: whole pictures (their curves at the
/// workspace scale, so the density of real pictures is kept) tiled side by side on a plane that grows
/// with the count. Also returns the plane's size.
inline std::vector<Polyline> tiled_scene(const std::vector<std::vector<Polyline>>& pictures, std::size_t segments,
                                         int max_levels, Vec2* plane_size_m, std::uint32_t seed = 7) {
  std::mt19937 rng(seed);
  std::vector<std::size_t> seg_count(pictures.size(), 0);
  for (std::size_t i = 0; i < pictures.size(); ++i) {
    for (const Polyline& p : pictures[i])
      seg_count[i] += plan_levels(p.points_m.size(), p.closed, max_levels).level0_points - (p.closed ? 0 : 1);
  }
  std::vector<Polyline> out;
  std::size_t total = 0;
  const double tile_w = 0.14, tile_h = 0.09;
  std::vector<Vec2> offsets;
  std::uniform_int_distribution<std::size_t> pick(0, pictures.size() - 1);
  // Tiles in a near-square grid, filled row by row until the count is reached.
  std::size_t tiles = 0;
  std::vector<std::size_t> chosen;
  while (total < segments) {
    const std::size_t i = pick(rng);
    if (seg_count[i] == 0) continue;
    chosen.push_back(i);
    ++tiles;
    total += seg_count[i];
  }
  const std::size_t cols = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(tiles) * tile_h / tile_w)));
  const std::size_t rows = (tiles + cols - 1) / cols;
  total = 0;
  for (std::size_t t = 0; t < chosen.size() && total < segments; ++t) {
    const Vec2 off{(static_cast<double>(t % cols) + 0.5 - cols / 2.0) * tile_w,
                   (static_cast<double>(t / cols) + 0.5 - rows / 2.0) * tile_h};
    for (const Polyline& p : pictures[chosen[t]]) {
      if (total >= segments) break;
      Polyline q = p;
      for (Vec2& v : q.points_m) v += off;
      total += plan_levels(q.points_m.size(), q.closed, max_levels).level0_points - (q.closed ? 0 : 1);
      out.push_back(std::move(q));
    }
  }
  if (plane_size_m) *plane_size_m = {static_cast<double>(cols) * tile_w, static_cast<double>(rows) * tile_h};
  return out;
}

/// A coherent random walk of the handle over a plane: speed wanders between 0.02 and 0.4 m/s, heading
/// turns smoothly, walls of the plane reflect it. One sweep per 1 ms tick.
inline std::vector<Sweep> random_walk_stream(Vec2 plane_size_m, std::size_t count, std::uint32_t seed = 11) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> turn(0.0, 0.08), dv(0.0, 0.01);
  std::uniform_real_distribution<double> ux(-plane_size_m.x / 2, plane_size_m.x / 2),
      uy(-plane_size_m.y / 2, plane_size_m.y / 2);
  Vec2 p{ux(rng), uy(rng)};
  double heading = 0.3, speed = 0.1;
  std::vector<Sweep> out;
  out.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    heading += turn(rng);
    speed = std::clamp(speed + dv(rng), 0.02, 0.4);
    Vec2 q = p + (speed * 0.001) * Vec2{std::cos(heading), std::sin(heading)};
    if (std::abs(q.x) > plane_size_m.x / 2) {
      heading = M_PI - heading;
      q.x = std::clamp(q.x, -plane_size_m.x / 2, plane_size_m.x / 2);
    }
    if (std::abs(q.y) > plane_size_m.y / 2) {
      heading = -heading;
      q.y = std::clamp(q.y, -plane_size_m.y / 2, plane_size_m.y / 2);
    }
    out.push_back({p, q});
    p = q;
  }
  return out;
}

}  // namespace hk::bench
