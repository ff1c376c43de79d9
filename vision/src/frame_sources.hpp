#pragma once
// Private to the vision library: the three frame sources behind vision/frame_source.hpp (file, libcamera,
// V4L2), opened by open_frame_source and listed by list_cameras, and the one-line CameraError messages they
// share.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "vision/frame_source.hpp"

namespace hk::vision::detail {

/// "camera '<spec, control characters escaped>': <problem>" as a CameraError. problem must be one line.
[[noreturn]] void throw_camera_error(const SourceSpec& spec, const std::string& problem);

/// A camera's still (FrameSource::still) between `to_still` and `back`, which set its size for the still and back
/// to the preview (both may throw CameraError): kStillSettleFrames frames dropped while the exposure settles, the
/// next kept in `out`, and `back` called whatever happened, a CameraError from the frames thrown after it. False
/// when no frame came within `timeout_s` [s].
bool still_between(FrameSource& source, Frame& out, double timeout_s, const std::function<void()>& to_still,
                   const std::function<void()>& back);

/// Frames dropped after a camera's size changes for a still, while its exposure settles.
inline constexpr int kStillSettleFrames = 2;

/// strerror(err) as a std::string (thread-safe).
std::string errno_text(int err);

/// The file source (file_frame_source.cpp). spec.kind must be File; params already checked.
/// @throws CameraError as open_frame_source.
std::unique_ptr<FrameSource> open_file_source(const SourceSpec& spec, const FrameSourceParams& params);

/// The V4L2 source (v4l2_frame_source.cpp). spec.kind must be V4l2; params already checked.
/// @throws CameraError as open_frame_source.
std::unique_ptr<FrameSource> open_v4l2_source(const SourceSpec& spec, const FrameSourceParams& params);

/// The libcamera source (libcamera_frame_source.cpp). spec.kind must be Libcamera; params already checked.
/// @throws CameraError as open_frame_source.
std::unique_ptr<FrameSource> open_libcamera_source(const SourceSpec& spec, const FrameSourceParams& params);

/// Appends every V4L2 device node /dev/video* with the video-capture capability, in number order. Nodes that
/// cannot be opened or queried are left out; only std::bad_alloc can escape.
void list_v4l2_cameras(std::vector<CameraInfo>& out);

/// Appends every camera libcamera enumerates, in libcamera's order (the N of "libcamera:N"). Nothing is
/// appended when the camera manager cannot start; only std::bad_alloc can escape.
void list_libcamera_cameras(std::vector<CameraInfo>& out);

}  // namespace hk::vision::detail
