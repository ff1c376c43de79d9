// The settings mapped to the picture side's parameters (picture_params.hpp).
#include "pictures/picture_params.hpp"
#include "hk/language.hpp"

#include "vision/intake.hpp"

#include <algorithm>
#include <string>

namespace hk::app {

CaptureParams capture_params_from(const config::Settings& s) {
  CaptureParams p;
  p.framing.still_s = s.camera.still_s;
  p.timeout_s = s.camera.timeout_s;
  return p;
}

vision::FrameSourceParams frame_source_params_from(const config::Settings& s) {
  vision::FrameSourceParams p;
  p.width_px = s.camera.width_px;
  p.height_px = s.camera.height_px;
  p.max_frame_bytes = s.vision.max_file_bytes;
  return p;
}

vision::ScanLimits scan_limits_from(const config::Settings& s) {
  vision::ScanLimits l;
  l.max_depth = s.stick.max_depth;
  l.max_entries = s.stick.max_entries;
  l.max_documents = s.stick.max_documents;
  l.max_file_bytes = s.stick.max_file_bytes;
  l.max_seconds = s.stick.scan_timeout_s;
  l.picture_check = vision::image_header_problem;  // a visitor hears what can be read, and one line for what cannot
  return l;
}

vision::PdfLimits pdf_limits_from(const config::Settings& s) {
  vision::PdfLimits l;
  l.max_file_bytes = s.stick.max_file_bytes;
  l.max_pages = s.stick.max_pdf_pages;
  l.max_page_pixels = s.stick.page_max_pixels;
  l.max_dpi = s.stick.page_max_dpi;
  l.worker_cpu_s = s.stick.page_timeout_s;
  l.worker_wall_s = s.stick.page_timeout_s;
  return l;
}

namespace {

/// BCP 47 language subtags and the Tesseract languages that read them.
constexpr std::pair<std::string_view, std::string_view> kTesseractCodes[] = {
    {"en", "eng"}, {"fr", "fra"}, {"de", "deu"}, {"es", "spa"}, {"it", "ita"}, {"pt", "por"}, {"nl", "nld"}};

}  // namespace

std::string language_of_tesseract(std::string_view code) {
  for (const auto& [bcp47, tess] : kTesseractCodes)
    if (tess == code) return std::string(bcp47);
  return {};
}

std::string tesseract_languages_for(std::string_view tag) {
  const auto& kCodes = kTesseractCodes;
  const std::string_view primary = hk::language_subtag(tag);
  for (const auto& [bcp47, tess] : kCodes)
    if (bcp47 == primary) return tess == "eng" ? std::string("eng") : std::string(tess) + "+eng";
  return "eng";
}

vision::OcrParams ocr_params_from(const config::Settings& s) {
  vision::OcrParams p;
  p.languages = s.vision.ocr_languages.empty() ? tesseract_languages_for(s.kiosk.language) : s.vision.ocr_languages;
  p.min_word_confidence = s.vision.ocr_min_confidence;
  return p;
}

vision::ExtractParams extract_params_from(const config::Settings& s) {
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
  p.surround_inhibition = s.vision.surround_inhibition;
  p.line_drawing_max_ink_m = s.vision.thin_line_max_width_m;
  p.workspace_width_m = s.workspace.width_m;
  p.workspace_height_m = s.workspace.height_m;
  // Length is judged in metres by simplify_chains, where the workspace scale is known; keep every real chain here.
  p.min_chain_length_px = 2.0;
  return p;
}

vision::SimplifyParams simplify_params_from(const config::Settings& s) {
  vision::SimplifyParams p;
  p.workspace_width_m = s.workspace.width_m;
  p.workspace_height_m = s.workspace.height_m;
  p.thin_line_max_width_m = s.vision.thin_line_max_width_m;
  p.gap_close_m = s.vision.gap_close_m;
  p.min_chain_length_m = s.vision.min_chain_length_m;
  p.max_shapes = static_cast<std::size_t>(s.vision.max_shapes);
  p.max_segments = static_cast<std::size_t>(s.vision.max_segments);
  return p;
}

}  // namespace hk::app
