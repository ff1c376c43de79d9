// extract_chains: the vision stages in the order of DESIGN.md "Data flow", timed per stage so
// the app can report where build time goes (summary.json "build times per stage").

#include "vision/pipeline.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace hk::vision {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

Extraction extract_chains(const std::string& path, const ExtractParams& p) {
  if (p.max_image_side_px < 1) throw std::invalid_argument("extract_chains: max_image_side_px must be >= 1");
  if (std::isnan(p.min_chain_length_px) || p.min_chain_length_px < 0.0) {
    throw std::invalid_argument("extract_chains: min_chain_length_px must be >= 0");
  }
  Extraction out{};

  auto t0 = std::chrono::steady_clock::now();
  const cv::Mat bgr = load_image(path, p.limits);
  const cv::Mat grey = to_grey(bgr, p.max_image_side_px, &out.px_scale);
  out.width_px = bgr.cols;
  out.height_px = bgr.rows;
  out.times.load_ms = ms_since(t0);

  t0 = std::chrono::steady_clock::now();
  out.edge_map = detect_edges(grey, p.edges);
  out.times.edges_ms = ms_since(t0);

  t0 = std::chrono::steady_clock::now();
  out.chains = link_edges(out.edge_map.edges, p.min_chain_length_px);
  if (grey.size() != bgr.size()) {
    // Pixel-centre correspondence of area resampling: processed pixel i covers original
    // [i * s, (i + 1) * s), whose centre is (i + 0.5) * s - 0.5.
    const double sx = static_cast<double>(bgr.cols) / grey.cols;
    const double sy = static_cast<double>(bgr.rows) / grey.rows;
    for (Chain& c : out.chains) {
      for (cv::Point2d& q : c.points_px) q = {(q.x + 0.5) * sx - 0.5, (q.y + 0.5) * sy - 0.5};
    }
  }
  out.times.linking_ms = ms_since(t0);
  return out;
}

}  // namespace hk::vision
