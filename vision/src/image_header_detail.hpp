#pragma once
// Private to the vision library: the byte-level parsers behind read_image_header and
// load_image. Kept behind an abstract byte source so the same parser reads a path lazily (only
// the header bytes of a 60 MB file) and checks the in-memory bytes that load_image decodes.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/intake.hpp"

namespace hk::vision::detail {

/// Random-access, bounds-checked bytes.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  /// Total size [bytes].
  virtual std::uint64_t size() const = 0;
  /// Copies bytes [offset, offset + n) to out; false (out unspecified) if that range is not
  /// entirely inside the source or cannot be read.
  virtual bool read(std::uint64_t offset, std::size_t n, std::uint8_t* out) = 0;
};

/// A ByteSource over bytes in memory (not owned; must outlive the source).
class MemorySource final : public ByteSource {
 public:
  explicit MemorySource(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  std::uint64_t size() const override { return bytes_.size(); }
  bool read(std::uint64_t offset, std::size_t n, std::uint8_t* out) override;

 private:
  std::span<const std::uint8_t> bytes_;
};

/// The header plus what load_image needs to decide how to decode.
struct HeaderDetails {
  ImageHeader header;
  bool may_have_alpha = false;  ///< the format declares an alpha channel or transparency
};

/// Parses the header of src (see read_image_header for the formats and their sources).
/// path is only used in error messages. Throws InputError.
HeaderDetails parse_image_header(ByteSource& src, const std::string& path);

/// Size of the regular file at path [bytes], > 0. Throws InputError if it does not exist, is
/// not a regular file, or is empty.
std::uint64_t checked_file_size(const std::string& path);

/// The PNG file's bytes that libpng is given: only the chunks which change the pixels OpenCV decodes
/// (IHDR, PLTE, tRNS, IDAT, IEND, eXIf for orientation, and any unknown critical chunk, which libpng then
/// refuses), after checking the chunk structure: every kept chunk's CRC, an IDAT, and an IEND before the end
/// of the file. Dropped ancillary chunks (colour profiles, text, time...) are ones OpenCV ignores but libpng
/// may complain about on stderr (e.g. "iCCP: known incorrect sRGB profile"). When no chunk is dropped the
/// result is a view of `bytes` up to IEND (no copy: a photo PNG is tens of MB); otherwise it is `storage`,
/// filled with the kept chunks. Throws InputError naming path.
std::span<const std::uint8_t> png_decodable(std::span<const std::uint8_t> bytes, const std::string& path,
                                            std::vector<std::uint8_t>& storage);

/// Whether a checked PNG (as png_decodable returns it) can be decoded a row at a time: not interlaced
/// (Adam7 passes need the whole image) and without an eXIf chunk (OpenCV turns such a picture upright,
/// which the row decode does not). Bytes past the IHDR are only scanned for chunk types.
bool png_decodes_by_rows(std::span<const std::uint8_t> png);

/// A checked PNG (as png_decodable returns it) decoded with libpng a strip of rows at a time, each block
/// of `scale` x `scale` pixels averaged into one (cv::INTER_AREA), so the full-size image is never held:
/// BGR, 8 bits, ceil(width / scale) x ceil(height / scale) px. A partial block at the right or bottom edge
/// is completed by repeating the last column or row. The pixels before averaging are those OpenCV's
/// cv::imdecode gives (libpng's transformations as OpenCV's PNG decoder sets them: 16 bits cut to 8,
/// palette and low bit depths expanded, grey to BGR); one with alpha (an alpha channel, or tRNS on an RGB
/// or palette image) is first composited over white as decode_image does. At scale 1 these are
/// cv::imdecode's pixels. `scale` >= 1; the PNG must satisfy png_decodes_by_rows.
/// @throws InputError naming `path` with libpng's reason when it finds the data corrupt or short;
///         hk::ArgumentError if scale < 1.
cv::Mat decode_png_by_rows(std::span<const std::uint8_t> png, const std::string& path, int scale);

/// out = alpha * colour + (1 - alpha) * white, for 8- or 16-bit BGRA (CV_8UC4 or CV_16UC4); CV_8UC3.
cv::Mat composite_over_white(const cv::Mat& bgra);

/// True when a JPEG stream (starting with SOI) reaches its end-of-image marker 0xFFD9 through a
/// well-formed sequence of marker segments and entropy-coded scans (ITU-T T.81 §B.1.1, B.2).
/// Bytes after EOI are ignored. Linear in the number of bytes.
bool jpeg_is_complete(std::span<const std::uint8_t> bytes);

}  // namespace hk::vision::detail
