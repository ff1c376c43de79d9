#include "image_scene.hpp"

#include <algorithm>

namespace hk::app {

std::vector<Polyline> chains_to_polylines(const std::vector<vision::Chain>& chains, const vision::PxToM& map, double min_length_m,
                                          std::size_t* too_short) {
  std::vector<Polyline> out;
  out.reserve(chains.size());
  std::size_t dropped = 0;
  for (const vision::Chain& c : chains) {
    Polyline pl;
    pl.closed = c.closed;
    pl.points_m.reserve(c.points_px.size());
    double length_m = 0.0;
    for (const auto& q : c.points_px) {
      const Vec2 m{map.x_m(q.x), map.y_m(q.y)};
      if (!pl.points_m.empty()) length_m += distance(pl.points_m.back(), m);
      pl.points_m.push_back(m);
    }
    if (pl.closed && pl.points_m.size() > 1) length_m += distance(pl.points_m.back(), pl.points_m.front());
    if (length_m < min_length_m) {
      ++dropped;
      continue;
    }
    out.push_back(std::move(pl));
  }
  if (too_short) *too_short = dropped;
  return out;
}

ImageScene build_image_scene(const std::string& path, const config::Settings& s) {
  ImageScene out;
  out.image_path = path;
  vision::ExtractParams p;
  p.limits.max_file_bytes = s.vision.max_file_bytes;
  p.limits.max_width_px = s.vision.max_width_px;
  p.limits.max_height_px = s.vision.max_height_px;
  p.limits.max_pixels = s.vision.max_pixels;
  p.edges.blur_sigma_px = s.vision.blur_sigma_px;
  p.edges.canny_low = s.vision.canny_low;
  p.edges.canny_high = s.vision.canny_high;
  p.max_image_side_px = s.vision.max_image_side_px;
  // Length is judged in metres below, where the workspace scale is known; keep every real chain here.
  p.min_chain_length_px = 2.0;
  const vision::Extraction ex = vision::extract_chains(path, p);
  out.width_px = ex.width_px;
  out.height_px = ex.height_px;
  out.canny_low = ex.edge_map.low;
  out.canny_high = ex.edge_map.high;
  out.times.load_ms = ex.times.load_ms;
  out.times.edges_ms = ex.times.edges_ms;
  out.times.linking_ms = ex.times.linking_ms;
  out.px_to_m = vision::fit_to_workspace(ex.width_px, ex.height_px, s.workspace.width_m, s.workspace.height_m);
  out.chains_found = ex.chains.size();

  out.polylines = chains_to_polylines(ex.chains, out.px_to_m, s.vision.min_chain_length_m, &out.chains_too_short);
  out.scene = std::make_unique<Scene>(Scene::build(out.polylines, s.haptics.max_levels));
  // Scene budget (issue 6, item 4): keep the servo's data within max_segments level-0 segments, keeping
  // the longest curves (a first measure of salience: long boundaries are the shapes a visitor explores).
  const auto budget = static_cast<std::size_t>(s.vision.max_segments);
  if (out.scene->total_segments(0) > budget) {
    std::vector<std::size_t> order(out.scene->curve_count());
    std::vector<double> len(order.size(), 0.0);
    for (std::size_t c = 0; c < order.size(); ++c) {
      order[c] = c;
      const Polyline& p = out.polylines[out.scene->source_index(c)];
      for (std::size_t i = 1; i < p.points_m.size(); ++i) len[c] += distance(p.points_m[i - 1], p.points_m[i]);
    }
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return len[a] > len[b]; });
    std::vector<Polyline> kept;
    std::size_t used = 0;
    for (std::size_t c : order) {
      const std::size_t n = out.scene->curve(c).segment_count[0];
      if (used + n > budget) continue;  // a shorter one further down may still fit
      used += n;
      kept.push_back(out.polylines[out.scene->source_index(c)]);
    }
    out.chains_over_budget = out.scene->curve_count() - kept.size();
    out.polylines = std::move(kept);
    out.scene = std::make_unique<Scene>(Scene::build(out.polylines, s.haptics.max_levels));
  }
  out.times.multires_ms = out.scene->build_times().multires_ms;
  out.times.tree_ms = out.scene->build_times().tree_ms;
  return out;
}

}  // namespace hk::app
