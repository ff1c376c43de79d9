#include "pictures/image_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>

#include <spdlog/spdlog.h>
#include <opencv2/imgproc.hpp>

#include "haptics/multires.hpp"
#include "hk/error.hpp"
#include "meaning/faces.hpp"
#include "pictures/picture_params.hpp"
#include "vision/intake.hpp"

namespace hk::app {

double polyline_length_m(const Polyline& p) {
  double l = 0.0;
  for (std::size_t i = 1; i < p.points_m.size(); ++i) l += distance(p.points_m[i - 1], p.points_m[i]);
  if (p.closed && p.points_m.size() > 1) l += distance(p.points_m.back(), p.points_m.front());
  return l;
}

std::size_t approx_scene_bytes(const ImageScene& is) {
  std::size_t b = is.picture.total() * is.picture.elemSize();
  for (const Polyline& p : is.polylines) b += p.points_m.size() * sizeof(Vec2);
  if (is.scene) b += is.scene->total_segments(0) * 150;
  return b + sizeof(ImageScene);
}

void describe_scene_shapes(ImageScene& is) {
  const auto start = std::chrono::steady_clock::now();
  const meaning::PictureColours colours{is.picture, is.px_to_m, is.line_drawing};
  is.descriptors = is.scene ? meaning::describe_shapes(is.polylines, *is.scene, colours)
                            : meaning::describe_shapes(is.polylines, colours);
  const auto described = std::chrono::steady_clock::now();
  is.times.descriptors_ms = std::chrono::duration<double, std::milli>(described - start).count();
  is.faces_m.clear();
  // A document page holds text and figures, a two-tone picture (a silhouette, a line drawing) outlines: no faces
  // to see, and the cascades' search is the dearest part of a build.
  if (is.pages > 0 || is.picture.empty() || is.tones.two_tone || is.line_drawing) return;
  for (const cv::Rect& f : meaning::find_faces(is.picture)) {
    const Vec2 a{is.px_to_m.x_m(f.x), is.px_to_m.y_m(f.y)};
    const Vec2 b{is.px_to_m.x_m(f.x + f.width), is.px_to_m.y_m(f.y + f.height)};
    is.faces_m.push_back({{std::min(a.x, b.x), std::min(a.y, b.y)}, {std::max(a.x, b.x), std::max(a.y, b.y)}});
  }
  is.times.faces_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - described).count();
}

void fit_picture(ImageScene& is, int max_side_px) {
  if (max_side_px < 1) throw hk::ArgumentError("fit_picture: max_side_px must be >= 1");
  const int side = std::max(is.picture.cols, is.picture.rows);
  if (is.picture.empty() || side <= max_side_px) return;
  const double f = static_cast<double>(max_side_px) / side;  // new pixels per old pixel
  cv::Mat small;
  cv::resize(is.picture, small, cv::Size(), f, f, cv::INTER_AREA);
  // Old pixel u sits at new pixel u' = (u + 0.5) f − 0.5 (centres), so u = (u' + 0.5) / f − 0.5.
  const vision::PxToM& m = is.px_to_m;
  const double back = 0.5 / f - 0.5;
  is.px_to_m = {m.scale_m_per_px / f, m.x_m(back), m.y_m(back)};
  is.picture = small;
}

std::vector<Polyline> to_polylines(const std::vector<vision::SceneCurve>& curves) {
  std::vector<Polyline> out;
  out.reserve(curves.size());
  for (const vision::SceneCurve& c : curves) {
    Polyline pl;
    pl.closed = c.closed;
    pl.points_m.reserve(c.points_m.size());
    for (const cv::Point2d& q : c.points_m) pl.points_m.push_back({q.x, q.y});
    out.push_back(std::move(pl));
  }
  return out;
}

namespace {

/// The level-0 segments Scene::build will give a curve: plan_levels' sample count (closed: points; open:
/// points − 1).
vision::SegmentCost segment_cost(const config::Settings& s) {
  const int max_levels = s.haptics.max_levels;
  return [max_levels](const vision::SceneCurve& c) -> std::size_t {
    const std::size_t n = plan_levels(c.points_m.size(), c.closed, max_levels).level0_points;
    return c.closed ? n : (n > 0 ? n - 1 : 0);
  };
}

/// The scene of vision's curves: the report copied, the trees built (haptics.max_levels).
void build_from_chains(ImageScene& out, vision::SceneChains sc, const config::Settings& s) {
  const vision::Extraction& ex = sc.extraction;
  out.width_px = ex.width_px;
  out.height_px = ex.height_px;
  out.canny_low = ex.edge_map.low;
  out.canny_high = ex.edge_map.high;
  out.detector = ex.detector_used;
  out.tones = ex.tones;
  out.line_drawing = ex.line_drawing;
  out.times.load_ms = ex.times.load_ms;
  out.times.edges_ms = ex.times.edges_ms;
  out.times.linking_ms = ex.times.linking_ms;
  out.px_to_m = sc.px_to_m;
  out.chains_texture = ex.texture_chains;
  const vision::SimplifyReport& r = sc.report;
  out.chains_found = r.chains_found;
  out.thin_line_pairs_merged = r.thin_line_pairs_merged;
  out.chains_after_thin_lines = r.chains_after_thin_lines;
  out.gaps_closed = r.gaps_closed;
  out.chains_closed_by_gaps = r.chains_closed_by_gaps;
  out.chains_after_gaps = r.chains_after_gaps;
  out.chains_too_short = r.chains_too_short;
  out.chains_along_border = r.chains_along_border;
  out.chains_over_max_shapes = r.chains_over_max_shapes;
  out.chains_over_budget = r.chains_over_budget;
  out.segments_before_budget = r.segments_before_budget;
  out.times.thin_lines_ms = r.thin_lines_ms;
  out.times.gaps_ms = r.gaps_ms;
  out.polylines = to_polylines(sc.curves);
  out.strength.reserve(sc.curves.size());
  for (const vision::SceneCurve& c : sc.curves) out.strength.push_back(c.strength);
  out.scene = std::make_unique<Scene>(Scene::build(out.polylines, s.haptics.max_levels));
  out.segments_after_budget = out.scene->total_segments(0);
  out.times.multires_ms = out.scene->build_times().multires_ms;
  out.times.tree_ms = out.scene->build_times().tree_ms;
  describe_scene_shapes(out);
}

/// OCR's words as a text layer's, for the text mask.
std::vector<vision::PdfWord> as_page_words(const std::vector<vision::OcrWord>& words) {
  std::vector<vision::PdfWord> out;
  out.reserve(words.size());
  for (const vision::OcrWord& w : words) out.push_back({w.text, w.box_px, true});
  return out;
}

/// A text block's box in pixels (origin at the top-left pixel's corner) in workspace metres (PxToM maps
/// pixel centres).
TextBlockM block_in_metres(const cv::Rect2d& box_px, const vision::PxToM& m, int id) {
  TextBlockM t;
  t.id = id;
  t.lo_m = {m.x_m(box_px.x - 0.5), m.y_m(box_px.y + box_px.height - 0.5)};
  t.hi_m = {m.x_m(box_px.x + box_px.width - 0.5), m.y_m(box_px.y - 0.5)};
  return t;
}

/// OCR's blocks in metres, after the scene's pixel mapping is known.
void add_ocr_blocks(ImageScene& out, const vision::OcrResult& text) {
  for (const vision::OcrBlock& b : text.blocks) {
    TextBlockM t = block_in_metres(b.box_px, out.px_to_m, static_cast<int>(out.text_blocks.size()));
    t.text = b.text;
    t.source = "ocr";
    t.confidence = b.confidence;
    t.language = language_of_tesseract(b.language);
    out.text_blocks.push_back(std::move(t));
  }
}

/// Shrinks `grey` to at most `side_px` on its longer side (INTER_AREA); the scale used in `scale`.
cv::Mat at_most(const cv::Mat& grey, int side_px, double& scale) {
  const int side = std::max(grey.cols, grey.rows);
  scale = side > side_px ? static_cast<double>(side_px) / side : 1.0;
  if (scale == 1.0) return grey;
  cv::Mat out;
  cv::resize(grey, out, cv::Size(), scale, scale, cv::INTER_AREA);
  return out;
}

/// Side a picture is judged at for being a page of text [px].
constexpr int kJudgedSidePx = 1600;

/// The picture decoded again in more detail for OCR (at up to kOcrMaxSidePx), when the scene's picture was
/// decoded reduced; empty when the scene's picture is all the detail there is. May throw vision::InputError.
using OcrSource = std::function<vision::DecodedImage()>;

/// Scales OCR's boxes by `k` (from one pixel frame to another; corner origin, so no offset).
void scale_boxes(vision::OcrResult& r, double k) {
  if (k == 1.0) return;
  const auto sc = [k](const cv::Rect2d& b) { return cv::Rect2d(b.x * k, b.y * k, b.width * k, b.height * k); };
  for (vision::OcrWord& w : r.words) w.box_px = sc(w.box_px);
  for (vision::OcrBlock& b : r.blocks) b.box_px = sc(b.box_px);
}

/// The text of the scene's picture (`grey`, at 1/decode_scale of the file), read at full detail: from `source`
/// when given (its boxes scaled into grey's frame), else from `grey`. A refused second decode costs the text
/// only, as an OCR failure does.
vision::OcrResult read_picture_text(const cv::Mat& grey, int decode_scale, const OcrSource& source,
                                    const std::string& name, const config::Settings& s, OcrReport& report,
                                    const TextRun& run) {
  if (!source) return read_text(grey, name, s, report, run);
  cv::Mat detail_grey;
  int detail_scale = 1;
  try {
    const vision::DecodedImage detail = source();
    cv::cvtColor(detail.bgr, detail_grey, cv::COLOR_BGR2GRAY);
    detail_scale = detail.scale;
  } catch (const vision::InputError& e) {
    spdlog::warn("{}; the picture is felt without its text", e.what());
    report.ran = false;
    report.why = std::string("failed: ") + e.what();
    return {};
  }
  vision::OcrResult r = read_text(detail_grey, name, s, report, run);
  // A position x in the detail decode's pixels is x * detail_scale at full detail, x * detail_scale /
  // decode_scale in the scene's picture.
  scale_boxes(r, static_cast<double>(detail_scale) / decode_scale);
  return r;
}

/// The scene of a picture (BGR) whose text is read when [vision] ocr asks (now, or later by with_text): the
/// words masked from the edges, the blocks kept in metres.
/// `source` (may be empty): the picture in more detail for OCR, see OcrSource; out.decode_scale is bgr's.
void build_picture(ImageScene& out, const cv::Mat& bgr, const config::Settings& s, TextTiming timing,
                   const TextRun& run, const OcrSource& source = {}) {
  out.width_px = bgr.cols;
  out.height_px = bgr.rows;
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  vision::OcrResult text;
  cv::Mat mask;
  if (wants_picture_text(grey, s, out.ocr.why)) {
    // The letters of printed lines are kept out of the curves whether OCR reads them or not (a word too
    // uncertain to speak is still no shape to feel).
    mask = printed_letters_mask_of(grey);
    if (timing == TextTiming::now) {
      text = read_picture_text(grey, out.decode_scale, source, out.image_path, s, out.ocr, run);
      if (!text.words.empty()) {
        const cv::Mat words = text_mask(grey.size(), as_page_words(text.words));
        mask = mask.empty() ? words : (mask | words);
      }
    } else {
      out.text_pending = true;
      out.text_likely = true;  // it looks like a page of text, or [vision] ocr "always" asks for it
      out.with_text = [bgr, name = out.image_path, s, source, fw = out.file_width_px, fh = out.file_height_px,
                       scale = out.decode_scale](const TextRun& run) {
        ImageScene again;
        again.image_path = name;
        again.picture = bgr;
        again.file_width_px = fw;
        again.file_height_px = fh;
        again.decode_scale = scale;
        build_picture(again, bgr, s, TextTiming::now, run, source);
        return again;
      };
    }
  }
  out.text_words_masked = text.words.size();
  build_from_chains(
      out, vision::scene_chains_from_image(bgr, extract_params_from(s), simplify_params_from(s), segment_cost(s), mask),
      s);
  add_ocr_blocks(out, text);
}

/// The scene of a rendered document page (see build_page_scene).
/// `choice`: wants_page_text's answer when the caller has it, else null (judged here).
void build_page(ImageScene& out, const vision::PdfPage& page, const config::Settings& s, TextTiming timing,
                const TextRun& run, const PageTextChoice* choice) {
  cv::cvtColor(page.grey, out.picture, cv::COLOR_GRAY2BGR);
  out.file_width_px = page.grey.cols;
  out.file_height_px = page.grey.rows;
  vision::OcrResult text;
  cv::Mat letters;  // printed letters, kept out whether OCR reads them or not
  bool wanted = false;
  if (choice) {
    wanted = choice->read;
    out.ocr.why = choice->why;
  } else {
    wanted = wants_page_text(page, s, out.ocr.why);
  }
  if (wanted) {
    letters = printed_letters_mask_of(page.grey);
    if (timing == TextTiming::now) {
      text = read_text(page.grey, out.image_path, s, out.ocr, run);
    } else {
      out.text_pending = true;
      out.text_likely = !letters.empty() || !page.words.empty();
      out.with_text = [kept = std::make_shared<const vision::PdfPage>(page), name = out.image_path, number = out.page,
                       s](const TextRun& run) {
        ImageScene again;
        again.image_path = name;
        again.page = number;
        again.pages = kept->pages;
        build_page(again, *kept, s, TextTiming::now, run, nullptr);
        return again;
      };
    }
  }
  const bool read = !text.words.empty();  // else the text layer's words, if any
  const std::vector<vision::PdfWord> words = read ? as_page_words(text.words) : page.words;
  out.text_words_masked = words.size();
  cv::Mat mask = words.empty() ? cv::Mat() : text_mask(page.grey.size(), words);
  if (!letters.empty()) mask = mask.empty() ? letters : (mask | letters);
  build_from_chains(out,
                    vision::scene_chains_from_image(page.grey, extract_params_from(s), simplify_params_from(s),
                                                    segment_cost(s), mask),
                    s);
  if (read) {
    add_ocr_blocks(out, text);
    return;
  }
  for (const vision::TextBlock& b : page.blocks) {
    TextBlockM t = block_in_metres(b.box_px, out.px_to_m, static_cast<int>(out.text_blocks.size()));
    t.text = b.text;
    out.text_blocks.push_back(std::move(t));
  }
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

bool wants_picture_text(const cv::Mat& grey, const config::Settings& s, std::string& why) {
  if (s.vision.ocr == "off") {
    why = "off";
    return false;
  }
  if (s.vision.ocr == "always") {
    why = "always";
    return true;
  }
  double scale = 1.0;
  const bool page = vision::looks_like_text_page(at_most(grey, kJudgedSidePx, scale));
  why = page ? "a page of text" : "not a page of text";
  return page;
}

cv::Mat printed_letters_mask_of(const cv::Mat& grey) {
  double scale = 1.0;
  const cv::Mat judged = at_most(grey, kJudgedSidePx, scale);
  cv::Mat mask = vision::printed_letters_mask(judged);
  if (mask.empty() || scale == 1.0) return mask;
  cv::Mat full;
  cv::resize(mask, full, grey.size(), 0, 0, cv::INTER_NEAREST);
  return full;
}

vision::OcrResult read_text(const cv::Mat& grey, const std::string& name, const config::Settings& s, OcrReport& report,
                            const TextRun& run) {
  double scale = 1.0;
  const cv::Mat read = at_most(grey, kOcrMaxSidePx, scale);
  vision::OcrParams params = ocr_params_from(s);
  params.cancel = run.cancel;
  if (run.on_block)
    params.on_block = [&run](const vision::OcrBlock& b) { run.on_block(b.text, language_of_tesseract(b.language)); };
  vision::OcrResult r;
  try {
    r = vision::recognise_text(read, name, params);
  } catch (const vision::OcrError& e) {
    report.ran = false;
    if (e.kind() == vision::OcrError::Kind::Cancelled) {
      spdlog::info("{}", e.what());
      report.why = "cancelled";
    } else {
      spdlog::warn("{}; the picture is felt without its text", e.what());
      report.why = std::string("failed: ") + e.what();
    }
    return {};
  }
  if (scale < 1.0) {  // back to the picture's pixels
    for (vision::OcrWord& w : r.words)
      w.box_px = cv::Rect2d(w.box_px.x / scale, w.box_px.y / scale, w.box_px.width / scale, w.box_px.height / scale);
    for (vision::OcrBlock& b : r.blocks)
      b.box_px = cv::Rect2d(b.box_px.x / scale, b.box_px.y / scale, b.box_px.width / scale, b.box_px.height / scale);
  }
  report.ran = true;
  report.words = static_cast<int>(r.words.size());
  report.mean_confidence = r.mean_confidence;
  report.ms = r.ms;
  report.worker_max_rss_kb = r.worker_max_rss_kb;
  return r;
}

int picture_keep_side_px(const config::Settings& s) {
  return s.vision.ocr == "off" ? s.vision.max_image_side_px
                               : std::max(s.vision.max_image_side_px, kPictureTextJudgedMinSidePx);
}

namespace {

/// The decoded picture's pixels and sizes into `out`.
void keep_decoded(ImageScene& out, vision::DecodedImage&& d, double decode_ms) {
  out.picture = std::move(d.bgr);
  out.file_width_px = d.file_width_px;
  out.file_height_px = d.file_height_px;
  out.decode_scale = d.scale;
  out.times.decode_ms = decode_ms;
}

}  // namespace

ImageScene build_image_scene(const std::string& path, const config::Settings& s, TextTiming timing) {
  ImageScene out;
  out.image_path = path;
  const vision::ImageLimits limits = extract_params_from(s).limits;
  const auto t0 = std::chrono::steady_clock::now();
  vision::DecodedImage decoded = vision::load_image_reduced(path, limits, picture_keep_side_px(s));
  keep_decoded(out, std::move(decoded), ms_since(t0));
  OcrSource source;
  if (out.decode_scale > 1 && s.vision.ocr != "off") {
    source = [path, limits] { return vision::load_image_reduced(path, limits, kOcrMaxSidePx); };
  }
  build_picture(out, out.picture, s, timing, TextRun{}, source);
  out.times.load_ms += out.times.decode_ms;
  return out;
}

ImageScene build_image_scene_from_bytes(const std::vector<std::uint8_t>& bytes, const std::string& name,
                                        const config::Settings& s, TextTiming timing) {
  ImageScene out;
  out.image_path = name;
  const vision::ImageLimits limits = extract_params_from(s).limits;
  const auto t0 = std::chrono::steady_clock::now();
  vision::DecodedImage decoded = vision::decode_image_reduced(bytes, name, limits, picture_keep_side_px(s));
  keep_decoded(out, std::move(decoded), ms_since(t0));
  OcrSource source;
  if (out.decode_scale > 1 && s.vision.ocr != "off") {
    source = [kept = std::make_shared<const std::vector<std::uint8_t>>(bytes), name, limits] {
      return vision::decode_image_reduced(*kept, name, limits, kOcrMaxSidePx);
    };
  }
  build_picture(out, out.picture, s, timing, TextRun{}, source);
  out.times.load_ms += out.times.decode_ms;
  return out;
}

ImageScene build_image_scene_from_picture(const cv::Mat& bgr, const std::string& name, const config::Settings& s,
                                          TextTiming timing) {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw hk::ArgumentError("picture '" + name + "': must be a non-empty 8-bit BGR image");
  ImageScene out;
  out.image_path = name;
  out.picture = bgr.clone();
  out.file_width_px = bgr.cols;
  out.file_height_px = bgr.rows;
  build_picture(out, out.picture, s, timing, TextRun{});
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
    const cv::Rect2d r =
        cv::Rect2d(w.box_px.x - g, w.box_px.y - g, w.box_px.width + 2 * g, w.box_px.height + 2 * g) & frame;
    if (r.width <= 0 || r.height <= 0) continue;
    const cv::Point p0(static_cast<int>(std::floor(r.x)), static_cast<int>(std::floor(r.y)));
    const cv::Point p1(static_cast<int>(std::ceil(r.x + r.width)) - 1, static_cast<int>(std::ceil(r.y + r.height)) - 1);
    cv::rectangle(mask, p0, p1, cv::Scalar(255), cv::FILLED);
  }
  return mask;
}

bool wants_page_text(const vision::PdfPage& page, const config::Settings& s, std::string& why) {
  if (s.vision.ocr == "off") {
    why = "off";
    return false;
  }
  if (page.words.empty()) {
    why = "no text layer";
    return true;
  }
  cv::Mat uncovered = page.grey.clone();  // the page with its text layer's words whited out
  uncovered.setTo(255, text_mask(page.grey.size(), page.words));
  const bool little = vision::looks_like_text_page(uncovered);
  why = little ? "text layer covers little of the text" : "a text layer";
  return little;
}

ImageScene build_page_scene(const vision::PdfPage& page, const std::string& name, int page_number,
                            const config::Settings& s, TextTiming timing, const PageTextChoice* choice) {
  ImageScene out;
  out.image_path = name;
  out.page = page_number;
  out.pages = page.pages;
  build_page(out, page, s, timing, TextRun{}, choice);
  return out;
}

}  // namespace hk::app
