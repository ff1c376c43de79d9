// load_image: the checked path from a file name to BGR pixels.
//
// The file is read into memory once and everything (header, limits, JPEG completeness,
// decoding) works on those bytes, so a file swapped on the USB stick between the check and the
// decode cannot slip past the limits. OpenCV's logger is silenced while decoding because the
// kiosk reports refusals itself, in one line, and its log must not fill with decoder chatter.

#include <algorithm>
#include <climits>
#include <fstream>
#include <mutex>
#include <span>
#include <vector>

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>

#include "hk/error.hpp"
#include "image_header_detail.hpp"
#include "input_error.hpp"

namespace hk::vision {
namespace {

/// Silences OpenCV's logger for its lifetime. Nested and concurrent guards share one count so
/// the level saved by the first is restored by the last.
class QuietOpenCvLog {
 public:
  QuietOpenCvLog() {
    const std::lock_guard<std::mutex> lock(mutex());
    if (count()++ == 0) saved() = cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  }
  ~QuietOpenCvLog() {
    const std::lock_guard<std::mutex> lock(mutex());
    if (--count() == 0) cv::utils::logging::setLogLevel(saved());
  }
  QuietOpenCvLog(const QuietOpenCvLog&) = delete;
  QuietOpenCvLog& operator=(const QuietOpenCvLog&) = delete;

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static int& count() {
    static int c = 0;
    return c;
  }
  static cv::utils::logging::LogLevel& saved() {
    static cv::utils::logging::LogLevel level = cv::utils::logging::LOG_LEVEL_WARNING;
    return level;
  }
};

/// The whole file, which was measured at `expected` bytes (already checked against the limit).
std::vector<std::uint8_t> read_all(const std::string& path, std::uint64_t expected) {
  std::ifstream f(path, std::ios::binary);
  if (!f) detail::throw_input_error(path, "cannot open the file for reading");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(expected));
  f.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  const bool short_read = static_cast<std::uint64_t>(f.gcount()) != expected;
  if (short_read || f.peek() != std::ifstream::traits_type::eof()) {
    detail::throw_input_error(path, "the file changed size while being read");
  }
  return bytes;
}

}  // namespace

namespace detail {

cv::Mat composite_over_white(const cv::Mat& bgra) {
  cv::Mat f;
  bgra.convertTo(f, CV_32F, bgra.depth() == CV_16U ? 1.0 / 65535.0 : 1.0 / 255.0);
  cv::Mat out(bgra.size(), CV_8UC3);
  for (int y = 0; y < f.rows; ++y) {
    const auto* src = f.ptr<cv::Vec4f>(y);
    auto* dst = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < f.cols; ++x) {
      const float a = src[x][3];
      for (int c = 0; c < 3; ++c) dst[x][c] = cv::saturate_cast<std::uint8_t>(255.0f * (a * src[x][c] + 1.0f - a));
    }
  }
  return out;
}

}  // namespace detail

int decode_reduction_for(int width_px, int height_px, int keep_side_px) {
  if (keep_side_px <= 0) return 1;
  const std::int64_t side = std::max(width_px, height_px);
  int scale = 1;
  for (int f = 2; f <= 8; f *= 2) {
    if ((side + f - 1) / f >= keep_side_px) scale = f;  // libjpeg's scaled size rounds up
  }
  return scale;
}

cv::Mat load_image(const std::string& path, const ImageLimits& limits) {
  if (limits.max_file_bytes <= 0 || limits.max_width_px <= 0 || limits.max_height_px <= 0 || limits.max_pixels <= 0) {
    throw hk::ArgumentError("load_image: every ImageLimits field must be positive");
  }
  return decode_image(read_input_file(path, limits.max_file_bytes), path, limits);
}

DecodedImage load_image_reduced(const std::string& path, const ImageLimits& limits, int keep_side_px) {
  if (limits.max_file_bytes <= 0 || limits.max_width_px <= 0 || limits.max_height_px <= 0 || limits.max_pixels <= 0) {
    throw hk::ArgumentError("load_image_reduced: every ImageLimits field must be positive");
  }
  return decode_image_reduced(read_input_file(path, limits.max_file_bytes), path, limits, keep_side_px);
}

std::vector<std::uint8_t> read_input_file(const std::string& path, std::int64_t max_bytes) {
  if (max_bytes <= 0) throw hk::ArgumentError("read_input_file: max_bytes must be positive");
  const std::uint64_t size = detail::checked_file_size(path);
  if (size > static_cast<std::uint64_t>(max_bytes)) {
    detail::throw_input_error(path, "file size " + std::to_string(size) + " bytes exceeds the limit of " +
                                        std::to_string(max_bytes) + " bytes");
  }
  return read_all(path, size);
}

cv::Mat decode_image(std::span<const std::uint8_t> bytes, const std::string& path, const ImageLimits& limits) {
  if (limits.max_file_bytes <= 0 || limits.max_width_px <= 0 || limits.max_height_px <= 0 || limits.max_pixels <= 0) {
    throw hk::ArgumentError("decode_image: every ImageLimits field must be positive");
  }
  return decode_image_reduced(bytes, path, limits, 0).bgr;
}

namespace {

/// The header of `bytes`, checked before any pixel is decoded: declared width, height and pixel count
/// within `limits`, and a JPEG's stream reaching its end-of-image marker. Throws InputError naming `path`.
detail::HeaderDetails checked_header(std::span<const std::uint8_t> bytes, const std::string& path,
                                     const ImageLimits& limits) {
  detail::MemorySource src(bytes);
  detail::HeaderDetails hd = detail::parse_image_header(src, path);
  const ImageHeader& h = hd.header;
  const std::string declared =
      "declared size " + std::to_string(h.width_px) + " x " + std::to_string(h.height_px) + " px";
  if (h.width_px > limits.max_width_px || h.height_px > limits.max_height_px) {
    detail::throw_input_error(path, declared + " exceeds the limit of " + std::to_string(limits.max_width_px) + " x " +
                                        std::to_string(limits.max_height_px) + " px");
  }
  const std::int64_t pixels = std::int64_t{h.width_px} * h.height_px;
  if (pixels > limits.max_pixels) {
    detail::throw_input_error(path, declared + " (" + std::to_string(pixels) + " pixels) exceeds the limit of " +
                                        std::to_string(limits.max_pixels) + " pixels");
  }
  if (h.format == "jpeg" && !detail::jpeg_is_complete(bytes)) {
    detail::throw_input_error(path,
                              "truncated or corrupt JPEG: the stream does not reach its end-of-image marker (0xFFD9)");
  }
  return hd;
}

}  // namespace

namespace {

/// `bytes` decoded by OpenCV at 1/scale (libjpeg's DCT scaling for a JPEG; other formats at scale 1) and,
/// when the format may carry alpha, composited over white from a second decode with the alpha channel.
/// Empty when OpenCV cannot decode it.
cv::Mat decoded_by_opencv(std::span<const std::uint8_t> bytes, const detail::HeaderDetails& hd, int scale) {
  const int flags = scale == 8   ? cv::IMREAD_REDUCED_COLOR_8
                    : scale == 4 ? cv::IMREAD_REDUCED_COLOR_4
                    : scale == 2 ? cv::IMREAD_REDUCED_COLOR_2
                                 : cv::IMREAD_COLOR;
  const QuietOpenCvLog quiet;
  const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<std::uint8_t*>(bytes.data()));
  cv::Mat bgr;
  try {
    bgr = cv::imdecode(buffer, flags);
  } catch (const cv::Exception&) {
    return {};
  }
  if (bgr.empty() || !hd.may_have_alpha || scale != 1) return bgr;
  cv::Mat with_alpha;
  try {
    with_alpha = cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    return bgr;  // keep the colour decode
  }
  const bool usable = with_alpha.channels() == 4 && with_alpha.size() == bgr.size() &&
                      (with_alpha.depth() == CV_8U || with_alpha.depth() == CV_16U);
  return usable ? detail::composite_over_white(with_alpha) : bgr;
}

}  // namespace

DecodedImage decode_image_reduced(std::span<const std::uint8_t> bytes, const std::string& path,
                                  const ImageLimits& limits, int keep_side_px) {
  if (limits.max_file_bytes <= 0 || limits.max_width_px <= 0 || limits.max_height_px <= 0 || limits.max_pixels <= 0) {
    throw hk::ArgumentError("decode_image_reduced: every ImageLimits field must be positive");
  }
  if (bytes.empty()) detail::throw_input_error(path, "empty file (0 bytes)");
  if (bytes.size() > static_cast<std::uint64_t>(limits.max_file_bytes)) {
    detail::throw_input_error(path, "file size " + std::to_string(bytes.size()) + " bytes exceeds the limit of " +
                                        std::to_string(limits.max_file_bytes) + " bytes");
  }
  const detail::HeaderDetails hd = checked_header(bytes, path, limits);
  const ImageHeader& h = hd.header;
  const std::string declared =
      "declared size " + std::to_string(h.width_px) + " x " + std::to_string(h.height_px) + " px";

  std::vector<std::uint8_t> png_storage;
  std::span<const std::uint8_t> to_decode = bytes;
  if (h.format == "png") to_decode = detail::png_decodable(bytes, path, png_storage);
  if (to_decode.size() > static_cast<std::size_t>(INT_MAX)) {  // cv::Mat's column count is an int
    detail::throw_input_error(path, "file too large for the decoder (over 2 GiB)");
  }
  // libjpeg decodes less for a reduced size (DCT scaling). A PNG read by rows is averaged as it is read, so
  // its full-size pixels are never held, and libpng's reason for refusing it reaches the message instead of
  // stderr. Other decoders would decode in full and resize.
  const bool png_by_rows = h.format == "png" && detail::png_decodes_by_rows(to_decode);
  const int scale = h.format == "jpeg" || png_by_rows ? decode_reduction_for(h.width_px, h.height_px, keep_side_px) : 1;
  const cv::Mat bgr =
      png_by_rows ? detail::decode_png_by_rows(to_decode, path, scale) : decoded_by_opencv(to_decode, hd, scale);
  if (bgr.empty()) {
    detail::throw_input_error(path, "the " + h.format + " data could not be decoded (corrupt or unsupported)");
  }
  const int want_w = (h.width_px + scale - 1) / scale, want_h = (h.height_px + scale - 1) / scale;
  const bool as_declared = bgr.cols == want_w && bgr.rows == want_h;
  const bool transposed = bgr.cols == want_h && bgr.rows == want_w;  // EXIF rotation
  if (!as_declared && !transposed) {
    detail::throw_input_error(path, "decoded size " + std::to_string(bgr.cols) + " x " + std::to_string(bgr.rows) +
                                        " px differs from the " + declared +
                                        (scale > 1 ? " reduced to 1/" + std::to_string(scale) : std::string()));
  }
  if (bgr.type() != CV_8UC3) {
    detail::throw_input_error(path, "decoder returned an unexpected pixel type");
  }
  DecodedImage out;
  out.bgr = bgr;
  out.file_width_px = as_declared ? h.width_px : h.height_px;
  out.file_height_px = as_declared ? h.height_px : h.width_px;
  out.scale = scale;
  out.format = h.format;
  return out;
}

}  // namespace hk::vision
