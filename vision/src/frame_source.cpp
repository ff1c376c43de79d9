// Frame sources (vision/frame_source.hpp): the spec parser, the dispatch to the three sources and the camera
// list. The sources themselves are in file_frame_source.cpp, v4l2_frame_source.cpp and
// libcamera_frame_source.cpp.

#include "vision/frame_source.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <system_error>

#include "frame_sources.hpp"
#include "hk/error.hpp"
#include "input_error.hpp"

namespace hk::vision {

namespace detail {

void throw_camera_error(const SourceSpec& spec, const std::string& problem) {
  throw CameraError("camera '" + hk::one_line(spec.str()) + "': " + problem);
}

std::string errno_text(int err) { return std::system_category().message(err); }

}  // namespace detail

namespace {

constexpr const char* kExpectedKinds = "expected file:PATH, libcamera:N or v4l2:DEV";

[[noreturn]] void throw_spec_error(const std::string& spec, const std::string& problem) {
  throw CameraError("camera source '" + hk::one_line(spec) + "': " + problem);
}

/// A non-negative decimal integer written with digits only (no sign, no space), or -1.
int parse_decimal(const std::string& text) {
  if (text.empty() || text.size() > 9) return -1;
  for (const char c : text) {
    if (c < '0' || c > '9') return -1;
  }
  int value = -1;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return -1;
  return value;
}

void check_params(const SourceSpec& spec, const FrameSourceParams& p) {
  const auto bad = [&](const std::string& what) {
    throw hk::ArgumentError("camera '" + hk::one_line(spec.str()) + "': " + what);
  };
  if (p.width_px < 64 || p.width_px > 8192) bad("width_px " + std::to_string(p.width_px) + " is outside [64, 8192]");
  if (p.height_px < 64 || p.height_px > 8192)
    bad("height_px " + std::to_string(p.height_px) + " is outside [64, 8192]");
  if (!(std::isfinite(p.file_fps) && p.file_fps > 0.0 && p.file_fps <= 1000.0)) {
    bad("file_fps " + std::to_string(p.file_fps) + " is outside (0, 1000]");
  }
  if (p.max_frame_bytes <= 0) bad("max_frame_bytes " + std::to_string(p.max_frame_bytes) + " is not positive");
}

}  // namespace

std::string SourceSpec::str() const {
  switch (kind) {
    case Kind::File:
      return "file:" + path;
    case Kind::Libcamera:
      return "libcamera:" + std::to_string(index);
    case Kind::V4l2:
      return "v4l2:" + path;
  }
  return "?";
}

SourceSpec parse_source_spec(const std::string& spec) {
  const std::size_t colon = spec.find(':');
  if (colon == std::string::npos) throw_spec_error(spec, std::string("unknown kind (") + kExpectedKinds + ")");
  const std::string kind = spec.substr(0, colon);
  const std::string rest = spec.substr(colon + 1);
  if (kind != "file" && kind != "libcamera" && kind != "v4l2") {
    throw_spec_error(spec, std::string("unknown kind (") + kExpectedKinds + ")");
  }
  if (rest.find('\0') != std::string::npos) throw_spec_error(spec, "contains a NUL byte");

  SourceSpec out;
  if (kind == "file") {
    if (rest.empty()) throw_spec_error(spec, "empty path (expected file:PATH)");
    out.kind = SourceSpec::Kind::File;
    out.path = rest;
  } else if (kind == "libcamera") {
    const int index = parse_decimal(rest);
    if (index < 0 || index > 63) {
      throw_spec_error(spec, "bad camera index (expected libcamera:N with N a decimal integer from 0 to 63)");
    }
    out.kind = SourceSpec::Kind::Libcamera;
    out.index = index;
  } else {
    if (rest.empty()) throw_spec_error(spec, "empty device (expected v4l2:/dev/videoN or v4l2:N)");
    out.kind = SourceSpec::Kind::V4l2;
    if (rest.front() == '/') {
      out.path = rest;
    } else {
      const int n = parse_decimal(rest);
      if (n < 0)
        throw_spec_error(spec, "bad device (expected a path starting with '/' or a number: v4l2:/dev/video0, v4l2:0)");
      out.path = "/dev/video" + std::to_string(n);
    }
  }
  return out;
}

std::unique_ptr<FrameSource> open_frame_source(const SourceSpec& spec, const FrameSourceParams& params) {
  check_params(spec, params);
  if (spec.path.find('\0') != std::string::npos) detail::throw_camera_error(spec, "the path contains a NUL byte");
  switch (spec.kind) {
    case SourceSpec::Kind::File:
      if (spec.path.empty()) detail::throw_camera_error(spec, "empty path");
      return detail::open_file_source(spec, params);
    case SourceSpec::Kind::Libcamera:
      if (spec.index < 0 || spec.index > 63) detail::throw_camera_error(spec, "camera index outside [0, 63]");
      return detail::open_libcamera_source(spec, params);
    case SourceSpec::Kind::V4l2:
      if (spec.path.empty()) detail::throw_camera_error(spec, "empty device path");
      return detail::open_v4l2_source(spec, params);
  }
  detail::throw_camera_error(spec, "unknown kind");
}

std::vector<CameraInfo> list_cameras() {
  std::vector<CameraInfo> out;
  try {
    detail::list_libcamera_cameras(out);
  } catch (...) {
    // Only an allocation failure gets here; the list stays what it was.
  }
  try {
    detail::list_v4l2_cameras(out);
  } catch (...) {
  }
  return out;
}

bool detail::still_between(FrameSource& source, Frame& out, double timeout_s, const std::function<void()>& to_still,
                           const std::function<void()>& back) {
  to_still();
  bool got = false;
  std::exception_ptr failed;
  try {
    for (int dropped = 0; (got = source.next(out, timeout_s)) && dropped < kStillSettleFrames; ++dropped) {
    }
  } catch (const CameraError&) {
    failed = std::current_exception();
  }
  back();
  if (failed) std::rethrow_exception(failed);
  return got;
}

}  // namespace hk::vision
