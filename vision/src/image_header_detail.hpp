#pragma once
// Private to the vision library: the byte-level parsers behind read_image_header and
// load_image. Kept behind an abstract byte source so the same parser reads a path lazily (only
// the header bytes of a 60 MB file) and checks the in-memory bytes that load_image decodes.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

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

/// CRC-32 as used by PNG chunks (W3C PNG 2nd ed. Annex D; the zlib/ISO 3309 polynomial).
std::uint32_t crc32_png(const std::uint8_t* data, std::size_t n);

/// A copy of a PNG file that keeps only the chunks which change the pixels OpenCV decodes
/// (IHDR, PLTE, tRNS, IDAT, IEND, and eXIf for orientation), after checking the chunk structure:
/// every kept chunk's CRC, an IDAT, and an IEND before the end of the file. Dropped ancillary
/// chunks (colour profiles, text, time...) are ones OpenCV ignores but libpng may complain about
/// on stderr (e.g. "iCCP: known incorrect sRGB profile"). Throws InputError naming path.
std::vector<std::uint8_t> png_decodable_copy(std::span<const std::uint8_t> bytes, const std::string& path);

/// True when a JPEG stream (starting with SOI) reaches its end-of-image marker 0xFFD9 through a
/// well-formed sequence of marker segments and entropy-coded scans (ITU-T T.81 §B.1.1, B.2).
/// Bytes after EOI are ignored. Linear in the number of bytes.
bool jpeg_is_complete(std::span<const std::uint8_t> bytes);

}  // namespace hk::vision::detail
