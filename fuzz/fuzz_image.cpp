// Fuzz harness: image files from a stranger's stick (vision/intake.hpp).
//
// Entry points: hk::vision::decode_image (in memory: header, limits, JPEG completeness, PNG chunk check,
// OpenCV decode), hk::vision::decode_image_reduced (the same at a reduced size: libjpeg's DCT scaling, a PNG
// read by rows with libpng) and hk::vision::read_image_header (the same header parser reading a file lazily, here a
// memfd). Properties:
//  - decode_image returns a CV_8UC3 image of the declared size (or transposed, EXIF) within the limits,
//    or throws InputError whose what() is one line "image '<name, escaped>': <problem>"; nothing else;
//  - decode_image_reduced returns ceil(file size / scale) pixels, scale 1, 2, 4 or 8, the file's size being
//    decode_image's where both decode; or throws InputError as above;
//  - read_image_header on the same bytes agrees with decode_image's header: it accepts a file whose
//    decode succeeded, and with the same dimensions.
// Limits are lower than the kiosk's (4096 x 4096 px, 4 MP) so that a run decodes in milliseconds.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include "fuzz_common.hpp"
#include "vision/intake.hpp"

namespace {

// A hostile-looking name: the message must escape it.
const std::string kName = "stick/evil\n\x1b[31m.png";
const std::string kShown = "image 'stick/evil\\x0A\\x1B[31m.png': ";

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  cv::setNumThreads(1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static hk::fuzz::MemFile file;
  hk::vision::ImageLimits limits;
  limits.max_file_bytes = 1 << 20;
  limits.max_width_px = 4096;
  limits.max_height_px = 4096;
  limits.max_pixels = 4'000'000;

  const std::span<const std::uint8_t> bytes(data, size);
  bool decoded = false;
  int rows = 0, cols = 0;
  try {
    const cv::Mat bgr = hk::vision::decode_image(bytes, kName, limits);
    FUZZ_CHECK(!bgr.empty() && bgr.type() == CV_8UC3, "");
    // Within the limits as declared, or transposed by an EXIF rotation.
    FUZZ_CHECK((bgr.cols <= limits.max_width_px && bgr.rows <= limits.max_height_px) ||
                   (bgr.rows <= limits.max_width_px && bgr.cols <= limits.max_height_px),
               std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows));
    FUZZ_CHECK(static_cast<std::int64_t>(bgr.cols) * bgr.rows <= limits.max_pixels, std::to_string(bgr.rows));
    decoded = true;
    rows = bgr.rows;
    cols = bgr.cols;
  } catch (const hk::vision::InputError& e) {
    const std::string what = e.what();
    FUZZ_CHECK(hk::fuzz::is_one_line(what), what);
    FUZZ_CHECK(what.starts_with(kShown), what);
    FUZZ_CHECK(what.size() > kShown.size(), what);
  }

  // A reduced decode (libjpeg's DCT scaling, a PNG read by rows) keeps the same promises, at 1/scale of the
  // full size; and where both decode, the file's own size is the full decode's.
  try {
    const hk::vision::DecodedImage d = hk::vision::decode_image_reduced(bytes, kName, limits, 64);
    FUZZ_CHECK(!d.bgr.empty() && d.bgr.type() == CV_8UC3, d.format);
    FUZZ_CHECK(d.scale == 1 || d.scale == 2 || d.scale == 4 || d.scale == 8, std::to_string(d.scale));
    FUZZ_CHECK(d.bgr.cols == (d.file_width_px + d.scale - 1) / d.scale &&
                   d.bgr.rows == (d.file_height_px + d.scale - 1) / d.scale,
               d.format + " " + std::to_string(d.bgr.cols) + "x" + std::to_string(d.bgr.rows) + " at 1/" +
                   std::to_string(d.scale));
    if (decoded) FUZZ_CHECK(d.file_width_px == cols && d.file_height_px == rows, d.format);
  } catch (const hk::vision::InputError& e) {
    const std::string what = e.what();
    FUZZ_CHECK(hk::fuzz::is_one_line(what), what);
    FUZZ_CHECK(what.starts_with(kShown), what);
  }

  // The lazy file reader must agree with the in-memory one.
  const std::string& path = file.set(data, size);
  try {
    const hk::vision::ImageHeader h = hk::vision::read_image_header(path);
    FUZZ_CHECK(h.width_px > 0 && h.height_px > 0, h.format);
    FUZZ_CHECK(h.format == "png" || h.format == "jpeg" || h.format == "bmp" || h.format == "tiff" || h.format == "webp",
               h.format);
    if (decoded) {
      FUZZ_CHECK((h.width_px == cols && h.height_px == rows) || (h.width_px == rows && h.height_px == cols),
                 h.format + " " + std::to_string(h.width_px) + "x" + std::to_string(h.height_px));
    }
  } catch (const hk::vision::InputError& e) {
    const std::string what = e.what();
    FUZZ_CHECK(hk::fuzz::is_one_line(what), what);
    FUZZ_CHECK(what.starts_with("image '" + path + "': "), what);
    FUZZ_CHECK(!decoded, what);
  }
  return 0;
}
