// One camera capture: frames → looks → the framing guide → the page rectified (see capture.hpp).

#include "pictures/capture.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "config/load.hpp"
#include "formats/app_error.hpp"
#include "hk/error.hpp"
#include "pictures/picture_params.hpp"

namespace hk::app {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

/// Keeps the frame as the capture: the page rectified when the look found one, else the whole frame. The frame
/// is copied: a source may reuse its buffer for the next frame.
void take(CaptureOutcome& o, const cv::Mat& frame, const vision::FrameLook& look) {
  o.frame = frame.clone();
  if (look.page.found) {
    const auto t0 = Clock::now();
    o.image = vision::rectify_page(frame, look.page.corners_px);
    o.rectify_ms = ms_since(t0);
    o.corners_px = look.page.corners_px;
    o.rectified = true;
  } else {
    o.image = frame.clone();
    o.corners_px.reset();
    o.rectified = false;
  }
}

/// Takes the capture from a still at the camera's largest size when it gives one larger than `preview`: the page
/// found again in the still (else the preview's corners scaled to it) and rectified from it, so that OCR reads
/// the sensor's pixels. A camera that gives none larger, or fails to (one warning), leaves the preview frame.
void take_still(CaptureOutcome& o, vision::FrameSource& source, const cv::Mat& preview, const vision::FrameLook& look,
                const CaptureParams& params) {
  vision::Frame still;
  bool got = false;
  try {
    got = source.still(still, params.frame_wait_s);
  } catch (const vision::CameraError& e) {
    spdlog::warn("{}; the capture keeps the preview frame", e.what());
  }
  if (!got || still.bgr.empty() || still.bgr.cols <= preview.cols || still.bgr.rows <= preview.rows) {
    take(o, preview, look);
    return;
  }
  vision::FrameLook at_still = look;
  if (look.page.found) {
    const vision::PageDetection again = vision::find_page(still.bgr, params.page);
    if (again.found) {
      at_still.page = again;
    } else {  // the page lay still: where the preview saw it, at the still's scale
      const double kx = static_cast<double>(still.bgr.cols) / preview.cols;
      const double ky = static_cast<double>(still.bgr.rows) / preview.rows;
      for (cv::Point2d& c : at_still.page.corners_px) c = {c.x * kx, c.y * ky};
    }
  }
  take(o, still.bgr, at_still);
  o.from_still = true;
}

}  // namespace

const char* capture_end_name(CaptureEnd e) {
  switch (e) {
    case CaptureEnd::Still:
      return "still";
    case CaptureEnd::WholeFrame:
      return "whole_frame";
    case CaptureEnd::Timeout:
      return "timeout";
    case CaptureEnd::Cancelled:
      return "cancelled";
  }
  return "?";
}

audio::MessageId advice_message(vision::FramingAdvice a) {
  using audio::MessageId;
  switch (a) {
    case vision::FramingAdvice::PlacePicture:
      return MessageId::capture_place;
    case vision::FramingAdvice::TooDark:
      return MessageId::capture_too_dark;
    case vision::FramingAdvice::CutOffTop:
      return MessageId::capture_cut_off_top;
    case vision::FramingAdvice::CutOffBottom:
      return MessageId::capture_cut_off_bottom;
    case vision::FramingAdvice::CutOffLeft:
      return MessageId::capture_cut_off_left;
    case vision::FramingAdvice::CutOffRight:
      return MessageId::capture_cut_off_right;
    case vision::FramingAdvice::MoveLeft:
      return MessageId::capture_move_left;
    case vision::FramingAdvice::MoveRight:
      return MessageId::capture_move_right;
    case vision::FramingAdvice::MoveUp:
      return MessageId::capture_move_up;
    case vision::FramingAdvice::MoveDown:
      return MessageId::capture_move_down;
    case vision::FramingAdvice::HoldStill:
      return MessageId::capture_hold_still;
  }
  return MessageId::capture_place;
}

CaptureOutcome run_capture(vision::FrameSource& source, const CaptureParams& params, const CaptureHooks& hooks) {
  if (!(params.timeout_s > 0.0) || !(params.frame_wait_s > 0.0)) {
    throw hk::ArgumentError("capture: timeout_s and frame_wait_s must be > 0 s");
  }
  vision::FramingGuide guide(params.framing);
  CaptureOutcome o;
  vision::Frame frame;
  vision::FrameLook look, previous;
  cv::Mat small;
  for (;;) {
    if (hooks.cancel != nullptr && hooks.cancel->load(std::memory_order_acquire)) {
      o.end = CaptureEnd::Cancelled;
      o.image.release();
      return o;
    }
    if (!source.next(frame, params.frame_wait_s)) {
      throw vision::CameraError("camera '" + source.name() + "': no frame came for " +
                                std::to_string(params.frame_wait_s) + " s");
    }
    const auto t0 = Clock::now();
    look = vision::look_at_frame(frame.bgr, frame.t_s, o.frames > 0 ? &previous : nullptr, small, params.page);
    o.look_ms += ms_since(t0);
    if (o.frames == 0) o.first_frame_t_s = frame.t_s;
    ++o.frames;
    o.captured_t_s = frame.t_s;
    if (hooks.preview) hooks.preview(frame.bgr, look);
    const vision::FramingStep step = guide.update(look);
    if (step.say) {
      o.advice.push_back(*step.say);
      o.advice_t_s.push_back(frame.t_s);
      if (hooks.advice) hooks.advice(*step.say);
    }
    if (step.capture) {
      o.end = look.page.found ? CaptureEnd::Still : CaptureEnd::WholeFrame;
      take_still(o, source, frame.bgr, look, params);
      return o;
    }
    if (frame.t_s - o.first_frame_t_s >= params.timeout_s) {
      o.end = CaptureEnd::Timeout;
      take(o, frame.bgr, look);
      return o;
    }
    previous = look;
  }
}

std::string capture_json(const CaptureOutcome& o, const std::string& source_name) {
  nlohmann::json j;
  if (o.corners_px) {
    nlohmann::json corners = nlohmann::json::array();
    for (const cv::Point2d& c : *o.corners_px) corners.push_back({c.x, c.y});
    j["corners_px"] = std::move(corners);
  } else {
    j["corners_px"] = nullptr;
  }
  const audio::MessageCatalog& en = audio::MessageCatalog::english();
  nlohmann::json guidance = nlohmann::json::array(), advice = nlohmann::json::array();
  for (vision::FramingAdvice a : o.advice) {
    guidance.push_back(en.text(advice_message(a)));
    advice.push_back(vision::advice_name(a));
  }
  j["guidance"] = std::move(guidance);
  j["advice"] = std::move(advice);
  j["advice_t_s"] = o.advice_t_s;
  j["rectified"] = o.rectified;
  j["from_still"] = o.from_still;
  j["captured_by"] = capture_end_name(o.end);
  j["source"] = source_name;
  j["frames"] = o.frames;
  j["first_frame_t_s"] = o.first_frame_t_s;
  j["captured_t_s"] = o.captured_t_s;
  j["rectify_ms"] = o.rectify_ms;
  j["look_ms_per_frame"] = o.frames > 0 ? o.look_ms / o.frames : 0.0;
  j["width_px"] = o.image.cols;
  j["height_px"] = o.image.rows;
  return j.dump(2) + "\n";
}

void write_capture(const CaptureOutcome& o, const std::string& source_name, const std::string& out_dir) {
  if (o.image.empty()) throw AppError("capture: nothing was captured, so nothing is written to '" + out_dir + "'");
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir)) {
    throw AppError("output folder '" + out_dir + "': cannot create it (" + ec.message() + ")");
  }
  const std::filesystem::path dir(out_dir);
  const std::string png = (dir / "capture.png").string();
  if (!cv::imwrite(png, o.image)) throw AppError("output '" + png + "': cannot write the PNG");
  const std::filesystem::path json = dir / "capture.json";
  std::ofstream f(json, std::ios::binary | std::ios::trunc);
  f << capture_json(o, source_name);
  f.close();
  if (!f) throw AppError("output '" + json.string() + "': cannot write the file");
}

int run_capture_command(const CaptureOptions& opt) {
  const config::Settings s = opt.config_path.empty() ? config::Settings{} : config::load_settings(opt.config_path);
  const vision::SourceSpec spec = vision::parse_source_spec(opt.source);
  std::unique_ptr<vision::FrameSource> source = vision::open_frame_source(spec, frame_source_params_from(s));
  const CaptureOutcome o = run_capture(*source, capture_params_from(s));
  write_capture(o, source->name(), opt.out_dir);
  std::printf("capture: %s after %d frames (%.1f s), %s, %zu things said -> %s\n", capture_end_name(o.end), o.frames,
              o.captured_t_s - o.first_frame_t_s, o.rectified ? "page rectified" : "whole frame", o.advice.size(),
              opt.out_dir.c_str());
  return 0;
}

int run_cameras_command() {
  const std::vector<vision::CameraInfo> cameras = vision::list_cameras();
  if (cameras.empty()) {
    std::printf("no camera found\n");
    return 0;
  }
  for (const vision::CameraInfo& c : cameras)
    std::printf("%s  %s  (%s)\n", c.spec.c_str(), c.name.c_str(), c.backend.c_str());
  return 0;
}

}  // namespace hk::app
