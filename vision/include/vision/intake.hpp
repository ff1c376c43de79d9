#pragma once
/// @file intake.hpp
/// Image intake: the only door through which outside image files enter the kiosk.
///
/// Files come from USB sticks handed in by strangers, so every check that can be made without
/// decoding is made before decoding (DESIGN.md "Bad input"): file size, then the dimensions the
/// header declares (a 100 kB PNG can declare 100000 x 100000 px and make a decoder allocate 30 GB),
/// then, for JPEG, that the stream is complete. Only then is OpenCV allowed to decode, from the
/// bytes already checked (not by reopening the path, which could have changed in between).
/// Every refusal is an InputError whose message is one line naming the file and the problem.

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>
#include "hk/error.hpp"

#include <opencv2/core.hpp>

namespace hk::vision {

/// Limits applied to an image file before it is decoded. All must be positive.
struct ImageLimits {
  std::int64_t max_file_bytes = 64LL << 20;  ///< largest accepted file [bytes] (64 MiB)
  int max_width_px = 10000;                  ///< largest declared width [px]
  int max_height_px = 10000;                 ///< largest declared height [px]
  std::int64_t max_pixels = 40'000'000;      ///< largest declared width x height [px]
};

/// A refused input file. what() is a single line (control characters in the path are escaped)
/// of the form "image '<path>': <problem>", e.g.
/// "image 'x.png': declared size 100000 x 100000 px exceeds the limit of 10000 x 10000 px".
class InputError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// What an image file's header declares, read without decoding any pixel data.
struct ImageHeader {
  int width_px = 0;    ///< declared width [px], > 0
  int height_px = 0;   ///< declared height [px], > 0
  std::string format;  ///< container format: "png", "jpeg", "bmp", "tiff" or "webp"
};

/// Reads the declared size of an image from its header bytes only; the format is recognised by
/// its signature, not by the file name's extension.
///
/// Parsed structures (sources: the format specifications):
/// - PNG: signature + IHDR chunk, CRC checked (W3C PNG 2nd ed. §5.3, §11.2.2);
/// - JPEG: marker segments walked up to the first SOFn frame header (ITU-T T.81 §B.2);
/// - BMP: BITMAPCOREHEADER / BITMAPINFOHEADER and later (Microsoft "Bitmap Header Types");
/// - TIFF and BigTIFF: first IFD, tags ImageWidth (256) and ImageLength (257) (TIFF 6.0 §2);
/// - WebP: RIFF chunk VP8 (RFC 6386 §9.1), VP8L (RFC 9649 §3.4 / WebP lossless spec) or VP8X.
/// Reads a few hundred bytes for most files; a JPEG's walk skips over (does not read) segments.
///
/// @throws InputError if the file is missing or unreadable, empty (0 bytes), of an unknown format
///         (e.g. a text file named .png), or its header is truncated, corrupt, or declares a zero
///         or out-of-range size.
ImageHeader read_image_header(const std::string& path);

/// read_image_header's check of a file already open as `fd` (read with pread, the offset untouched) of
/// `size_bytes` bytes, named `name` in the answer: "" when its header is whole, else the InputError's one line
/// (a USB stick's scan refuses such a picture: ScanLimits::picture_check). Never throws for a bad file.
std::string image_header_problem(int fd, std::uint64_t size_bytes, const std::string& name);

/// Loads an image file as 8-bit BGR after checking it against the limits.
///
/// Order of checks: file exists and is a regular file; size in (0, max_file_bytes]; header
/// (read_image_header rules) declares width <= max_width_px, height <= max_height_px and
/// width*height <= max_pixels; then the container structure: a JPEG must reach its end-of-image
/// marker 0xFFD9 (libjpeg only warns on a truncated stream and returns a half-grey image, which
/// would show as a false edge), a PNG must have intact chunks (CRC) up to IEND.
/// Decoding is cv::imdecode(IMREAD_COLOR) of the bytes that were checked, equivalent to
/// cv::imread(path, IMREAD_COLOR) (EXIF orientation is applied; same pixels) but without
/// reopening the path. A PNG that is not interlaced and has no eXIf chunk is decoded by libpng
/// directly, a strip of rows at a time, with the transformations OpenCV's PNG decoder sets (the
/// same pixels), so that libpng's reason for refusing a damaged one is in the message ("... could
/// not be decoded (corrupt or unsupported): Not enough image data") and not on stderr. For PNG,
/// ancillary chunks OpenCV ignores (colour profiles, text) are left out of what libpng is given.
/// Images with an alpha channel (PNG colour types 4/6 or tRNS, WebP alpha, TIFF extra samples)
/// are composited over white, as a viewer would show them, so transparent areas do not turn black.
/// OpenCV's own log output is silenced while decoding (libjpeg may still print a warning for
/// corrupt data inside a complete JPEG: it writes to stderr directly).
///
/// @return CV_8UC3 BGR image, rows = height, cols = width (as decoded; an EXIF rotation may swap
///         the declared width and height).
/// @throws InputError for every refusal above and when decoding fails.
/// @throws hk::ArgumentError if a limit is not positive.
cv::Mat load_image(const std::string& path, const ImageLimits& limits);

/// An image decoded at reduced detail (see load_image_reduced), with what a report needs to say about it.
struct DecodedImage {
  /// CV_8UC3 BGR pixels as decoded: the picture shown upright (EXIF orientation applied), each side
  /// ceil(file side / scale) [px].
  cv::Mat bgr;
  /// The picture's own size at full detail, upright like `bgr` (an EXIF rotation of 90 or 270 degrees
  /// swaps the header's width and height) [px].
  int file_width_px = 0;
  int file_height_px = 0;
  /// Full-detail pixels per decoded pixel along each side: 1 (full decode), 2, 4 or 8. A decoded pixel
  /// (u, v) covers the full-detail pixels [u * scale, (u + 1) * scale) x [v * scale, (v + 1) * scale)
  /// (libjpeg's scaled inverse DCT averages each block; a PNG read by rows averages them with
  /// cv::INTER_AREA), so a position x in full-detail pixels (origin at the top-left pixel's corner) is
  /// x / scale in decoded pixels.
  int scale = 1;
  std::string format;  ///< container format, as ImageHeader::format
};

/// The reduction factor a JPEG or PNG of `width_px` x `height_px` is decoded at so that its long side still
/// has at least `keep_side_px` pixels: the largest 2^k, k <= 3, with ceil(max(width, height) / 2^k) >=
/// keep_side_px (libjpeg rounds a scaled side up; a PNG's partial edge blocks do the same). 1 when
/// keep_side_px <= 0 (full decode) or when even 1/2 would leave fewer than keep_side_px pixels. Sizes [px],
/// both > 0.
int decode_reduction_for(int width_px, int height_px, int keep_side_px);

/// load_image at reduced detail: the same checks in the same order (file bytes, declared size, JPEG end
/// marker, PNG chunks), all made before any pixel is decoded, then the picture is decoded at 1/scale of its
/// size (scale from decode_reduction_for: its long side stays >= keep_side_px):
///  - a JPEG with libjpeg's DCT scaling (cv::IMREAD_REDUCED_COLOR_2/4/8), which spends a fraction of a full
///    decode's time;
///  - a PNG (not interlaced, without eXIf) with libpng a strip of rows at a time, each scale x scale block
///    averaged (cv::INTER_AREA) as the strip arrives, a partial block at the right or bottom edge completed
///    by repeating the last column or row. Every byte is still inflated, but the full-size pixels are never
///    held: the result is load_image's pixels (alpha composited over white) averaged by block.
/// EXIF orientation is applied as in a full decode. Other formats, interlaced PNGs and PNGs with an eXIf
/// chunk are decoded in full (scale 1): their decoders have no reduced path.
/// @param keep_side_px  fewest pixels the decoded long side may have [px]; 0 (or less) decodes in full, so
///                      that bgr is exactly load_image's result.
/// @throws InputError as load_image (and when the decoded size is not the declared one reduced by scale).
/// @throws hk::ArgumentError if a limit is not positive.
DecodedImage load_image_reduced(const std::string& path, const ImageLimits& limits, int keep_side_px);

/// The whole file at `path` (an input named on the command line), read once, after checking it is a
/// regular file of 1 to max_bytes bytes.
/// @throws InputError "image '<path>': <problem>" (not found, not a regular file, empty, over max_bytes with
///         both sizes named, changed size while read).
/// @throws hk::ArgumentError if max_bytes is not positive.
std::vector<std::uint8_t> read_input_file(const std::string& path, std::int64_t max_bytes);

/// load_image on bytes already read (a document from a USB stick, read through stick_scan's
/// read_stick_file so that no path is opened twice). `name` names the input in errors. Same checks and
/// decoding as load_image after the file has been read.
/// @throws InputError as load_image; hk::ArgumentError if a limit is not positive.
cv::Mat decode_image(std::span<const std::uint8_t> bytes, const std::string& name, const ImageLimits& limits);

/// decode_image at reduced detail: load_image_reduced on bytes already read. `name` names the input in errors.
/// @throws InputError as decode_image; hk::ArgumentError if a limit is not positive.
DecodedImage decode_image_reduced(std::span<const std::uint8_t> bytes, const std::string& name,
                                  const ImageLimits& limits, int keep_side_px);

/// Converts to one grey channel and shrinks so that max(width, height) <= max_side_px.
///
/// Shrinking uses cv::INTER_AREA (pixel-area averaging, the alias-free choice for decimation).
/// The long side becomes exactly max_side_px; the short side is rounded, so its scale differs
/// from the long side's by less than half a processed pixel. Images already small enough are
/// not resized (never enlarged).
///
/// @param bgr          CV_8UC3 (BGR), CV_8UC4 (BGRA, alpha ignored) or CV_8UC1 (copied).
/// @param max_side_px  largest allowed side of the result [px], >= 1.
/// @param px_scale_out if not null, receives original px per processed px along the long side
///                     (>= 1; exactly 1 when not resized).
/// @return CV_8UC1 grey image.
/// @throws hk::ArgumentError if bgr is empty or of another type, or max_side_px < 1.
cv::Mat to_grey(const cv::Mat& bgr, int max_side_px, double* px_scale_out);

}  // namespace hk::vision
