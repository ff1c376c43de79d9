// A PNG decoded with libpng a strip of rows at a time, each block of scale x scale pixels averaged as the
// strip arrives (decode_png_by_rows). Every PNG that can be read by rows is decoded here, at any scale, so
// that libpng's reason for refusing a file reaches its one-line message rather than stderr.
//
// Why not cv::imdecode and then cv::resize: a 13-megapixel photo PNG is 40 MB of BGR that the scene never
// uses (it is built at 800 px and shown at the screen's side). Writing those 40 MB into fresh pages cost
// about as much as inflating the PNG on the kiosk's machine, and the picture's later shrinking passes read
// them again. Averaging strip by strip keeps a few hundred kilobytes in flight; libpng still inflates every
// byte (PNG has no cheaper reduced decode, unlike libjpeg's DCT scaling).
//
// libpng reports errors by longjmp. The one function that calls libpng after setjmp (read_reduced) keeps
// no object with a destructor alive across a libpng call: every buffer is owned by its caller.

#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>

#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"
#include "hk/text.hpp"
#include "image_header_detail.hpp"
#include "input_error.hpp"
#include "vision/png_chunks.hpp"

namespace hk::vision::detail {
namespace {

constexpr int kStripInputRows = 64;  ///< rows of the file read between two averagings (rounded to whole blocks)

/// libpng's input (the checked bytes in memory) and its last error message.
struct PngInput {
  std::span<const std::uint8_t> bytes;
  std::size_t pos = 0;
  char error[160] = {};  ///< copied before the jump back, so that path allocates nothing
};

void read_bytes(png_structp png, png_bytep out, png_size_t n) {
  auto* in = static_cast<PngInput*>(png_get_io_ptr(png));
  if (n > in->bytes.size() - in->pos) png_error(png, "the file ends inside its image data");
  std::memcpy(out, in->bytes.data() + in->pos, n);
  in->pos += n;
}

[[noreturn]] void on_error(png_structp png, png_const_charp message) {
  auto* in = static_cast<PngInput*>(png_get_error_ptr(png));
  std::snprintf(in->error, sizeof in->error, "%s", message);
  png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // ancillary-chunk complaints: the pixels are unaffected

/// libpng's read and info structs, destroyed together.
struct PngReader {
  png_structp png = nullptr;
  png_infop info = nullptr;
  PngReader(const PngReader&) = delete;
  PngReader& operator=(const PngReader&) = delete;
  explicit PngReader(PngInput& in) {
    png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &in, on_error, on_warning);
    if (png != nullptr) info = png_create_info_struct(png);
    if (png != nullptr) png_set_read_fn(png, &in, read_bytes);
  }
  ~PngReader() { png_destroy_read_struct(&png, &info, nullptr); }
};

/// Sets libpng's transformations as OpenCV's PNG decoder does for IMREAD_COLOR, or for IMREAD_UNCHANGED
/// when the picture has alpha (an alpha channel, or tRNS on RGB or palette: what OpenCV decodes as 4
/// channels), and returns the row pixels' type: CV_8UC3, CV_8UC4 or CV_16UC4 (native byte order).
int set_transformations(png_structp png, png_infop info) {
  const int colour = png_get_color_type(png, info);
  const int depth = png_get_bit_depth(png, info);
  const bool trns = png_get_valid(png, info, PNG_INFO_tRNS) != 0;
  const bool alpha = (colour & PNG_COLOR_MASK_ALPHA) != 0 ||
                     (trns && (colour == PNG_COLOR_TYPE_RGB || colour == PNG_COLOR_TYPE_PALETTE));
  if (depth == 16 && !alpha) png_set_strip_16(png);
  if (depth == 16 && alpha) png_set_swap(png);  // PNG's samples are big-endian; cv::Mat's are native
  if (alpha) png_set_tRNS_to_alpha(png);
  if (!alpha) png_set_strip_alpha(png);
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((colour & PNG_COLOR_MASK_COLOR) == 0 && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if ((colour & PNG_COLOR_MASK_COLOR) != 0) png_set_bgr(png);
  if ((colour & PNG_COLOR_MASK_COLOR) == 0) png_set_gray_to_rgb(png);
  png_read_update_info(png, info);
  return !alpha ? CV_8UC3 : depth == 16 ? CV_16UC4 : CV_8UC4;
}

/// Completes the strip's last block: columns past `width` repeat column width - 1 in rows [0, rows_read),
/// and rows [rows_read, strip.rows) repeat row rows_read - 1.
void pad_strip(cv::Mat& strip, int rows_read, int width) {
  const std::size_t px = strip.elemSize();
  for (int r = 0; r < rows_read; ++r) {
    std::uint8_t* row = strip.ptr(r);
    for (int x = width; x < strip.cols; ++x) std::memcpy(row + x * px, row + (width - 1) * px, px);
  }
  for (int r = rows_read; r < strip.rows; ++r) std::memcpy(strip.ptr(r), strip.ptr(rows_read - 1), strip.cols * px);
}

/// Buffers read_reduced fills; owned by its caller so that a longjmp skips no destructor.
struct Strips {
  cv::Mat raw;      ///< rows as libpng delivers them, padded to whole blocks
  cv::Mat bgr;      ///< raw composited over white (pictures with alpha)
  cv::Mat reduced;  ///< one strip averaged
};

/// Reads the image, strip by strip, into `out` (CV_8UC3, ceil(w / scale) x ceil(h / scale)). False when
/// libpng reported an error (its message is in the PngInput).
bool read_reduced(PngReader& reader, int scale, Strips& s, cv::Mat& out) {
  png_structp png = reader.png;
  png_infop info = reader.info;
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  const int width = static_cast<int>(png_get_image_width(png, info));
  const int height = static_cast<int>(png_get_image_height(png, info));
  const int type = set_transformations(png, info);
  if (png_get_rowbytes(png, info) != static_cast<std::size_t>(width) * CV_ELEM_SIZE(type)) {
    png_error(png, "unexpected row layout after the colour transformations");
  }
  const int out_w = (width + scale - 1) / scale, out_h = (height + scale - 1) / scale;
  out.create(out_h, out_w, CV_8UC3);
  if (scale == 1 && type == CV_8UC3) {  // nothing to average or composite: rows straight into place
    for (int y = 0; y < height; ++y) png_read_row(png, out.ptr(y), nullptr);
    png_read_end(png, nullptr);
    return true;
  }
  const int strip_rows = std::max(1, kStripInputRows / scale);  // output rows per strip
  s.raw.create(strip_rows * scale, out_w * scale, type);
  for (int oy = 0; oy < out_h; oy += strip_rows) {
    const int n_out = std::min(strip_rows, out_h - oy);
    const int n_in = std::min(n_out * scale, height - oy * scale);
    for (int r = 0; r < n_in; ++r) png_read_row(png, s.raw.ptr(r), nullptr);
    pad_strip(s.raw, n_in, width);
    if (type == CV_8UC3) {
      cv::resize(s.raw.rowRange(0, n_out * scale), s.reduced, cv::Size(out_w, n_out), 0, 0, cv::INTER_AREA);
    } else {
      s.bgr = composite_over_white(s.raw.rowRange(0, n_out * scale));
      cv::resize(s.bgr, s.reduced, cv::Size(out_w, n_out), 0, 0, cv::INTER_AREA);
    }
    s.reduced.copyTo(out.rowRange(oy, oy + n_out));
  }
  png_read_end(png, nullptr);
  return true;
}

}  // namespace

bool png_decodes_by_rows(std::span<const std::uint8_t> png) {
  // Signature (8), IHDR length and type (8), width, height (8), bit depth, colour type, compression,
  // filter, interlace method (byte 28).
  if (png.size() < 33 || png[28] != 0) return false;
  PngChunkWalker walker(png_read_of(png));
  while (const std::optional<PngChunk> c = walker.next()) {
    if (c->is("eXIf")) return false;
    if (c->end() > png.size()) break;
  }
  return true;
}

cv::Mat decode_png_by_rows(std::span<const std::uint8_t> png, const std::string& path, int scale) {
  if (scale < 1) throw hk::ArgumentError("decode_png_by_rows: scale must be >= 1");
  PngInput in;
  in.bytes = png;
  PngReader reader(in);
  if (reader.png == nullptr || reader.info == nullptr)
    throw_input_error(path, "libpng could not start (out of memory)");
  Strips strips;
  cv::Mat out;
  if (!read_reduced(reader, scale, strips, out)) {
    throw_input_error(path, "the png data could not be decoded (corrupt or unsupported): " + hk::one_line(in.error));
  }
  return out;
}

}  // namespace hk::vision::detail
