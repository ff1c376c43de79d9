#pragma once
/// @file capture.hpp
/// One camera capture: frames from a vision::FrameSource are looked at (vision::look_at_frame), the
/// framing guide (vision::FramingGuide) says what to do and decides when to take the picture, a still is taken at
/// the camera's largest size (FrameSource::still: the page's text is read from the sensor's pixels, not the
/// preview's), and the page is rectified (vision::rectify_page) or, when none was found, the whole frame kept. The same
/// loop serves the headless `capture` command, `explore --source` and the kiosk's Capture key (on a worker thread, with
/// a cancel flag and a preview).

#include <array>
#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "audio/messages.hpp"
#include "config/settings.hpp"
#include "vision/frame_source.hpp"
#include "vision/framing.hpp"
#include "vision/page.hpp"

namespace hk::app {

/// The settings of a capture.
struct CaptureParams {
  vision::FramingParams framing;  ///< the guide's thresholds (still_s from [camera])
  vision::PageParams page;        ///< find_page's
  /// Frame time after which the capture gives up [s] (> 0): the kiosk says so; the `capture` command keeps
  /// the last frame instead (rectified when a page was in it).
  double timeout_s = 60.0;
  double frame_wait_s = 2.0;  ///< a source silent this long (wall clock) ends the capture with CameraError [s]
};

/// How a capture ended.
enum class CaptureEnd {
  Still,       ///< the page lay whole, centred and still for still_s
  WholeFrame,  ///< no page outline, but a still, lit frame with detail for whole_frame_after_s: the whole frame
  Timeout,     ///< timeout_s of frame time went by first
  Cancelled,   ///< the cancel flag was raised
};

/// "still", "whole_frame", "timeout", "cancelled" (capture.json's "captured_by").
const char* capture_end_name(CaptureEnd e);

/// What a capture gave.
struct CaptureOutcome {
  CaptureEnd end = CaptureEnd::Cancelled;
  cv::Mat frame;  ///< the frame captured (Still, WholeFrame) or the last one (Timeout), as delivered (CV_8UC3); empty
                  ///< for Cancelled
  /// What the scene is built from (CV_8UC3): the page rectified, or the whole frame when no page was found.
  /// For Timeout the last frame's (the kiosk does not use it); empty for Cancelled or no frame.
  cv::Mat image;
  std::optional<std::array<cv::Point2d, 4>> corners_px;  ///< the page's corners in `frame` (TL, TR, BR, BL), when found
  bool rectified = false;                                ///< `image` is the rectified page
  /// `frame` is the camera's still at its largest size (FrameSource::still), larger than the preview frames the
  /// guide looked at; false when the camera gave none larger (the preview frame is kept).
  bool from_still = false;
  std::vector<vision::FramingAdvice> advice;  ///< what the guide said, in order
  std::vector<double> advice_t_s;             ///< the frame time of each [s]
  int frames = 0;                             ///< frames looked at
  double first_frame_t_s = 0.0;               ///< the first frame's time [s]
  double captured_t_s = 0.0;                  ///< the last frame's time [s]
  double look_ms = 0.0;                       ///< wall time of look_at_frame over all frames [ms]
  double rectify_ms = 0.0;                    ///< wall time of the rectification [ms]
};

/// Callbacks of a running capture (all optional), called on the capturing thread.
struct CaptureHooks {
  std::function<void(vision::FramingAdvice)> advice;                            ///< the guide says this now
  std::function<void(const cv::Mat& frame, const vision::FrameLook&)> preview;  ///< every frame, with its look
  const std::atomic<bool>* cancel = nullptr;                                    ///< raised: stop at the next frame
};

/// Runs one capture on `source` until the guide captures, the time-out or the cancel flag.
/// @throws vision::CameraError when the source fails or sends no frame for frame_wait_s;
///         hk::ArgumentError for bad params.
CaptureOutcome run_capture(vision::FrameSource& source, const CaptureParams& params, const CaptureHooks& hooks = {});

/// The message that speaks an advice (capture_place, capture_move_left, ...).
audio::MessageId advice_message(vision::FramingAdvice a);

/// What `haptic-kiosk capture` was asked to do.
struct CaptureOptions {
  std::string source;       ///< "file:PATH" | "libcamera:N" | "v4l2:DEV"
  std::string out_dir;      ///< capture.png and capture.json go here (created if missing)
  std::string config_path;  ///< settings (TOML); empty: defaults
};

/// capture.json of an outcome: {"corners_px": [[x, y] × 4] or null, "guidance": [the spoken texts, in
/// English], "advice": [advice_name ...], "advice_t_s": [...], "rectified", "from_still", "captured_by", "source",
/// "frames",
/// "first_frame_t_s", "captured_t_s", "rectify_ms", "width_px", "height_px" (of capture.png)}.
std::string capture_json(const CaptureOutcome& o, const std::string& source_name);

/// Writes DIR/capture.png (CaptureOutcome::image) and DIR/capture.json.
/// @throws AppError (one line) when the folder cannot be made or a file cannot be written, or there is
///         no image (a cancelled capture).
void write_capture(const CaptureOutcome& o, const std::string& source_name, const std::string& out_dir);

/// `haptic-kiosk capture`: opens the source, runs one capture (a time-out keeps the last frame) and writes it.
/// Prints one line: how it ended and where it went. Returns the exit status (0).
/// @throws vision::CameraError, config::ConfigError, AppError (one line each).
int run_capture_command(const CaptureOptions& o);

/// `haptic-kiosk cameras`: one line per camera ("libcamera:0  imx219  (libcamera)"), or "no camera found".
/// Returns 0.
int run_cameras_command();

}  // namespace hk::app
