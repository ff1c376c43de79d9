// extract_chains: the vision stages in the order of DESIGN.md "Data flow", timed per stage so
// the app can report where build time goes (summary.json "build times per stage").

#include "vision/pipeline.hpp"

#include "hk/error.hpp"
#include "vision/mapping.hpp"
#include "vision/texture.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>

#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/edge_drawing.hpp>

namespace hk::vision {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// Edge strength at each chain point (integer processed pixels): the 3x3 Sobel L2 magnitude of
/// the image blurred as detect_edges blurs it (same sigma, same replicated border), so the values
/// are those Canny compared with its thresholds. Only the chain points are differentiated: a few
/// per cent of the pixels, instead of keeping two derivative images.
PointValues chain_strength(const cv::Mat& grey, double blur_sigma_px, const std::vector<Chain>& chains) {
  // Into a buffer of its own: `cv::Mat blurred = grey` would share grey's pixels and blur the caller's image
  // in place.
  cv::Mat blurred;
  if (blur_sigma_px > 0.0) {
    cv::GaussianBlur(grey, blurred, cv::Size(0, 0), blur_sigma_px, blur_sigma_px, cv::BORDER_REPLICATE);
  } else {
    blurred = grey;
  }
  const int w = blurred.cols;
  const int h = blurred.rows;
  PointValues out(chains.size());
  for (std::size_t k = 0; k < chains.size(); ++k) {
    out[k].reserve(chains[k].points_px.size());
    for (const cv::Point2d& p : chains[k].points_px) {
      const int x = static_cast<int>(p.x);
      const int y = static_cast<int>(p.y);
      const int xm = std::max(x - 1, 0);
      const int xp = std::min(x + 1, w - 1);
      const std::uint8_t* r0 = blurred.ptr<std::uint8_t>(std::max(y - 1, 0));
      const std::uint8_t* r1 = blurred.ptr<std::uint8_t>(y);
      const std::uint8_t* r2 = blurred.ptr<std::uint8_t>(std::min(y + 1, h - 1));
      const int gx = (r0[xp] - r0[xm]) + 2 * (r1[xp] - r1[xm]) + (r2[xp] - r2[xm]);
      const int gy = (r2[xm] - r0[xm]) + 2 * (r2[x] - r0[x]) + (r2[xp] - r0[xp]);
      out[k].push_back(std::sqrt(static_cast<double>(gx * gx + gy * gy)));
    }
  }
  return out;
}

}  // namespace

const char* detector_name(Detector d) {
  switch (d) {
    case Detector::Auto:
      return "auto";
    case Detector::Canny:
      return "canny";
    case Detector::Surround:
      return "surround";
    case Detector::Bilateral:
      return "bilateral";
    case Detector::Edpf:
      return "edpf";
    case Detector::Outline:
      return "outline";
  }
  return "auto";
}

Detector detector_from_name(const std::string& name) {
  for (Detector d :
       {Detector::Auto, Detector::Canny, Detector::Surround, Detector::Bilateral, Detector::Edpf, Detector::Outline})
    if (name == detector_name(d)) return d;
  throw hk::ArgumentError("detector '" + name + "' is not one of auto, canny, surround, bilateral, edpf, outline");
}

namespace {

void check_params(const ExtractParams& p) {
  if (p.max_image_side_px < 1) throw hk::ArgumentError("extract_chains: max_image_side_px must be >= 1");
  if (std::isnan(p.min_chain_length_px) || p.min_chain_length_px < 0.0) {
    throw hk::ArgumentError("extract_chains: min_chain_length_px must be >= 0");
  }
  if (!std::isfinite(p.surround_inhibition) || p.surround_inhibition < 0.0)
    throw hk::ArgumentError("extract_chains: surround_inhibition must be finite and >= 0");
  if (!std::isfinite(p.line_drawing_max_ink_m) || p.line_drawing_max_ink_m < 0.0)
    throw hk::ArgumentError("extract_chains: line_drawing_max_ink_m must be finite and >= 0");
  if (!(p.workspace_width_m > 0.0) || !(p.workspace_height_m > 0.0) || !std::isfinite(p.workspace_width_m) ||
      !std::isfinite(p.workspace_height_m))
    throw hk::ArgumentError("extract_chains: the workspace must be finite and > 0");
}

/// The ignore mask at the processed size: area-averaged, so any coverage of a processed pixel counts (nonzero).
cv::Mat processed_mask(const cv::Mat& ignore_mask, cv::Size size) {
  if (ignore_mask.empty() || ignore_mask.size() == size) return ignore_mask;
  cv::Mat small;
  cv::resize(ignore_mask, small, size, 0, 0, cv::INTER_AREA);
  return small;
}

/// Canny, Surround or Bilateral: (bilateral filter,) edges, ignored regions cleared, linking. Surround's
/// texture test comes after the strengths (drop_texture).
void canny_chains(const cv::Mat& grey, Detector detector, const ExtractParams& p, const cv::Mat& ignore_mask,
                  Extraction& out) {
  auto t0 = std::chrono::steady_clock::now();
  if (detector == Detector::Bilateral) {
    cv::Mat smooth;
    cv::bilateralFilter(grey, smooth, kBilateralDiameterPx, kBilateralSigmaGrey, kBilateralSigmaSpacePx,
                        cv::BORDER_REPLICATE);
    out.edge_map = detect_edges(smooth, p.edges);
  } else {
    out.edge_map = detect_edges(grey, p.edges);
  }
  if (!ignore_mask.empty()) out.edge_map.edges.setTo(0, processed_mask(ignore_mask, grey.size()) > 0);
  out.times.edges_ms = ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  out.chains = link_edges(out.edge_map.edges, p.min_chain_length_px);
  out.detector_used = detector;
  out.times.linking_ms = ms_since(t0);
}

/// Edpf: Edge Drawing in its parameter-free mode (Akinlar & Topal, "EDPF: a parameter-free edge segment
/// detector with a false detection control", IJPRAI 26(1), 2012; cv::ximgproc::EdgeDrawing with PFmode):
/// anchors on the gradient routed into segments, each kept only when its number of false alarms is below 1.
/// It detects and links in one pass; each segment is a chain, closed when its ends are 8-neighbours (and it
/// has at least 8 points). Segments under the ignore mask are cut there. edge_map: the segments' pixels, with
/// low = 0 and high = the high threshold detect_edges would choose, so that strengths compare alike.
void edpf_chains(const cv::Mat& grey, const ExtractParams& p, const cv::Mat& ignore_mask, Extraction& out) {
  auto t0 = std::chrono::steady_clock::now();
  cv::Ptr<cv::ximgproc::EdgeDrawing> ed = cv::ximgproc::createEdgeDrawing();
  ed->params.PFmode = true;
  ed->params.Sigma = static_cast<float>(std::max(p.edges.blur_sigma_px, 0.1));
  ed->detectEdges(grey);
  ed->getEdgeImage(out.edge_map.edges);
  const std::vector<std::vector<cv::Point>> segments = ed->getSegments();
  const cv::Mat small = processed_mask(ignore_mask, grey.size());
  out.edge_map.low = 0.0;
  out.edge_map.high = detect_edges(grey, p.edges).high;
  if (!small.empty()) out.edge_map.edges.setTo(0, small > 0);
  out.times.edges_ms = ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  out.chains.clear();
  const auto keep = [&](Chain&& c) {
    if (!c.points_px.empty() && chain_length_px(c) >= p.min_chain_length_px) out.chains.push_back(std::move(c));
  };
  for (const std::vector<cv::Point>& seg : segments) {
    Chain piece;
    bool cut = false;
    for (const cv::Point& q : seg) {
      if (!small.empty() && small.at<std::uint8_t>(q.y, q.x) != 0) {
        cut = true;
        keep(std::move(piece));
        piece = Chain{};
        continue;
      }
      if (piece.points_px.empty() || piece.points_px.back() != cv::Point2d(q)) piece.points_px.emplace_back(q);
    }
    const std::size_t n = piece.points_px.size();
    piece.closed = !cut && n >= 8 && std::abs(piece.points_px.front().x - piece.points_px.back().x) <= 1.0 &&
                   std::abs(piece.points_px.front().y - piece.points_px.back().y) <= 1.0;
    keep(std::move(piece));
  }
  out.detector_used = Detector::Edpf;
  out.times.linking_ms = ms_since(t0);
}

/// Surround's texture test (texture.hpp, stands_out): chains that do not stand out from their surround are
/// dropped with their strengths; their pixels are cleared from the edge map.
void drop_texture(const cv::Mat& grey, const ExtractParams& p, Extraction& out) {
  const PointValues surround = chain_surround(grey, p.edges.blur_sigma_px, out.chains);
  std::vector<Chain> kept;
  PointValues kept_strength;
  for (std::size_t k = 0; k < out.chains.size(); ++k) {
    if (stands_out(out.point_strength[k], surround[k], p.surround_inhibition, out.edge_map.low)) {
      kept.push_back(std::move(out.chains[k]));
      kept_strength.push_back(std::move(out.point_strength[k]));
    } else {
      ++out.texture_chains;
      for (const cv::Point2d& q : out.chains[k].points_px)
        out.edge_map.edges.at<std::uint8_t>(static_cast<int>(q.y), static_cast<int>(q.x)) = 0;
    }
  }
  out.chains = std::move(kept);
  out.point_strength = std::move(kept_strength);
}

/// Outline: the two tones' boundaries, closed where they do not meet the frame (nothing to link). Chains under
/// the ignore mask are cut there, as Canny's edges are cleared.
void outline_chains(const cv::Mat& grey, const ExtractParams& p, const cv::Mat& ignore_mask, Extraction& out) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Chain> chains = trace_outlines(grey, out.tones.threshold);
  if (!ignore_mask.empty()) {
    const cv::Mat small = processed_mask(ignore_mask, grey.size());
    std::vector<Chain> kept;
    for (Chain& c : chains) {
      Chain piece;
      bool cut = false;
      for (const cv::Point2d& q : c.points_px) {
        if (small.at<std::uint8_t>(static_cast<int>(q.y), static_cast<int>(q.x)) != 0) {
          cut = true;
          if (!piece.points_px.empty()) kept.push_back(std::move(piece));
          piece = Chain{};
        } else {
          piece.points_px.push_back(q);
        }
      }
      piece.closed = c.closed && !cut;
      if (!piece.points_px.empty()) kept.push_back(std::move(piece));
    }
    chains = std::move(kept);
  }
  out.chains.clear();
  for (Chain& c : chains)
    if (chain_length_px(c) >= p.min_chain_length_px) out.chains.push_back(std::move(c));  // as link_edges measures
  // The strength a blurred step between the tones gives (detect_edges' units: 8·D/(σ·√(2π)), the unblurred
  // 3x3 Sobel of a step: 4·D), halved: as sure as Canny's high threshold.
  const double step = out.tones.light_mean - out.tones.dark_mean;
  const double sigma = p.edges.blur_sigma_px;
  const double magnitude = sigma > 0.0 ? 8.0 * step / (sigma * std::sqrt(2.0 * std::numbers::pi)) : 4.0 * step;
  // The boundary pixels kept, as an edge image like Canny's (for views and the processed size).
  cv::Mat edges = cv::Mat::zeros(grey.size(), CV_8U);
  for (const Chain& c : out.chains)
    for (const cv::Point2d& q : c.points_px) edges.at<std::uint8_t>(static_cast<int>(q.y), static_cast<int>(q.x)) = 255;
  out.edge_map = EdgeMap{edges, 0.0, 0.5 * std::min(magnitude, 4.0 * step)};
  out.detector_used = Detector::Outline;
  out.times.edges_ms = 0.0;
  out.times.linking_ms = ms_since(t0);
}

/// The stages after the grey image is ready: boundaries (Canny or outline), strength, scale back to the
/// `full` size.
void extract_from_grey(const cv::Mat& grey, cv::Size full, const ExtractParams& p, const cv::Mat& ignore_mask,
                       Extraction& out) {
  if (p.detector == Detector::Auto || p.detector == Detector::Outline) out.tones = classify_two_tone(grey);
  if (out.tones.two_tone && p.line_drawing_max_ink_m > 0.0) {
    const double m_per_px =
        fit_to_workspace(full.width, full.height, p.workspace_width_m, p.workspace_height_m).scale_m_per_px;
    const double px_scale = static_cast<double>(full.width) / grey.cols;
    out.line_drawing = out.tones.ink_width_px * px_scale * m_per_px <= p.line_drawing_max_ink_m;
  }
  if (p.detector == Detector::Outline || (p.detector == Detector::Auto && out.tones.two_tone && !out.line_drawing)) {
    outline_chains(grey, p, ignore_mask, out);
  } else if (p.detector == Detector::Edpf) {
    edpf_chains(grey, p, ignore_mask, out);
  } else if (p.detector == Detector::Auto) {
    // A line drawing has two tones and no texture; surround inhibition would only weaken its strokes' edges.
    canny_chains(grey, out.line_drawing ? Detector::Canny : kAutoEdgeDetector, p, ignore_mask, out);
  } else {
    canny_chains(grey, p.detector, p, ignore_mask, out);
  }
  const auto t0 = std::chrono::steady_clock::now();
  out.point_strength = chain_strength(grey, p.edges.blur_sigma_px, out.chains);
  if (out.detector_used == Detector::Surround) drop_texture(grey, p, out);
  if (grey.size() != full) {
    // Pixel-centre correspondence of area resampling: processed pixel i covers original
    // [i * s, (i + 1) * s), whose centre is (i + 0.5) * s - 0.5.
    const double sx = static_cast<double>(full.width) / grey.cols;
    const double sy = static_cast<double>(full.height) / grey.rows;
    for (Chain& c : out.chains) {
      for (cv::Point2d& q : c.points_px) q = {(q.x + 0.5) * sx - 0.5, (q.y + 0.5) * sy - 0.5};
    }
  }
  out.times.linking_ms += ms_since(t0);
}

}  // namespace

Extraction extract_chains(const std::string& path, const ExtractParams& p) {
  check_params(p);
  Extraction out{};
  const auto t0 = std::chrono::steady_clock::now();
  const cv::Mat bgr = load_image(path, p.limits);
  const cv::Mat grey = to_grey(bgr, p.max_image_side_px, &out.px_scale);
  out.width_px = bgr.cols;
  out.height_px = bgr.rows;
  out.times.load_ms = ms_since(t0);
  extract_from_grey(grey, bgr.size(), p, cv::Mat(), out);
  return out;
}

Extraction extract_chains_from_image(const cv::Mat& image, const ExtractParams& p, const cv::Mat& ignore_mask) {
  check_params(p);
  if (image.empty()) throw hk::ArgumentError("extract_chains_from_image: the image is empty");
  if (!ignore_mask.empty() && (ignore_mask.type() != CV_8UC1 || ignore_mask.size() != image.size())) {
    throw hk::ArgumentError("extract_chains_from_image: ignore_mask must be CV_8UC1 of the image's size");
  }
  Extraction out{};
  const auto t0 = std::chrono::steady_clock::now();
  const cv::Mat grey = to_grey(image, p.max_image_side_px, &out.px_scale);  // checks the type
  out.width_px = image.cols;
  out.height_px = image.rows;
  out.times.load_ms = ms_since(t0);
  extract_from_grey(grey, image.size(), p, ignore_mask, out);
  return out;
}

}  // namespace hk::vision
