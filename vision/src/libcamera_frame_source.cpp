// The libcamera frame source ("libcamera:N", vision/frame_source.hpp), written against libcamera 0.0.3 (Debian
// 12, libcamera-dev).
//
// libcamera allows one CameraManager per process (a second one is a fatal error), so there is one here,
// created and started on first use and kept (see ProcessCameraManager). A source acquires its camera,
// configures one StillCapture stream in a format OpenCV can convert, allocates the stream's buffers, maps
// each dmabuf once, and keeps one request per buffer queued: libcamera completes requests on its own thread,
// where on_request_completed copies the frame into a mutex-protected slot (the latest frame wins) and queues
// the request again. next() waits on the slot and converts the copied bytes to BGR on the caller's thread.
// still() stops the camera, configures the stream at the size libcamera proposes for a still (the sensor's
// full resolution), takes one frame after the exposure has settled, and configures the preview again.
// Written from libcamera's documentation; no camera was at hand to try still() on.

#include <linux/dma-buf.h>
#include <sys/ioctl.h>
#include <sys/mman.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <libcamera/camera.h>
#include <libcamera/camera_manager.h>
#include <libcamera/formats.h>
#include <libcamera/framebuffer.h>
#include <libcamera/framebuffer_allocator.h>
#include <libcamera/logging.h>
#include <libcamera/property_ids.h>
#include <libcamera/request.h>
#include <libcamera/stream.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "frame_sources.hpp"
#include "input_error.hpp"
#include "vision/frame_source.hpp"

namespace hk::vision::detail {
namespace {

namespace lc = libcamera;

/// The process's one libcamera CameraManager.
///
/// Created and started on first use (list or open) and then kept, so that cameras keep their libcamera
/// indices and hot-plugged ones appear. A start that fails (no media devices, no sysfs) is not kept: the next
/// use tries again. libcamera's own log output is switched off before the manager is made (the kiosk reports
/// its own one-line errors; with no camera nothing is printed), unless the operator asked for it with
/// LIBCAMERA_LOG_LEVELS or LIBCAMERA_LOG_FILE.
///
/// Shutdown: this bookkeeping object is never destroyed (a source destroyed late during exit can still report
/// that it closed). Once the manager has started, a function-local static "stopper" is made; static objects
/// are destroyed in the reverse order of their construction, so it runs at exit before the libcamera statics
/// that were made while the manager started. It then deletes the manager when no source holds a camera (the
/// destructor stops libcamera's thread and frees everything: LeakSanitizer sees nothing) and refuses to start
/// another. When a source is still open at exit (leaked, or owned by a static destroyed later), the manager is
/// left running and reachable from here, since stopping it under an acquired camera is not allowed.
class ProcessCameraManager {
 public:
  static ProcessCameraManager& instance() {
    static ProcessCameraManager* const m = new ProcessCameraManager;  // never deleted, see above
    return *m;
  }

  /// The cameras libcamera enumerates, in its order; empty when the manager cannot start (or exit began).
  std::vector<std::shared_ptr<lc::Camera>> cameras() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (manager_ == nullptr) {
      if (exiting_) return {};
      auto m = std::make_unique<lc::CameraManager>();
      if (m->start() != 0) return {};
      manager_ = m.release();
      stop_at_exit_after_libcamera_statics();
    }
    return manager_->cameras();
  }

  /// A source holds (or is about to acquire) a camera: the manager must not be stopped.
  void source_opened() {
    const std::lock_guard<std::mutex> lock(mutex_);
    ++open_sources_;
  }
  /// The source has released its camera and dropped every libcamera object.
  void source_closed() {
    const std::lock_guard<std::mutex> lock(mutex_);
    --open_sources_;
  }

  ProcessCameraManager(const ProcessCameraManager&) = delete;
  ProcessCameraManager& operator=(const ProcessCameraManager&) = delete;

 private:
  ProcessCameraManager() {
    if (std::getenv("LIBCAMERA_LOG_LEVELS") == nullptr && std::getenv("LIBCAMERA_LOG_FILE") == nullptr) {
      lc::logSetTarget(lc::LoggingTargetNone);
    }
  }
  ~ProcessCameraManager() = default;

  /// Registers (once) the exit-time stop; called right after the first successful start.
  static void stop_at_exit_after_libcamera_statics() {
    struct Stopper {
      Stopper() = default;
      Stopper(const Stopper&) = delete;
      Stopper& operator=(const Stopper&) = delete;
      ~Stopper() { instance().stop_at_exit(); }
    };
    static const Stopper stopper;
  }

  void stop_at_exit() {
    const std::lock_guard<std::mutex> lock(mutex_);
    exiting_ = true;
    if (manager_ != nullptr && open_sources_ == 0) {
      delete manager_;  // stops libcamera's thread
      manager_ = nullptr;
    }
  }

  std::mutex mutex_;
  lc::CameraManager* manager_ = nullptr;  ///< started, or null; owned (raw so that exit can choose to keep it)
  int open_sources_ = 0;
  bool exiting_ = false;
};

/// How a libcamera pixel format becomes BGR, in order of preference (least work first).
enum class Conversion { Copy, SwapRB, DropX, DropXSwapRB, Yuyv, Nv12, Jpeg };

struct FormatChoice {
  lc::PixelFormat format;
  Conversion conversion;
};

// libcamera's formats are DRM fourccs, little-endian: RGB888 is B, G, R in memory (OpenCV's BGR), BGR888 is
// R, G, B, XRGB8888 is B, G, R, X (libcamera formats.yaml / include/uapi/drm/drm_fourcc.h).
const std::vector<FormatChoice>& format_choices() {
  static const std::vector<FormatChoice> choices = {
      {lc::formats::RGB888, Conversion::Copy},    {lc::formats::BGR888, Conversion::SwapRB},
      {lc::formats::XRGB8888, Conversion::DropX}, {lc::formats::XBGR8888, Conversion::DropXSwapRB},
      {lc::formats::YUYV, Conversion::Yuyv},      {lc::formats::NV12, Conversion::Nv12},
      {lc::formats::MJPEG, Conversion::Jpeg},
  };
  return choices;
}

std::optional<Conversion> conversion_of(const lc::PixelFormat& f) {
  for (const FormatChoice& c : format_choices()) {
    if (c.format == f) return c.conversion;
  }
  return std::nullopt;
}

/// The camera's model property, else its id; control characters escaped.
std::string camera_model(const lc::Camera& camera) {
  const std::optional<std::string> model = camera.properties().get(lc::properties::Model);
  return hk::one_line(model && !model->empty() ? *model : camera.id());
}

double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

class LibcameraFrameSource final : public FrameSource {
 public:
  LibcameraFrameSource(SourceSpec spec, const FrameSourceParams& params) : spec_(std::move(spec)), params_(params) {}

  ~LibcameraFrameSource() override {
    stopping_.store(true);
    if (started_) camera_->stop();  // completes every pending request as cancelled, on libcamera's thread
    if (connected_) {
      camera_->requestCompleted.disconnect(this);
      camera_->disconnected.disconnect(this);
    }
    requests_.clear();
    for (const auto& [fd, m] : maps_) ::munmap(m.first, m.second);
    maps_.clear();
    if (allocator_ != nullptr && stream_ != nullptr) allocator_->free(stream_);
    allocator_.reset();
    config_.reset();
    if (acquired_) camera_->release();
    camera_.reset();
    if (registered_) ProcessCameraManager::instance().source_closed();
  }

  LibcameraFrameSource(const LibcameraFrameSource&) = delete;
  LibcameraFrameSource& operator=(const LibcameraFrameSource&) = delete;

  /// Acquires, configures and starts the camera. On a throw the destructor undoes what was done.
  void open() {
    ProcessCameraManager& manager = ProcessCameraManager::instance();
    manager.source_opened();
    registered_ = true;
    const std::vector<std::shared_ptr<lc::Camera>> cameras = manager.cameras();
    const auto index = static_cast<std::size_t>(spec_.index);
    if (index >= cameras.size()) {
      fail(cameras.empty() ? std::string("no such camera (libcamera found none)")
                           : "no such camera (libcamera found " + std::to_string(cameras.size()) + ")");
    }
    camera_ = cameras[index];
    model_ = camera_model(*camera_);
    const int acquired = camera_->acquire();
    if (acquired == -EBUSY) fail("busy (in use by another program)");
    if (acquired != 0) fail("cannot acquire: " + errno_text(-acquired));
    acquired_ = true;

    configure(false);
    allocate_and_map();

    camera_->requestCompleted.connect(this, &LibcameraFrameSource::on_request_completed);
    camera_->disconnected.connect(this, &LibcameraFrameSource::on_disconnected);
    connected_ = true;
    start_and_queue();
  }

  bool still(Frame& out, double timeout_s) override {
    // The size libcamera proposes for a still: the sensor's full resolution.
    const std::unique_ptr<lc::CameraConfiguration> probe =
        camera_->generateConfiguration({lc::StreamRole::StillCapture});
    const lc::Size full = probe && !probe->empty() ? probe->at(0).size : lc::Size();
    if (static_cast<std::uint64_t>(full.width) * full.height <=
        static_cast<std::uint64_t>(width_) * static_cast<std::uint64_t>(height_))
      return next(out, timeout_s);  // the preview is the largest it gives
    return still_between(
        *this, out, timeout_s, [this] { restart(true); }, [this] { restart(false); });
  }

  std::string name() const override { return "libcamera camera " + std::to_string(spec_.index) + " (" + model_ + ")"; }

  bool next(Frame& out, double timeout_s) override {
    using Clock = std::chrono::steady_clock;
    const double wait_s =
        std::isfinite(timeout_s) ? std::clamp(timeout_s, 0.0, 86400.0) : (timeout_s > 0 ? 86400.0 : 0.0);
    const auto deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait_s));
    double t_s = 0.0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (!ready_.wait_until(lock, deadline, [&] { return slot_full_ || !failure_.empty(); })) return false;
      if (!failure_.empty()) fail(failure_);
      std::swap(work_, slot_);
      slot_full_ = false;
      t_s = slot_t_s_;
      work_planes_ = slot_planes_;
    }
    cv::Mat bgr = convert();
    out.bgr = std::move(bgr);
    out.t_s = t_s;
    out.index = next_index_++;
    return true;
  }

 private:
  /// Where one plane of one buffer is in this process.
  struct PlaneView {
    const std::uint8_t* data = nullptr;
    std::size_t length = 0;
    int fd = -1;
  };

  [[noreturn]] void fail(const std::string& problem) const { throw_camera_error(spec_, problem); }

  /// Starts the camera and queues every request.
  void start_and_queue() {
    const int started = camera_->start();
    if (started != 0) fail("cannot start: " + errno_text(-started));
    started_ = true;
    for (const std::unique_ptr<lc::Request>& r : requests_) {
      const int queued = camera_->queueRequest(r.get());
      if (queued != 0) fail("cannot queue a capture request: " + errno_text(-queued));
    }
  }

  /// Stops the camera, gives its buffers back and starts it again configured for a still at its full size
  /// (`full`) or for the preview at the requested size.
  void restart(bool full) {
    stopping_.store(true);
    if (started_) camera_->stop();  // completes every pending request as cancelled
    started_ = false;
    stopping_.store(false);
    requests_.clear();
    planes_.clear();
    for (const auto& [fd, m] : maps_) ::munmap(m.first, m.second);
    maps_.clear();
    if (allocator_ != nullptr && stream_ != nullptr) allocator_->free(stream_);
    allocator_.reset();
    stream_ = nullptr;
    config_.reset();
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      slot_full_ = false;
    }
    configure(full);
    allocate_and_map();
    start_and_queue();
  }

  /// The StillCapture stream in a format OpenCV converts, at its proposed size (`full`: the sensor's) or the
  /// requested preview size.
  void configure(bool full) {
    config_ = camera_->generateConfiguration({lc::StreamRole::StillCapture});
    if (config_ == nullptr || config_->empty()) config_ = camera_->generateConfiguration({lc::StreamRole::Viewfinder});
    if (config_ == nullptr || config_->empty()) fail("no still-capture configuration");
    lc::StreamConfiguration& cfg = config_->at(0);

    const std::vector<lc::PixelFormat> offered = cfg.formats().pixelformats();
    std::optional<lc::PixelFormat> chosen;
    for (const FormatChoice& c : format_choices()) {
      if (std::find(offered.begin(), offered.end(), c.format) != offered.end()) {
        chosen = c.format;
        break;
      }
    }
    if (!chosen && offered.empty() && conversion_of(cfg.pixelFormat)) chosen = cfg.pixelFormat;
    if (!chosen) {
      std::string list;
      for (const lc::PixelFormat& f : offered) list += (list.empty() ? "" : ", ") + f.toString();
      fail("no usable pixel format (offers " + (list.empty() ? std::string("none") : hk::one_line(list)) +
           "; RGB888, BGR888, XRGB8888, XBGR8888, YUYV, NV12 or MJPEG needed)");
    }
    cfg.pixelFormat = *chosen;
    if (!full) cfg.size = lc::Size(static_cast<unsigned>(params_.width_px), static_cast<unsigned>(params_.height_px));
    if (config_->validate() == lc::CameraConfiguration::Invalid) fail("the stream configuration was refused");
    const std::optional<Conversion> conversion = conversion_of(cfg.pixelFormat);
    if (!conversion) fail("the camera changed the pixel format to " + hk::one_line(cfg.pixelFormat.toString()));
    conversion_ = *conversion;
    width_ = static_cast<int>(cfg.size.width);
    height_ = static_cast<int>(cfg.size.height);
    if (width_ <= 0 || height_ <= 0 || width_ > 16384 || height_ > 16384) {
      fail("the camera gave an unusable frame size " + std::to_string(width_) + " x " + std::to_string(height_) +
           " px");
    }
    if ((conversion_ == Conversion::Yuyv || conversion_ == Conversion::Nv12) && (width_ % 2 != 0)) {
      fail("the camera gave an odd width of " + std::to_string(width_) + " px");
    }
    if (conversion_ == Conversion::Nv12 && height_ % 2 != 0) {
      fail("the camera gave an odd NV12 height of " + std::to_string(height_) + " px");
    }
    stride_ = cfg.stride != 0 ? cfg.stride : static_cast<unsigned>(width_) * bytes_per_pixel();
    if (conversion_ != Conversion::Jpeg && stride_ < static_cast<unsigned>(width_) * bytes_per_pixel()) {
      fail("the camera gave a line of " + std::to_string(stride_) + " bytes for " + std::to_string(width_) + " px");
    }
    const int configured = camera_->configure(config_.get());
    if (configured != 0) fail("cannot configure: " + errno_text(-configured));
    stream_ = cfg.stream();
    if (stream_ == nullptr) fail("cannot configure: no stream");
  }

  unsigned bytes_per_pixel() const {
    switch (conversion_) {
      case Conversion::Copy:
      case Conversion::SwapRB:
        return 3;
      case Conversion::DropX:
      case Conversion::DropXSwapRB:
        return 4;
      case Conversion::Yuyv:
        return 2;
      case Conversion::Nv12:
      case Conversion::Jpeg:
        return 1;
    }
    return 1;
  }

  /// Allocates the stream's buffers, maps each dmabuf once (all planes of a buffer usually share one), and
  /// makes one request per buffer.
  void allocate_and_map() {
    allocator_ = std::make_unique<lc::FrameBufferAllocator>(camera_);
    const int allocated = allocator_->allocate(stream_);
    if (allocated < 0) fail("cannot allocate frame buffers: " + errno_text(-allocated));
    const std::vector<std::unique_ptr<lc::FrameBuffer>>& buffers = allocator_->buffers(stream_);
    if (buffers.empty()) fail("cannot allocate frame buffers: none");

    // The extent of each dmabuf that the planes use.
    std::map<int, std::size_t> extent;
    const auto max_bytes = static_cast<std::uint64_t>(params_.max_frame_bytes);
    for (const std::unique_ptr<lc::FrameBuffer>& b : buffers) {
      std::uint64_t total = 0;
      for (const lc::FrameBuffer::Plane& p : b->planes()) {
        if (!p.fd.isValid() || p.offset == lc::FrameBuffer::Plane::kInvalidOffset || p.length == 0) {
          fail("the camera gave a frame buffer without a usable plane");
        }
        total += p.length;
        std::size_t& e = extent[p.fd.get()];
        e = std::max<std::size_t>(e, static_cast<std::size_t>(p.offset) + p.length);
      }
      if (total > max_bytes) {
        fail("frame buffer of " + std::to_string(total) + " bytes exceeds the limit of " + std::to_string(max_bytes) +
             " bytes");
      }
    }
    for (const auto& [fd, length] : extent) {
      void* addr = ::mmap(nullptr, length, PROT_READ, MAP_SHARED, fd, 0);
      if (addr == MAP_FAILED) fail("cannot map a frame buffer: " + errno_text(errno));
      maps_.emplace(fd, std::make_pair(addr, length));
    }
    for (const std::unique_ptr<lc::FrameBuffer>& b : buffers) {
      std::vector<PlaneView> views;
      for (const lc::FrameBuffer::Plane& p : b->planes()) {
        const auto* base = static_cast<const std::uint8_t*>(maps_.at(p.fd.get()).first);
        views.push_back(PlaneView{base + p.offset, p.length, p.fd.get()});
      }
      planes_.emplace(b.get(), std::move(views));

      std::unique_ptr<lc::Request> request = camera_->createRequest();
      if (request == nullptr) fail("cannot create a capture request");
      const int added = request->addBuffer(stream_, b.get());
      if (added != 0) fail("cannot attach a frame buffer to a request: " + errno_text(-added));
      requests_.push_back(std::move(request));
    }
  }

  /// libcamera's thread: a request is done. Copies its frame into the slot and queues the request again.
  void on_request_completed(lc::Request* request) {
    if (request->status() == lc::Request::RequestCancelled || stopping_.load()) return;
    const lc::FrameBuffer* buffer = request->findBuffer(stream_);
    if (buffer != nullptr && buffer->metadata().status == lc::FrameMetadata::FrameSuccess) copy_out(*buffer);
    request->reuse(lc::Request::ReuseBuffers);
    if (stopping_.load()) return;
    const int queued = camera_->queueRequest(request);
    if (queued != 0 && !stopping_.load()) {
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (failure_.empty()) failure_ = "cannot queue a capture request again: " + errno_text(-queued);
      }
      ready_.notify_one();
    }
  }

  void copy_out(const lc::FrameBuffer& buffer) {
    const auto it = planes_.find(&buffer);
    if (it == planes_.end()) return;
    const lc::FrameMetadata& meta = buffer.metadata();
    const auto used = meta.planes();
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      slot_.clear();
      slot_planes_.clear();
      for (std::size_t i = 0; i < it->second.size(); ++i) {
        const PlaneView& p = it->second[i];
        std::size_t n = p.length;
        if (i < used.size() && used[i].bytesused != 0) {
          if (used[i].bytesused > p.length) {
            if (failure_.empty()) {
              failure_ = "frame of " + std::to_string(used[i].bytesused) + " bytes exceeds its buffer of " +
                         std::to_string(p.length) + " bytes";
            }
            break;
          }
          n = used[i].bytesused;
        }
        sync_dmabuf(p.fd, DMA_BUF_SYNC_START | DMA_BUF_SYNC_READ);
        slot_.insert(slot_.end(), p.data, p.data + n);
        sync_dmabuf(p.fd, DMA_BUF_SYNC_END | DMA_BUF_SYNC_READ);
        slot_planes_.push_back(n);
      }
      slot_t_s_ = meta.timestamp != 0 ? static_cast<double>(meta.timestamp) * 1e-9 : steady_now_s();
      slot_full_ = failure_.empty();
    }
    ready_.notify_one();
  }

  /// Cache coherence around a CPU read of a dmabuf; a buffer that is not a dmabuf ignores it.
  static void sync_dmabuf(int fd, std::uint64_t flags) {
    dma_buf_sync sync{};
    sync.flags = flags;
    int r;
    do {
      r = ::ioctl(fd, DMA_BUF_IOCTL_SYNC, &sync);
    } while (r == -1 && errno == EINTR);
  }

  /// libcamera's thread: the camera went away.
  void on_disconnected() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (failure_.empty()) failure_ = "disconnected (unplugged?)";
    }
    ready_.notify_one();
  }

  /// work_ (the planes of one frame, back to back) as BGR.
  cv::Mat convert() const {
    const std::size_t plane0 = work_planes_.empty() ? 0 : work_planes_[0];
    switch (conversion_) {
      case Conversion::Copy:
      case Conversion::SwapRB:
      case Conversion::DropX:
      case Conversion::DropXSwapRB:
      case Conversion::Yuyv:
        return convert_packed(plane0);
      case Conversion::Nv12:
        return convert_nv12(plane0);
      case Conversion::Jpeg:
        return convert_jpeg(plane0);
    }
    return {};
  }

  /// Fails with the frame's size against the `need` bytes its format takes.
  [[noreturn]] void short_frame(std::size_t need) const {
    fail("frame " + std::to_string(next_index_) + " is " + std::to_string(work_.size()) + " bytes, " +
         std::to_string(need) + " expected");
  }

  /// Packed pixels in the first plane (`plane0` bytes): RGB, BGR, XRGB-style or YUYV, as BGR.
  cv::Mat convert_packed(std::size_t plane0) const {
    const auto h = static_cast<std::size_t>(height_);
    const std::size_t need = stride_ * (h - 1) + static_cast<std::size_t>(width_) * bytes_per_pixel();
    if (plane0 < need) short_frame(need);
    const int type = conversion_ == Conversion::Yuyv ? CV_8UC2 : (bytes_per_pixel() == 4 ? CV_8UC4 : CV_8UC3);
    auto* data = const_cast<std::uint8_t*>(work_.data());  // cv::Mat header over bytes it does not change
    const cv::Mat src(height_, width_, type, data, stride_);
    cv::Mat bgr;
    switch (conversion_) {
      case Conversion::Copy:
        bgr = src.clone();
        break;
      case Conversion::SwapRB:
        cv::cvtColor(src, bgr, cv::COLOR_RGB2BGR);
        break;
      case Conversion::DropX:
        cv::cvtColor(src, bgr, cv::COLOR_BGRA2BGR);
        break;
      case Conversion::DropXSwapRB:
        cv::cvtColor(src, bgr, cv::COLOR_RGBA2BGR);
        break;
      default:
        cv::cvtColor(src, bgr, cv::COLOR_YUV2BGR_YUYV);
        break;
    }
    return bgr;
  }

  /// NV12 as BGR: Y, height lines, then interleaved UV, height / 2 lines, each stride bytes (in one plane or
  /// two; the first `plane0` bytes long).
  cv::Mat convert_nv12(std::size_t plane0) const {
    const auto h = static_cast<std::size_t>(height_);
    const std::size_t luma = stride_ * h;
    const std::size_t chroma_lines = h / 2;
    const std::size_t need_uv = stride_ * (chroma_lines - 1) + static_cast<std::size_t>(width_);
    const std::uint8_t* uv = nullptr;
    if (work_planes_.size() >= 2) {
      if (plane0 < stride_ * (h - 1) + static_cast<std::size_t>(width_)) short_frame(luma + need_uv);
      if (work_planes_[1] < need_uv) short_frame(luma + need_uv);
      uv = work_.data() + plane0;
    } else {
      if (plane0 < luma + need_uv) short_frame(luma + need_uv);
      uv = work_.data() + luma;
    }
    cv::Mat packed(height_ + height_ / 2, width_, CV_8UC1);
    for (int y = 0; y < height_; ++y) {
      std::memcpy(packed.ptr(y), work_.data() + stride_ * static_cast<std::size_t>(y),
                  static_cast<std::size_t>(width_));
    }
    for (int y = 0; y < height_ / 2; ++y) {
      std::memcpy(packed.ptr(height_ + y), uv + stride_ * static_cast<std::size_t>(y),
                  static_cast<std::size_t>(width_));
    }
    cv::Mat bgr;
    cv::cvtColor(packed, bgr, cv::COLOR_YUV2BGR_NV12);
    return bgr;
  }

  /// One MJPEG frame of `plane0` bytes, decoded to BGR under [camera]'s frame size limit.
  cv::Mat convert_jpeg(std::size_t plane0) const {
    if (plane0 == 0) short_frame(1);
    if (static_cast<std::int64_t>(plane0) > params_.max_frame_bytes) {
      fail("frame of " + std::to_string(plane0) + " bytes exceeds the limit of " +
           std::to_string(params_.max_frame_bytes) + " bytes");
    }
    auto* data = const_cast<std::uint8_t*>(work_.data());  // cv::Mat header over bytes it does not change
    const cv::Mat jpeg(1, static_cast<int>(plane0), CV_8UC1, data);
    cv::Mat bgr;
    try {
      bgr = cv::imdecode(jpeg, cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
      bgr.release();
    }
    if (bgr.empty() || bgr.type() != CV_8UC3) {
      fail("frame " + std::to_string(next_index_) + " (" + std::to_string(plane0) +
           " bytes of MJPEG) cannot be decoded");
    }
    return bgr;
  }

  SourceSpec spec_;
  FrameSourceParams params_;
  std::shared_ptr<lc::Camera> camera_;
  std::string model_;
  bool registered_ = false;
  bool acquired_ = false;
  bool connected_ = false;
  bool started_ = false;
  std::atomic<bool> stopping_{false};
  std::unique_ptr<lc::CameraConfiguration> config_;
  lc::Stream* stream_ = nullptr;
  Conversion conversion_ = Conversion::Copy;
  int width_ = 0;
  int height_ = 0;
  std::size_t stride_ = 0;
  std::unique_ptr<lc::FrameBufferAllocator> allocator_;
  std::map<int, std::pair<void*, std::size_t>> maps_;  ///< dmabuf fd -> (address, length), each mapped once
  std::map<const lc::FrameBuffer*, std::vector<PlaneView>> planes_;
  std::vector<std::unique_ptr<lc::Request>> requests_;

  std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<std::uint8_t> slot_;        ///< the latest frame's planes, back to back (guarded by mutex_)
  std::vector<std::size_t> slot_planes_;  ///< their sizes [bytes] (guarded by mutex_)
  double slot_t_s_ = 0.0;                 ///< its capture time [s] (guarded by mutex_)
  bool slot_full_ = false;                ///< a frame waits in the slot (guarded by mutex_)
  std::string failure_;                   ///< why the camera stopped, once it has (guarded by mutex_)
  std::vector<std::uint8_t> work_;        ///< the frame being converted (caller's thread)
  std::vector<std::size_t> work_planes_;
  std::uint64_t next_index_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> open_libcamera_source(const SourceSpec& spec, const FrameSourceParams& params) {
  auto source = std::make_unique<LibcameraFrameSource>(spec, params);
  source->open();
  return source;
}

void list_libcamera_cameras(std::vector<CameraInfo>& out) {
  const std::vector<std::shared_ptr<lc::Camera>> cameras = ProcessCameraManager::instance().cameras();
  for (std::size_t i = 0; i < cameras.size() && i < 64; ++i) {
    out.push_back(CameraInfo{"libcamera:" + std::to_string(i), camera_model(*cameras[i]), "libcamera"});
  }
}

}  // namespace hk::vision::detail
