// The V4L2 frame source ("v4l2:DEV", vision/frame_source.hpp): raw ioctls on a video-capture node, MMAP
// streaming with four buffers, YUYV converted or MJPEG decoded with OpenCV. References: the Linux kernel's
// "Video for Linux API" (uAPI) documentation, sections "Querying Capabilities", "Image Format Negotiation",
// "Streaming I/O (Memory Mapping)" and "Buffers" (timestamp flags). still() stops streaming, sets the largest
// frame size the device lists (VIDIOC_ENUM_FRAMESIZES), takes one frame after the exposure has settled, and sets
// the preview size again. No camera was at hand to try still() on.

#include <dirent.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "frame_sources.hpp"
#include "input_error.hpp"
#include "vision/frame_source.hpp"

namespace hk::vision::detail {
namespace {

constexpr unsigned kBufferCount = 4;

/// ioctl, retried while interrupted by a signal.
int xioctl(int fd, unsigned long request, void* arg) {
  int r;
  do {
    r = ::ioctl(fd, request, arg);
  } while (r == -1 && errno == EINTR);
  return r;
}

/// open(2) for reading and writing, non-blocking, close-on-exec; retried while interrupted.
int open_node(const std::string& path) {
  int fd;
  do {
    fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  } while (fd == -1 && errno == EINTR);
  return fd;
}

/// The capabilities of the node itself (device_caps when the driver reports them, else the whole device's).
std::uint32_t node_caps(const v4l2_capability& cap) {
  return (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
}

/// A fixed-size, possibly unterminated driver string (card, driver), control characters escaped.
std::string driver_string(const std::uint8_t* s, std::size_t size) {
  const auto* c = reinterpret_cast<const char*>(s);
  return hk::one_line(std::string(c, strnlen(c, size)));
}

/// "YUYV", "MJPG", ...: a fourcc as text, unprintable bytes as '?'.
std::string fourcc_text(std::uint32_t f) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const auto b = static_cast<unsigned char>((f >> (8 * i)) & 0xFF);
    s += (b >= 0x20 && b < 0x7F) ? static_cast<char>(b) : '?';
  }
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

/// Whether the node offers pixel format `fourcc` at exactly width x height.
bool has_frame_size(int fd, std::uint32_t fourcc, std::uint32_t width, std::uint32_t height) {
  for (std::uint32_t i = 0; i < 256; ++i) {
    v4l2_frmsizeenum fs{};
    fs.index = i;
    fs.pixel_format = fourcc;
    if (xioctl(fd, VIDIOC_ENUM_FRAMESIZES, &fs) != 0) return false;
    if (fs.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
      if (fs.discrete.width == width && fs.discrete.height == height) return true;
      continue;
    }
    // Stepwise or continuous: one range (index 0 only).
    const v4l2_frmsize_stepwise& s = fs.stepwise;
    const std::uint32_t sw = std::max<std::uint32_t>(s.step_width, 1);
    const std::uint32_t sh = std::max<std::uint32_t>(s.step_height, 1);
    return width >= s.min_width && width <= s.max_width && height >= s.min_height && height <= s.max_height &&
           (width - s.min_width) % sw == 0 && (height - s.min_height) % sh == 0;
  }
  return false;
}

/// The largest frame size (by area) the node lists for pixel format `fourcc`; {0, 0} when it lists none.
std::pair<std::uint32_t, std::uint32_t> largest_frame_size(int fd, std::uint32_t fourcc) {
  std::pair<std::uint32_t, std::uint32_t> best{0, 0};
  const auto area = [](std::pair<std::uint32_t, std::uint32_t> s) {
    return static_cast<std::uint64_t>(s.first) * s.second;
  };
  for (std::uint32_t i = 0; i < 256; ++i) {
    v4l2_frmsizeenum fs{};
    fs.index = i;
    fs.pixel_format = fourcc;
    if (xioctl(fd, VIDIOC_ENUM_FRAMESIZES, &fs) != 0) break;
    const std::pair<std::uint32_t, std::uint32_t> size = fs.type == V4L2_FRMSIZE_TYPE_DISCRETE
                                                             ? std::pair{fs.discrete.width, fs.discrete.height}
                                                             : std::pair{fs.stepwise.max_width, fs.stepwise.max_height};
    if (area(size) > area(best)) best = size;
    if (fs.type != V4L2_FRMSIZE_TYPE_DISCRETE) break;  // stepwise or continuous: one range (index 0 only)
  }
  return best;
}

/// One mmap'ed driver buffer.
struct Mapping {
  void* start = MAP_FAILED;
  std::size_t length = 0;
};

class V4l2FrameSource final : public FrameSource {
 public:
  V4l2FrameSource(SourceSpec spec, const FrameSourceParams& params) : spec_(std::move(spec)), params_(params) {}

  ~V4l2FrameSource() override {
    stop_streaming();
    if (fd_ >= 0) ::close(fd_);
  }

  V4l2FrameSource(const V4l2FrameSource&) = delete;
  V4l2FrameSource& operator=(const V4l2FrameSource&) = delete;

  /// Opens the node, negotiates the format and starts streaming. On a throw the destructor undoes what was done.
  void open() {
    fd_ = open_node(spec_.path);
    if (fd_ < 0) fail("cannot open: " + errno_text(errno));
    struct stat st {};
    if (::fstat(fd_, &st) != 0) fail("cannot open: " + errno_text(errno));
    if (!S_ISCHR(st.st_mode)) fail("not a video device (not a character device)");

    v4l2_capability cap{};
    if (xioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0) fail("not a V4L2 device (VIDIOC_QUERYCAP: " + errno_text(errno) + ")");
    card_ = driver_string(cap.card, sizeof cap.card);
    const std::uint32_t caps = node_caps(cap);
    if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) {
      if ((caps & V4L2_CAP_VIDEO_CAPTURE_MPLANE) != 0) fail("multi-planar capture devices are not supported");
      fail("not a video capture device");
    }
    if ((caps & V4L2_CAP_STREAMING) == 0) fail("does not support streaming I/O");

    choose_format();
    start_streaming(static_cast<std::uint32_t>(params_.width_px), static_cast<std::uint32_t>(params_.height_px));
  }

  bool still(Frame& out, double timeout_s) override {
    const auto [w, h] = largest_frame_size(fd_, pixel_format_);
    if (static_cast<std::uint64_t>(w) * h <= static_cast<std::uint64_t>(width_) * static_cast<std::uint64_t>(height_))
      return next(out, timeout_s);  // the preview is the largest it gives
    const auto size_for = [this](std::uint32_t width, std::uint32_t height) {
      return [this, width, height] {
        stop_streaming();
        start_streaming(width, height);
      };
    };
    return still_between(
        *this, out, timeout_s, size_for(w, h),
        size_for(static_cast<std::uint32_t>(params_.width_px), static_cast<std::uint32_t>(params_.height_px)));
  }

  std::string name() const override { return "V4L2 camera " + hk::one_line(spec_.path) + " (" + card_ + ")"; }

  bool next(Frame& out, double timeout_s) override {
    if (requeue_failed_) fail("VIDIOC_QBUF: " + errno_text(requeue_errno_));
    using Clock = std::chrono::steady_clock;
    const double wait_s =
        std::isfinite(timeout_s) ? std::clamp(timeout_s, 0.0, 86400.0) : (timeout_s > 0 ? 86400.0 : 0.0);
    const auto deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait_s));
    for (;;) {
      const double left_s = std::chrono::duration<double>(deadline - Clock::now()).count();
      const int left_ms = left_s <= 0.0 ? 0 : static_cast<int>(std::ceil(left_s * 1000.0));
      pollfd p{fd_, POLLIN, 0};
      const int r = ::poll(&p, 1, left_ms);
      if (r < 0) {
        if (errno == EINTR) continue;
        fail("poll: " + errno_text(errno));
      }
      if (r == 0) return false;
      if ((p.revents & POLLIN) == 0) {
        if ((p.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) fail("stopped delivering frames (unplugged?)");
        continue;
      }
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      if (xioctl(fd_, VIDIOC_DQBUF, &b) != 0) {
        if (errno == EAGAIN) {
          if (left_ms == 0) return false;
          continue;
        }
        fail("VIDIOC_DQBUF: " + errno_text(errno));
      }
      if (b.index >= buffers_.size())
        fail("VIDIOC_DQBUF returned buffer " + std::to_string(b.index) + " of " + std::to_string(buffers_.size()));
      const Requeue requeue(*this, b.index);
      if ((b.flags & V4L2_BUF_FLAG_ERROR) != 0) continue;  // a corrupted frame: wait for the next one
      cv::Mat bgr;
      if (!convert(b, bgr)) continue;
      out.bgr = std::move(bgr);
      out.t_s = frame_time_s(b);
      out.index = next_index_++;
      return true;
    }
  }

 private:
  /// Queues a dequeued buffer again at the end of the scope; a failure is reported by the next next().
  class Requeue {
   public:
    Requeue(V4l2FrameSource& s, std::uint32_t index) : s_(s), index_(index) {}
    ~Requeue() {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      b.index = index_;
      if (xioctl(s_.fd_, VIDIOC_QBUF, &b) != 0) {
        s_.requeue_failed_ = true;
        s_.requeue_errno_ = errno;
      }
    }
    Requeue(const Requeue&) = delete;
    Requeue& operator=(const Requeue&) = delete;

   private:
    V4l2FrameSource& s_;
    std::uint32_t index_;
  };

  [[noreturn]] void fail(const std::string& problem) const { throw_camera_error(spec_, problem); }

  /// YUYV when it has the requested size (or when there is no MJPEG), else MJPEG.
  void choose_format() {
    bool yuyv = false;
    bool mjpeg = false;
    std::string offered;
    for (std::uint32_t i = 0; i < 256; ++i) {
      v4l2_fmtdesc d{};
      d.index = i;
      d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      if (xioctl(fd_, VIDIOC_ENUM_FMT, &d) != 0) break;
      yuyv = yuyv || d.pixelformat == V4L2_PIX_FMT_YUYV;
      mjpeg = mjpeg || d.pixelformat == V4L2_PIX_FMT_MJPEG;
      offered += (offered.empty() ? "" : ", ") + fourcc_text(d.pixelformat);
    }
    const auto w = static_cast<std::uint32_t>(params_.width_px);
    const auto h = static_cast<std::uint32_t>(params_.height_px);
    if (yuyv && (!mjpeg || has_frame_size(fd_, V4L2_PIX_FMT_YUYV, w, h))) {
      pixel_format_ = V4L2_PIX_FMT_YUYV;
    } else if (mjpeg) {
      pixel_format_ = V4L2_PIX_FMT_MJPEG;
    } else {
      fail("no usable pixel format (offers " + (offered.empty() ? std::string("none") : offered) +
           "; YUYV or MJPG needed)");
    }
  }

  /// Sets the format at `width` x `height` (the driver may give the nearest it has), maps the buffers, queues
  /// them and starts streaming.
  void start_streaming(std::uint32_t width, std::uint32_t height) {
    set_format(width, height);
    map_buffers();
    for (std::uint32_t i = 0; i < buffers_.size(); ++i) {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      b.index = i;
      if (xioctl(fd_, VIDIOC_QBUF, &b) != 0) fail("VIDIOC_QBUF: " + errno_text(errno));
    }
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(fd_, VIDIOC_STREAMON, &type) != 0) fail("VIDIOC_STREAMON: " + errno_text(errno));
    streaming_ = true;
  }

  /// Stops streaming and gives the buffers back (a format can be set again after).
  void stop_streaming() {
    if (streaming_) {
      int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      (void)xioctl(fd_, VIDIOC_STREAMOFF, &type);
      streaming_ = false;
    }
    for (const Mapping& m : buffers_)
      if (m.start != MAP_FAILED) ::munmap(m.start, m.length);
    buffers_.clear();
    if (buffers_requested_) {
      v4l2_requestbuffers req{};
      req.count = 0;
      req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      req.memory = V4L2_MEMORY_MMAP;
      (void)xioctl(fd_, VIDIOC_REQBUFS, &req);
      buffers_requested_ = false;
    }
    requeue_failed_ = false;
  }

  void set_format(std::uint32_t width, std::uint32_t height) {
    v4l2_format f{};
    f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    f.fmt.pix.width = width;
    f.fmt.pix.height = height;
    f.fmt.pix.pixelformat = pixel_format_;
    f.fmt.pix.field = V4L2_FIELD_ANY;
    if (xioctl(fd_, VIDIOC_S_FMT, &f) != 0) {
      if (errno == EBUSY) fail("busy (in use by another program)");
      fail("VIDIOC_S_FMT: " + errno_text(errno));
    }
    if (f.fmt.pix.pixelformat != pixel_format_) {
      fail("the driver gave pixel format " + fourcc_text(f.fmt.pix.pixelformat) + " instead of " +
           fourcc_text(pixel_format_));
    }
    const std::uint32_t w = f.fmt.pix.width;
    const std::uint32_t h = f.fmt.pix.height;
    if (w == 0 || h == 0 || w > 16384 || h > 16384) {
      fail("the driver gave an unusable frame size " + std::to_string(w) + " x " + std::to_string(h) + " px");
    }
    width_ = static_cast<int>(w);
    height_ = static_cast<int>(h);
    bytes_per_line_ = f.fmt.pix.bytesperline;
    if (pixel_format_ == V4L2_PIX_FMT_YUYV) {
      if (w % 2 != 0) fail("the driver gave an odd YUYV width of " + std::to_string(w) + " px");
      if (bytes_per_line_ == 0) bytes_per_line_ = 2 * w;
      if (bytes_per_line_ < 2 * w)
        fail("the driver gave a YUYV line of " + std::to_string(bytes_per_line_) + " bytes for " + std::to_string(w) +
             " px");
    }
  }

  void map_buffers() {
    v4l2_requestbuffers req{};
    req.count = kBufferCount;
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd_, VIDIOC_REQBUFS, &req) != 0) {
      if (errno == EBUSY) fail("busy (in use by another program)");
      fail("VIDIOC_REQBUFS: " + errno_text(errno));
    }
    buffers_requested_ = true;
    if (req.count < 2) fail("the driver gave " + std::to_string(req.count) + " buffer(s); at least 2 are needed");
    const auto max_bytes = static_cast<std::uint64_t>(params_.max_frame_bytes);
    const std::uint64_t yuyv_bytes = static_cast<std::uint64_t>(bytes_per_line_) * static_cast<std::uint64_t>(height_);
    buffers_.reserve(req.count);
    for (std::uint32_t i = 0; i < req.count; ++i) {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      b.index = i;
      if (xioctl(fd_, VIDIOC_QUERYBUF, &b) != 0) fail("VIDIOC_QUERYBUF: " + errno_text(errno));
      if (b.length == 0) fail("the driver gave an empty frame buffer");
      if (b.length > max_bytes) {
        fail("frame buffer of " + std::to_string(b.length) + " bytes exceeds the limit of " +
             std::to_string(max_bytes) + " bytes");
      }
      if (pixel_format_ == V4L2_PIX_FMT_YUYV && b.length < yuyv_bytes) {
        fail("frame buffer of " + std::to_string(b.length) + " bytes is smaller than a YUYV frame (" +
             std::to_string(yuyv_bytes) + " bytes)");
      }
      Mapping m;
      m.length = b.length;
      m.start = ::mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, b.m.offset);
      if (m.start == MAP_FAILED) fail("mmap of frame buffer " + std::to_string(i) + ": " + errno_text(errno));
      buffers_.push_back(m);
    }
  }

  /// The dequeued buffer as BGR. False for a frame to skip (empty or short: the camera dropped it).
  /// @throws CameraError for an MJPEG frame that is too large or cannot be decoded.
  bool convert(const v4l2_buffer& b, cv::Mat& bgr) const {
    const Mapping& m = buffers_[b.index];
    if (b.bytesused > m.length) {
      fail("frame of " + std::to_string(b.bytesused) + " bytes exceeds its buffer of " + std::to_string(m.length) +
           " bytes");
    }
    if (pixel_format_ == V4L2_PIX_FMT_YUYV) {
      const std::uint64_t need = static_cast<std::uint64_t>(bytes_per_line_) * static_cast<std::uint64_t>(height_);
      if (b.bytesused != 0 && b.bytesused < need) return false;
      const cv::Mat yuyv(height_, width_, CV_8UC2, m.start, bytes_per_line_);
      cv::cvtColor(yuyv, bgr, cv::COLOR_YUV2BGR_YUYV);
      return true;
    }
    if (b.bytesused == 0) return false;
    if (static_cast<std::int64_t>(b.bytesused) > params_.max_frame_bytes) {
      fail("frame of " + std::to_string(b.bytesused) + " bytes exceeds the limit of " +
           std::to_string(params_.max_frame_bytes) + " bytes");
    }
    const cv::Mat jpeg(1, static_cast<int>(b.bytesused), CV_8UC1, m.start);
    try {
      bgr = cv::imdecode(jpeg, cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
      bgr.release();
    }
    if (bgr.empty() || bgr.type() != CV_8UC3) {
      fail("frame " + std::to_string(next_index_) + " (" + std::to_string(b.bytesused) +
           " bytes of MJPEG) cannot be decoded");
    }
    return true;
  }

  /// The buffer's capture time when the driver stamps it on CLOCK_MONOTONIC, else the time it was taken [s]
  /// (steady_clock, which on Linux is CLOCK_MONOTONIC too).
  static double frame_time_s(const v4l2_buffer& b) {
    if ((b.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC &&
        (b.timestamp.tv_sec != 0 || b.timestamp.tv_usec != 0)) {
      return static_cast<double>(b.timestamp.tv_sec) + 1e-6 * static_cast<double>(b.timestamp.tv_usec);
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }

  SourceSpec spec_;
  FrameSourceParams params_;
  int fd_ = -1;
  std::string card_;
  std::uint32_t pixel_format_ = 0;
  int width_ = 0;
  int height_ = 0;
  std::uint32_t bytes_per_line_ = 0;
  std::vector<Mapping> buffers_;
  bool buffers_requested_ = false;
  bool streaming_ = false;
  bool requeue_failed_ = false;
  int requeue_errno_ = 0;
  std::uint64_t next_index_ = 0;
};

/// The number after "video" in a node name, or -1 when the rest is not all digits.
long video_number(const std::string& name) {
  const std::string digits = name.substr(5);
  if (digits.empty() || digits.size() > 9) return -1;
  for (const char c : digits) {
    if (c < '0' || c > '9') return -1;
  }
  return std::stol(digits);
}

}  // namespace

std::unique_ptr<FrameSource> open_v4l2_source(const SourceSpec& spec, const FrameSourceParams& params) {
  auto source = std::make_unique<V4l2FrameSource>(spec, params);
  source->open();
  return source;
}

void list_v4l2_cameras(std::vector<CameraInfo>& out) {
  std::vector<std::string> names;
  if (DIR* dir = ::opendir("/dev")) {
    while (const dirent* e = ::readdir(dir)) {
      const std::string n = e->d_name;
      if (n.rfind("video", 0) == 0) names.push_back(n);
    }
    ::closedir(dir);
  }
  // Number order (video2 before video10); names that are not "video<digits>" after, by name.
  std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
    const long na = video_number(a);
    const long nb = video_number(b);
    if ((na < 0) != (nb < 0)) return na >= 0;
    if (na != nb) return na < nb;
    return a < b;
  });
  for (const std::string& n : names) {
    const std::string path = "/dev/" + n;
    const int fd = open_node(path);
    if (fd < 0) continue;
    v4l2_capability cap{};
    const bool ok = xioctl(fd, VIDIOC_QUERYCAP, &cap) == 0 && (node_caps(cap) & V4L2_CAP_VIDEO_CAPTURE) != 0;
    ::close(fd);
    if (!ok) continue;
    out.push_back(CameraInfo{"v4l2:" + path, driver_string(cap.card, sizeof cap.card), "v4l2"});
  }
}

}  // namespace hk::vision::detail
