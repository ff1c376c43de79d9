// PNG chunk check and clean-up before decoding.
//
// libpng reports problems by printing to stderr ("libpng error: Read Error" for a truncated
// file, "libpng warning: iCCP: ..." for a colour profile it dislikes, as in tests/data/images/
// page.png) and OpenCV cannot silence it. Checking the chunk structure here turns a truncated or
// damaged file into one clear InputError, and handing libpng only the chunks that matter to
// OpenCV's pixels keeps the kiosk's log free of warnings about data it would ignore anyway.

#include "vision/png_chunks.hpp"

#include <zlib.h>

#include <cstring>

#include "hk/text.hpp"
#include "image_header_detail.hpp"
#include "input_error.hpp"

namespace hk::vision {

std::optional<PngChunk> PngChunkWalker::next() {
  std::uint8_t header[8];
  if (!read_(next_, sizeof header, header)) return std::nullopt;
  PngChunk c;
  c.offset = next_;
  c.length = png_u32(header);
  std::memcpy(c.type.data(), header + 4, 4);
  next_ = c.end();
  return c;
}

PngRead png_read_of(std::span<const std::uint8_t> bytes) {
  return [bytes](std::uint64_t offset, std::size_t n, std::uint8_t* out) {
    if (offset > bytes.size() || n > bytes.size() - offset) return false;
    if (n > 0) std::memcpy(out, bytes.data() + offset, n);
    return true;
  };
}

std::uint32_t png_u32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

std::uint32_t png_crc(const std::uint8_t* data, std::size_t n) {
  // PNG Annex D's CRC-32 is zlib's (ISO 3309 polynomial, init and final xor 0xFFFFFFFF).
  return static_cast<std::uint32_t>(::crc32_z(0UL, data, n));
}

}  // namespace hk::vision

namespace hk::vision::detail {
namespace {

bool kept_chunk(const std::uint8_t* type) {
  for (const char* keep : {"IHDR", "PLTE", "IDAT", "IEND", "tRNS", "eXIf"}) {
    if (std::memcmp(type, keep, 4) == 0) return true;
  }
  return false;
}

}  // namespace

std::span<const std::uint8_t> png_decodable(std::span<const std::uint8_t> bytes, const std::string& path,
                                            std::vector<std::uint8_t>& storage) {
  const std::size_t n = bytes.size();
  storage.clear();
  bool copying = false;  // a chunk has been dropped: `storage` holds the kept chunks so far
  std::size_t pos = 8;
  bool idat = false;
  PngChunkWalker walker(png_read_of(bytes));
  for (;;) {
    const std::optional<PngChunk> c = walker.next();
    if (!c || n - pos < 12) {
      throw_input_error(path, "truncated PNG: the file ends before its IEND chunk");
    }
    const std::uint8_t* chunk = bytes.data() + pos;
    const std::uint8_t* type = chunk + 4;
    const std::uint32_t len = c->length;
    // The type's 4 bytes as the file has them: letters in a sound file, anything in a damaged one.
    const std::string name = hk::one_line(c->name());
    if (len > kPngMaxChunkLength || len > n - pos - 12) {
      throw_input_error(path, "truncated PNG: chunk '" + name + "' at byte " + std::to_string(pos) +
                                  " runs past the end of the file");
    }
    const std::size_t chunk_bytes = 12 + std::size_t{len};
    if (kept_chunk(type) || c->critical()) {
      // Unknown critical chunks are passed on: libpng refuses them, as the standard requires.
      if (png_crc(type, 4 + std::size_t{len}) != png_u32(type + 4 + len)) {
        throw_input_error(
            path, "corrupt PNG: checksum (CRC) mismatch in chunk '" + name + "' at byte " + std::to_string(pos));
      }
      if (copying) storage.insert(storage.end(), chunk, chunk + chunk_bytes);
      idat = idat || c->is("IDAT");
      if (c->is("IEND")) {
        pos += chunk_bytes;
        break;
      }
    } else if (!copying) {  // the first chunk dropped: copy what was kept before it
      storage.reserve(n);
      storage.assign(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(pos));
      copying = true;
    }
    pos += chunk_bytes;
  }
  if (!idat) throw_input_error(path, "corrupt PNG: no image data (IDAT chunk)");
  if (copying) return storage;
  return bytes.first(pos);  // every chunk kept; bytes after IEND are not part of the PNG
}

}  // namespace hk::vision::detail
