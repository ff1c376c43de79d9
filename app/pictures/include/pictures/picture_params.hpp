#pragma once
/// @file picture_params.hpp
/// The settings (config::Settings, one TOML file) mapped to the picture side's parameters: capture,
/// camera, USB-stick scan and PDF limits, OCR, the edge pipeline and the scene's simplification. With
/// runtime/runtime_params.hpp the one place where a setting becomes a parameter: every part's own
/// parameter struct keeps its defaults and units; these functions copy the settings' values into it.

#include <string>
#include <string_view>
#include "config/settings.hpp"
#include "pictures/capture.hpp"
#include "vision/frame_source.hpp"
#include "vision/ocr.hpp"
#include "vision/pdf.hpp"
#include "vision/pipeline.hpp"
#include "vision/scene_chains.hpp"
#include "vision/stick_scan.hpp"

namespace hk::app {

/// The capture settings from [camera]: still_s and timeout_s; the rest at its defaults.
CaptureParams capture_params_from(const config::Settings& s);

/// The source settings from [camera]: the frame size asked for; the file source at 10 frames a second.
vision::FrameSourceParams frame_source_params_from(const config::Settings& s);

/// [stick] settings as the scan's limits.
vision::ScanLimits scan_limits_from(const config::Settings& s);

/// [stick] settings as the PDF worker's limits (page_timeout_s is both the wall-clock and the CPU limit).
vision::PdfLimits pdf_limits_from(const config::Settings& s);

/// vision::OcrParams from the [vision] settings: the languages (empty: tesseract_languages_for the kiosk's
/// [kiosk] language) and the confidence threshold.
vision::OcrParams ocr_params_from(const config::Settings& settings);

/// The Tesseract languages that read text in the language `tag` (BCP 47): its own data and English ("fr" →
/// "fra+eng"), "eng" for English and for a language the kiosk has no Tesseract code for (en, fr, de, es, it,
/// pt, nl are known).
std::string tesseract_languages_for(std::string_view tag);

/// The BCP 47 language subtag of a Tesseract language ("fra" → "fr"), of those tesseract_languages_for knows; ""
/// for another.
std::string language_of_tesseract(std::string_view code);

/// The edge pipeline's parameters from [vision] and [workspace]: input limits, edge detector and its
/// thresholds, the working size, the workspace (chains are kept down to 2 px here; length is judged in
/// metres by simplify_params_from's limits).
vision::ExtractParams extract_params_from(const config::Settings& s);

/// The scene's simplification from [vision] and [workspace]: thin-line merging, gap closing, the shortest
/// chain kept, and the shape and segment budgets.
vision::SimplifyParams simplify_params_from(const config::Settings& s);

}  // namespace hk::app
