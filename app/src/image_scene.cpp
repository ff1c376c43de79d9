#include "image_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include <opencv2/imgproc.hpp>

#include "vision/gaps.hpp"
#include "vision/thin_lines.hpp"

namespace hk::app {

double curve_salience(double length_m, double strength, double canny_high) {
  if (!std::isfinite(length_m) || !std::isfinite(strength) || !std::isfinite(canny_high) || canny_high <= 0.0) return 0.0;
  return length_m * std::clamp(strength / canny_high, 0.0, 1.0);
}

double polyline_length_m(const Polyline& p) {
  double l = 0.0;
  for (std::size_t i = 1; i < p.points_m.size(); ++i) l += distance(p.points_m[i - 1], p.points_m[i]);
  if (p.closed && p.points_m.size() > 1) l += distance(p.points_m.back(), p.points_m.front());
  return l;
}

double shape_salience(const ShapeFeatures& f, double canny_high) {
  if (!std::isfinite(f.area_m2) || f.area_m2 < 0.0) return 0.0;
  if (!std::isfinite(f.length_m) || !std::isfinite(f.strength) || !std::isfinite(canny_high) || canny_high <= 0.0) return 0.0;
  const double outline_m = f.length_m + (f.closed ? 2.0 * std::sqrt(f.area_m2) : 0.0);
  return outline_m * std::max(0.0, f.strength) / canny_high;
}

double enclosed_area_m2(const Polyline& p) {
  const std::size_t n = p.points_m.size();
  double twice = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = p.points_m[i], b = p.points_m[(i + 1) % n];
    twice += a.x * b.y - b.x * a.y;
  }
  return 0.5 * std::abs(twice);
}

double border_share(const Polyline& p, const vision::PxToM& map, int width_px, int height_px, double band_m) {
  if (p.points_m.empty()) return 0.0;
  const double band_px = band_m / map.scale_m_per_px;
  std::size_t near = 0;
  for (const Vec2& q : p.points_m) {
    const double u = map.u_px(q.x), v = map.v_px(q.y);
    // The frame is the outer edge of the outer pixels: u = -0.5 and u = width - 0.5.
    const double to_frame = std::min({u + 0.5, width_px - 0.5 - u, v + 0.5, height_px - 0.5 - v});
    near += to_frame <= band_px;
  }
  return static_cast<double>(near) / static_cast<double>(p.points_m.size());
}

std::vector<Polyline> chains_to_polylines(const std::vector<vision::Chain>& chains, const vision::PxToM& map, double min_length_m,
                                          std::size_t* too_short, std::vector<std::size_t>* kept) {
  std::vector<Polyline> out;
  out.reserve(chains.size());
  if (kept) kept->clear();
  std::size_t dropped = 0;
  for (std::size_t k = 0; k < chains.size(); ++k) {
    const vision::Chain& c = chains[k];
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
    if (kept) kept->push_back(k);
  }
  if (too_short) *too_short = dropped;
  return out;
}

namespace {

double mean(const std::vector<double>& v) {
  return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

}  // namespace

namespace {

vision::ExtractParams extract_params(const config::Settings& s) {
  vision::ExtractParams p;
  p.limits.max_file_bytes = s.vision.max_file_bytes;
  p.limits.max_width_px = s.vision.max_width_px;
  p.limits.max_height_px = s.vision.max_height_px;
  p.limits.max_pixels = s.vision.max_pixels;
  p.edges.blur_sigma_px = s.vision.blur_sigma_px;
  p.edges.canny_low = s.vision.canny_low;
  p.edges.canny_high = s.vision.canny_high;
  p.max_image_side_px = s.vision.max_image_side_px;
  p.detector = vision::detector_from_name(s.vision.detector);
  p.line_drawing_max_ink_m = s.vision.thin_line_max_width_m;
  p.workspace_width_m = s.workspace.width_m;
  p.workspace_height_m = s.workspace.height_m;
  // Length is judged in metres below, where the workspace scale is known; keep every real chain here.
  p.min_chain_length_px = 2.0;
  return p;
}

/// The budgets (issue 6, item 4; issue 15, item 2): curves along the picture's frame are dropped; the rest
/// are taken in decreasing shape_salience (ties: pipeline order) and each is kept while fewer than
/// vision.max_shapes are kept and its level-0 segments still fit vision.max_segments (a less salient one
/// further down may still fit). The scene is rebuilt from the kept curves, in pipeline order, so the curve
/// ids follow the picture, not the ranking.
void apply_budgets(ImageScene& out, const config::Settings& s) {
  const std::size_t n_curves = out.scene->curve_count();
  std::vector<std::size_t> order;
  std::vector<double> salience(n_curves, 0.0);
  for (std::size_t c = 0; c < n_curves; ++c) {
    const std::size_t i = out.scene->source_index(c);
    const Polyline& p = out.polylines[i];
    if (border_share(p, out.px_to_m, out.width_px, out.height_px, kBorderBandM) >= kBorderShare) {
      ++out.chains_along_border;
      continue;
    }
    order.push_back(c);
    salience[c] = shape_salience({polyline_length_m(p), out.strength[i], p.closed, p.closed ? enclosed_area_m2(p) : 0.0}, out.canny_high);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return salience[a] > salience[b]; });
  const auto max_segments = static_cast<std::size_t>(s.vision.max_segments);
  const auto max_shapes = static_cast<std::size_t>(s.vision.max_shapes);
  std::vector<char> keep(n_curves, 0);
  std::size_t used = 0, kept_count = 0;
  for (const std::size_t c : order) {
    const std::size_t n = out.scene->curve(c).segment_count[0];
    if (kept_count == max_shapes) {
      ++out.chains_over_max_shapes;
      continue;
    }
    if (used + n > max_segments) {
      ++out.chains_over_budget;
      continue;
    }
    used += n;
    ++kept_count;
    keep[c] = 1;
  }
  if (kept_count == n_curves) return;
  std::vector<Polyline> kept;
  std::vector<double> kept_strength;
  for (std::size_t c = 0; c < n_curves; ++c) {
    if (!keep[c]) continue;
    kept.push_back(out.polylines[out.scene->source_index(c)]);
    kept_strength.push_back(out.strength[out.scene->source_index(c)]);
  }
  out.polylines = std::move(kept);
  out.strength = std::move(kept_strength);
  out.scene = std::make_unique<Scene>(Scene::build(out.polylines, s.haptics.max_levels));
}

/// Steps 2-5 of build_image_scene on an extraction: thin lines, metres, budget, trees.
void build_from_extraction(ImageScene& out, vision::Extraction ex, const config::Settings& s) {
  out.width_px = ex.width_px;
  out.height_px = ex.height_px;
  out.canny_low = ex.edge_map.low;
  out.canny_high = ex.edge_map.high;
  out.detector = ex.detector_used;
  out.tones = ex.tones;
  out.times.load_ms = ex.times.load_ms;
  out.times.edges_ms = ex.times.edges_ms;
  out.times.linking_ms = ex.times.linking_ms;
  out.px_to_m = vision::fit_to_workspace(ex.width_px, ex.height_px, s.workspace.width_m, s.workspace.height_m);
  out.chains_found = ex.chains.size();

  // Thin lines (issue 6, item 4): the two edges of a stroke thinner than a fingertip can resolve become
  // its centre line. Merged at the resolution the edges were found at (extract_chains returns original
  // pixels; the inverse of its scale-back is exact), where the chains are 8-connected pixel walks.
  // Traced outlines (a two-tone picture but a line drawing, which goes to Canny) stay as they are: a
  // silhouette keeps one closed curve per outline, exact to the pixel, its narrow parts included.
  std::vector<vision::Chain> chains = std::move(ex.chains);
  vision::PointValues point_strength = std::move(ex.point_strength);
  out.line_drawing = ex.line_drawing;
  if (s.vision.thin_line_max_width_m > 0.0 && ex.detector_used == vision::Detector::Canny) {
    const auto t0 = std::chrono::steady_clock::now();
    const double sx = static_cast<double>(ex.width_px) / ex.edge_map.edges.cols;
    const double sy = static_cast<double>(ex.height_px) / ex.edge_map.edges.rows;
    for (vision::Chain& c : chains) {
      for (cv::Point2d& q : c.points_px) q = {(q.x + 0.5) / sx - 0.5, (q.y + 0.5) / sy - 0.5};
    }
    // Metres → original px → processed px (sx and sy differ from each other only by rounding).
    const double width_px = s.vision.thin_line_max_width_m / out.px_to_m.scale_m_per_px / (0.5 * (sx + sy));
    vision::ThinLineStats st;
    vision::PointValues merged_strength;
    chains = vision::merge_thin_lines(chains, width_px, &st, point_strength, &merged_strength);
    point_strength = std::move(merged_strength);
    out.thin_line_pairs_merged = st.pairs_merged;
    for (vision::Chain& c : chains) {
      for (cv::Point2d& q : c.points_px) q = {(q.x + 0.5) * sx - 0.5, (q.y + 0.5) * sy - 0.5};
    }
    out.times.thin_lines_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  out.chains_after_thin_lines = chains.size();

  // Gaps (issue 15, item 3): chain ends facing each other across at most gap_close_m are joined, so outlines
  // Canny broke at a highlight or a notch are felt closed. Not for traced outlines: closed by construction,
  // their open ends are where a shape runs into the frame.
  if (s.vision.gap_close_m > 0.0 && ex.detector_used == vision::Detector::Canny) {
    const auto t0 = std::chrono::steady_clock::now();
    vision::GapParams gp;
    // The gap is the space between the two end pixels: their centres' distance less one pixel (of the
    // resolution the chains were found at, px_scale original px); in original px, as the chains are.
    gp.max_gap_px = s.vision.gap_close_m / out.px_to_m.scale_m_per_px + ex.px_scale;
    gp.direction_span_px = std::max(gp.direction_span_px, 2.0 * gp.max_gap_px);
    // Outlines are completed, crumbs are not assembled: each piece joined is at least half as long as a
    // curve worth keeping (min_chain_length_m).
    gp.min_piece_px = 0.5 * s.vision.min_chain_length_m / out.px_to_m.scale_m_per_px;
    vision::GapStats gs;
    vision::PointValues joined_strength;
    chains = vision::close_gaps(chains, gp, &gs, point_strength, &joined_strength);
    point_strength = std::move(joined_strength);
    out.gaps_closed = gs.joins;
    out.chains_closed_by_gaps = gs.chains_closed;
    out.times.gaps_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  out.chains_after_gaps = chains.size();

  std::vector<std::size_t> kept_chain;
  out.polylines = chains_to_polylines(chains, out.px_to_m, s.vision.min_chain_length_m, &out.chains_too_short, &kept_chain);
  out.strength.reserve(kept_chain.size());
  for (const std::size_t k : kept_chain) out.strength.push_back(mean(point_strength[k]));
  out.scene = std::make_unique<Scene>(Scene::build(out.polylines, s.haptics.max_levels));
  out.segments_before_budget = out.scene->total_segments(0);
  apply_budgets(out, s);
  out.segments_after_budget = out.scene->total_segments(0);
  out.times.multires_ms = out.scene->build_times().multires_ms;
  out.times.tree_ms = out.scene->build_times().tree_ms;
}

}  // namespace

ImageScene build_image_scene(const std::string& path, const config::Settings& s) {
  ImageScene out;
  out.image_path = path;
  build_from_extraction(out, vision::extract_chains(path, extract_params(s)), s);
  return out;
}

ImageScene build_image_scene_from_bytes(const std::vector<std::uint8_t>& bytes, const std::string& name, const config::Settings& s) {
  ImageScene out;
  out.image_path = name;
  const vision::ExtractParams p = extract_params(s);
  const auto t0 = std::chrono::steady_clock::now();
  out.picture = vision::decode_image(bytes, name, p.limits);
  const double decode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  build_from_extraction(out, vision::extract_chains_from_image(out.picture, p), s);
  out.times.load_ms += decode_ms;
  return out;
}

std::vector<Aabb> text_block_regions(const std::vector<TextBlockM>& blocks) {
  std::vector<Aabb> out;
  out.reserve(blocks.size());
  const Vec2 grow{kTextBlockReachM, kTextBlockReachM};
  for (const TextBlockM& b : blocks) out.push_back({b.lo_m - grow, b.hi_m + grow});
  return out;
}

const TextBlockM* text_block_at(const std::vector<TextBlockM>& blocks, Vec2 p) {
  const TextBlockM* best = nullptr;
  double best_d = 3.0 * kTextBlockReachM;
  for (const TextBlockM& b : blocks) {
    const double d = b.distance_m(p);
    if (d <= best_d) {
      best_d = d;
      best = &b;
      if (d == 0.0) break;
    }
  }
  return best;
}

cv::Mat text_mask(cv::Size size, const std::vector<vision::PdfWord>& words, double grow) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
  const cv::Rect2d frame(0, 0, size.width, size.height);
  for (const vision::PdfWord& w : words) {
    const double g = grow * w.box_px.height;
    const cv::Rect2d r = cv::Rect2d(w.box_px.x - g, w.box_px.y - g, w.box_px.width + 2 * g, w.box_px.height + 2 * g) & frame;
    if (r.width <= 0 || r.height <= 0) continue;
    const cv::Point p0(static_cast<int>(std::floor(r.x)), static_cast<int>(std::floor(r.y)));
    const cv::Point p1(static_cast<int>(std::ceil(r.x + r.width)) - 1, static_cast<int>(std::ceil(r.y + r.height)) - 1);
    cv::rectangle(mask, p0, p1, cv::Scalar(255), cv::FILLED);
  }
  return mask;
}

ImageScene build_page_scene(const vision::PdfPage& page, const std::string& name, int page_number, const config::Settings& s) {
  ImageScene out;
  out.image_path = name;
  out.page = page_number;
  out.pages = page.pages;
  cv::cvtColor(page.grey, out.picture, cv::COLOR_GRAY2BGR);
  out.text_words_masked = page.words.size();
  const cv::Mat mask = page.words.empty() ? cv::Mat() : text_mask(page.grey.size(), page.words);
  build_from_extraction(out, vision::extract_chains_from_image(page.grey, extract_params(s), mask), s);
  // Word boxes have their origin at the top-left pixel's corner; PxToM maps pixel centres.
  for (const vision::TextBlock& b : page.blocks) {
    TextBlockM t;
    t.id = static_cast<int>(out.text_blocks.size());
    t.lo_m = {out.px_to_m.x_m(b.box_px.x - 0.5), out.px_to_m.y_m(b.box_px.y + b.box_px.height - 0.5)};
    t.hi_m = {out.px_to_m.x_m(b.box_px.x + b.box_px.width - 0.5), out.px_to_m.y_m(b.box_px.y - 0.5)};
    t.text = b.text;
    out.text_blocks.push_back(std::move(t));
  }
  return out;
}

}  // namespace hk::app
