// The kiosk's camera and its captures on a worker thread (see capture_service.hpp).

#include "pictures/capture_service.hpp"
#include "pictures/picture_params.hpp"

#include <exception>
#include <utility>

#include <spdlog/spdlog.h>
#include <opencv2/imgproc.hpp>

namespace hk::app {
namespace {

constexpr int kPreviewWidthPx = 640;

}  // namespace

CameraChoice choose_camera(const config::CameraSettings& camera) {
  CameraChoice c;
  if (camera.source == "none") {
    c.why = "[camera] source is \"none\"";
    return c;
  }
  if (camera.source == "auto") {
    const std::vector<vision::CameraInfo> found = vision::list_cameras();
    if (found.empty()) {
      c.why = "no camera found (libcamera, V4L2)";
      return c;
    }
    try {
      c.spec = vision::parse_source_spec(found.front().spec);
      c.name = found.front().spec + " (" + found.front().name + ")";
    } catch (const vision::CameraError& e) {
      c.why = e.what();
    }
    return c;
  }
  try {
    c.spec = vision::parse_source_spec(camera.source);
    c.name = camera.source;
  } catch (const vision::CameraError& e) {
    c.why = e.what();
  }
  return c;
}

CaptureService::CaptureService(const config::Settings& settings, CameraChoice camera)
    : settings_(settings), camera_(std::move(camera)) {}

CaptureService::~CaptureService() { cancel(); }

bool CaptureService::start() {
  if (!available()) return false;
  cancel();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    news_.clear();
    preview_ = {};
  }
  cancel_.store(false, std::memory_order_release);
  busy_ = true;
  worker_ = std::thread([this, s = settings_] { run(s); });
  return true;
}

void CaptureService::cancel() {
  cancel_.store(true, std::memory_order_release);
  if (worker_.joinable()) worker_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  news_.clear();
  busy_ = false;
}

std::vector<CaptureNews> CaptureService::poll() {
  std::vector<CaptureNews> out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    out.swap(news_);
  }
  for (const CaptureNews& n : out) {
    if (n.kind != CaptureNews::Kind::Advice) busy_ = false;
  }
  if (!busy_ && worker_.joinable()) worker_.join();  // it has posted its end: it is finishing
  return out;
}

CapturePreview CaptureService::preview() const {
  std::lock_guard<std::mutex> lock(mutex_);
  CapturePreview p;
  p.frame = preview_.frame.clone();
  p.corners_px = preview_.corners_px;
  return p;
}

void CaptureService::post(CaptureNews n) {
  std::lock_guard<std::mutex> lock(mutex_);
  news_.push_back(std::move(n));
}

void CaptureService::run(config::Settings s) {
  CaptureNews end;
  try {
    std::unique_ptr<vision::FrameSource> source = vision::open_frame_source(*camera_.spec, frame_source_params_from(s));
    spdlog::info("capture: from {}", source->name());
    CaptureHooks hooks;
    hooks.cancel = &cancel_;
    hooks.advice = [this](vision::FramingAdvice a) {
      CaptureNews n;
      n.advice = a;
      post(std::move(n));
    };
    hooks.preview = [this](const cv::Mat& frame, const vision::FrameLook& look) {
      const double f = frame.cols > kPreviewWidthPx ? static_cast<double>(kPreviewWidthPx) / frame.cols : 1.0;
      CapturePreview p;
      cv::resize(frame, p.frame, cv::Size(), f, f, cv::INTER_AREA);
      if (look.page.found) {
        std::array<cv::Point2d, 4> c = look.page.corners_px;
        for (cv::Point2d& q : c) q *= f;
        p.corners_px = c;
      }
      std::lock_guard<std::mutex> lock(mutex_);
      preview_ = std::move(p);
    };
    const CaptureOutcome o = run_capture(*source, capture_params_from(s), hooks);
    if (o.end == CaptureEnd::Cancelled) return;  // nothing to say: the flow said it
    if (o.end == CaptureEnd::Timeout) {
      end.kind = CaptureNews::Kind::TimedOut;
    } else {
      end.kind = CaptureNews::Kind::Captured;
      end.scene =
          std::make_shared<ImageScene>(build_image_scene_from_picture(o.image, "camera capture", s, TextTiming::later));
      spdlog::info("capture: {} after {:.1f} s, {}, {} shapes", capture_end_name(o.end),
                   o.captured_t_s - o.first_frame_t_s, o.rectified ? "page rectified" : "whole frame",
                   end.scene->scene->curve_count());
    }
  } catch (const std::exception& e) {
    end.kind = CaptureNews::Kind::Failed;
    end.reason = e.what();
    spdlog::warn("capture: {}", e.what());
  }
  post(std::move(end));
}

}  // namespace hk::app
