#pragma once
/// @file frame_source.hpp
/// Camera capture: frames from a camera or from files, behind one interface.
///
/// Three sources, named by a spec string (the `--source` of `capture` and `explore`, `[camera] source`):
/// - `file:PATH`: an image file, or a folder of frames served in name order (tests and demos);
/// - `libcamera:N`: the N-th camera libcamera enumerates (from 0), in its StillCapture configuration;
/// - `v4l2:DEV`: a V4L2 capture device (`/dev/video0`), MMAP streaming, YUYV or MJPEG decoded with OpenCV.
/// Frames leave as 8-bit BGR with a capture time on the source's own monotonic clock, so that what is
/// decided from frames over time (framing guidance: "hold still", "whole and still for 1 s") is the same
/// for a camera in real time and for a folder of frames read as fast as the disk allows.

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>
#include "hk/error.hpp"

#include <opencv2/core.hpp>

namespace hk::vision {

/// A camera or frame file that cannot be opened or read, or a malformed source spec. what() is one line
/// naming the source and the problem (control characters escaped), e.g.
/// "camera 'v4l2:/dev/video9': cannot open: No such file or directory",
/// "camera source 'usb:1': unknown kind (expected file:PATH, libcamera:N or v4l2:DEV)".
class CameraError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// A parsed source spec.
struct SourceSpec {
  enum class Kind { File, Libcamera, V4l2 };
  Kind kind = Kind::File;
  std::string path;  ///< File: the image or folder; V4l2: the device node (e.g. /dev/video0)
  int index = 0;     ///< Libcamera: the camera's place in libcamera's list, >= 0
  /// The spec as written back ("file:PATH", "libcamera:N", "v4l2:DEV").
  std::string str() const;
};

/// Parses "file:PATH", "libcamera:N" (N a decimal integer in [0, 63]) or "v4l2:DEV" (DEV a path starting with
/// '/'; a bare "v4l2:N" means /dev/videoN).
/// @throws CameraError (one line naming the spec) for an unknown kind, an empty path, or a bad index.
SourceSpec parse_source_spec(const std::string& spec);

/// Settings of a source.
struct FrameSourceParams {
  int width_px = 1280;     ///< requested frame width [px], [64, 8192]; a camera may give the nearest it has
  int height_px = 960;     ///< requested frame height [px], [64, 8192]
  double file_fps = 10.0;  ///< file source: frame i is stamped i / file_fps [s], (0, 1000]
  std::int64_t max_frame_bytes = 64LL << 20;  ///< largest frame buffer or file accepted [bytes]
};

/// One frame.
struct Frame {
  cv::Mat bgr;              ///< CV_8UC3, the whole sensor image as delivered (not rectified)
  double t_s = 0.0;         ///< capture time [s] on the source's monotonic clock (file: index / file_fps)
  std::uint64_t index = 0;  ///< 0, 1, 2, ... in delivery order
};

/// A source of frames. Not thread-safe: one thread calls next(). Destroying it stops the camera and frees
/// every buffer (no leak under the sanitizers).
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// What a person is told it is, one line, e.g. "file 'frames/' (12 frames)", "libcamera camera 0 (imx219)",
  /// "V4L2 camera /dev/video0 (HD Webcam)".
  virtual std::string name() const = 0;
  /// Waits at most timeout_s for the next frame. False on time-out (out untouched).
  /// The file source never times out: after its last frame it serves the last frame again (a camera keeps
  /// seeing the scene), with times going on at file_fps.
  /// @throws CameraError when the source failed (unplugged, a frame that cannot be decoded or is too large).
  virtual bool next(Frame& out, double timeout_s) = 0;
  /// A still for reading a page: one frame at the largest size the camera gives (libcamera: its StillCapture
  /// configuration at the size the camera proposes for it, the sensor's full resolution; V4L2: the largest frame
  /// size the device lists for the pixel format in use), after which the source streams at its preview size
  /// again. Waits at most timeout_s for the still's frame; false on time-out (the preview streams again all the
  /// same). The file source, which has no larger frame, gives its next frame.
  /// @throws CameraError when the camera cannot be set to the still's size or back (the source may then be
  ///         unusable: its next() throws too).
  virtual bool still(Frame& out, double timeout_s) { return next(out, timeout_s); }
};

/// Opens the source a spec names.
/// A file source checks at open what it can without decoding a folder: a single image is loaded (load_image,
/// with max_file_bytes = params.max_frame_bytes), a folder is listed (its regular files whose header is an
/// image, sorted by name); each folder frame is decoded when next() reaches it, so a bad frame is a
/// CameraError from next() naming its file.
/// @throws CameraError for a source that cannot be opened (no such file or camera, no usable format), and for
///         a file source with no readable image (a folder: none of its files is an image; files that are not
///         images are skipped, an image refused by load_image's limits is an error naming it).
/// @throws hk::ArgumentError if a parameter is outside the range its docstring gives.
std::unique_ptr<FrameSource> open_frame_source(const SourceSpec& spec, const FrameSourceParams& params);

/// A camera found on this machine.
struct CameraInfo {
  std::string spec;     ///< how to open it: "libcamera:0", "v4l2:/dev/video0"
  std::string name;     ///< its model, as the backend reports it (libcamera's "model" property, V4L2's card)
  std::string backend;  ///< "libcamera" or "v4l2"
};

/// Every camera libcamera enumerates (in its order: the N of libcamera:N, at most 64), then every V4L2 device
/// node /dev/video* with the video-capture capability (in number order). Never throws;
/// empty when there is none (no camera is a clean, quiet path: nothing printed, nothing leaked). The
/// libcamera part uses the process's one CameraManager (libcamera allows only one per process).
std::vector<CameraInfo> list_cameras();

}  // namespace hk::vision
