#pragma once
/// @file capture_service.hpp
/// The kiosk's camera: which camera it has ([camera] source), and captures run off the window
/// thread. A capture opens the source, runs run_capture (capture.hpp) on a worker thread, and builds the scene
/// of what it took (build_image_scene_from_picture, its text left for the kiosk's TextReader); the window thread polls
/// the news (advice to speak, the scene, a failure) and the latest preview frame for sighted companions.
///
/// Threads: construct, call and destroy on one thread (the window thread); the worker is owned here and joined
/// by cancel(), the next start() or the destructor.

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "config/settings.hpp"
#include "pictures/capture.hpp"
#include "pictures/image_scene.hpp"
#include "vision/frame_source.hpp"

namespace hk::app {

/// The camera [camera] source names: "none" → none; "auto" → the first of list_cameras (none when it finds
/// none); a spec → that spec, parsed (a spec that does not parse → none, with `why`). Never throws; never opens
/// the camera.
struct CameraChoice {
  std::optional<vision::SourceSpec> spec;  ///< the camera to open; empty: no camera
  std::string name;                        ///< what it is, for the log ("libcamera:0 (imx219)"); empty when none
  std::string why;                         ///< no camera: why (for the log), e.g. "[camera] source is \"none\""
};
CameraChoice choose_camera(const config::CameraSettings& camera);

/// Something a capture has to say.
struct CaptureNews {
  enum class Kind { Advice, Captured, Failed, TimedOut };
  Kind kind = Kind::Advice;
  vision::FramingAdvice advice{};     ///< Advice: what the guide says
  std::shared_ptr<ImageScene> scene;  ///< Captured: the scene of the picture taken (its picture in ImageScene::picture)
  std::string reason;                 ///< Failed: why, one line (for the log)
};

/// The latest frame with what the guide saw in it, for the preview.
struct CapturePreview {
  cv::Mat frame;  ///< BGR, at most 640 px wide (scaled down); empty before the first frame
  std::optional<std::array<cv::Point2d, 4>> corners_px;  ///< the page's corners in `frame`'s pixels, when found
};

/// The camera and its captures.
class CaptureService {
 public:
  /// `settings` gives [camera], [vision] and the rest the scene is built with; `camera` is the camera to use
  /// (choose_camera).
  CaptureService(const config::Settings& settings, CameraChoice camera);
  ~CaptureService();
  CaptureService(const CaptureService&) = delete;
  CaptureService& operator=(const CaptureService&) = delete;

  /// Whether there is a camera to capture from.
  bool available() const { return camera_.spec.has_value(); }
  const CameraChoice& camera() const { return camera_; }
  /// Starts a capture (a capture under way is cancelled first). False when there is no camera.
  bool start();
  /// Stops the capture under way (joins its worker; a capture that already finished keeps its news unread
  /// but it is dropped). Idempotent.
  void cancel();
  /// News since the last call, in order.
  std::vector<CaptureNews> poll();
  /// The latest preview (a copy).
  CapturePreview preview() const;
  /// A capture is under way (started, and its end not yet polled).
  bool busy() const { return busy_; }
  /// New settings for the next capture (the camera stays the one chosen at start).
  void set_settings(const config::Settings& settings) { settings_ = settings; }

 private:
  void run(config::Settings settings);  // the worker
  void post(CaptureNews n);

  config::Settings settings_;
  CameraChoice camera_;
  std::thread worker_;
  std::atomic<bool> cancel_{false};
  mutable std::mutex mutex_;  // guards news_ and preview_
  std::vector<CaptureNews> news_;
  CapturePreview preview_;
  bool busy_ = false;
};

}  // namespace hk::app
