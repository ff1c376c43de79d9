// PNG chunk check and clean-up before decoding.
//
// libpng reports problems by printing to stderr ("libpng error: Read Error" for a truncated
// file, "libpng warning: iCCP: ..." for a colour profile it dislikes, as in tests/data/images/
// page.png) and OpenCV cannot silence it. Checking the chunk structure here turns a truncated or
// damaged file into one clear InputError, and handing libpng only the chunks that matter to
// OpenCV's pixels keeps the kiosk's log free of warnings about data it would ignore anyway.

#include <cstring>

#include "hk/text.hpp"
#include "image_header_detail.hpp"
#include "input_error.hpp"

namespace hk::vision::detail {
namespace {

bool kept_chunk(const std::uint8_t* type) {
  for (const char* keep : {"IHDR", "PLTE", "IDAT", "IEND", "tRNS", "eXIf"}) {
    if (std::memcmp(type, keep, 4) == 0) return true;
  }
  return false;
}

bool is_critical(const std::uint8_t* type) { return (type[0] & 0x20U) == 0; }  // upper-case first letter

std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

}  // namespace

std::span<const std::uint8_t> png_decodable(std::span<const std::uint8_t> bytes, const std::string& path,
                                            std::vector<std::uint8_t>& storage) {
  const std::size_t n = bytes.size();
  storage.clear();
  bool copying = false;  // a chunk has been dropped: `storage` holds the kept chunks so far
  std::size_t pos = 8;
  bool idat = false;
  // W3C PNG 2nd ed. §5.3: length (4, <= 2^31 - 1), type (4), data, CRC over type + data (4).
  for (;;) {
    if (pos > n || n - pos < 12) {
      throw_input_error(path, "truncated PNG: the file ends before its IEND chunk");
    }
    const std::uint8_t* chunk = bytes.data() + pos;
    const std::uint32_t len = be32(chunk);
    const std::uint8_t* type = chunk + 4;
    // The type's 4 bytes as the file has them: letters in a sound file, anything in a damaged one.
    const std::string name = hk::one_line(std::string_view(reinterpret_cast<const char*>(type), 4));
    if (len > 0x7FFFFFFFU || len > n - pos - 12) {
      throw_input_error(path, "truncated PNG: chunk '" + name + "' at byte " + std::to_string(pos) +
                                  " runs past the end of the file");
    }
    const std::size_t chunk_bytes = 12 + std::size_t{len};
    if (kept_chunk(type) || is_critical(type)) {
      // Unknown critical chunks are passed on: libpng refuses them, as the standard requires.
      if (crc32_png(type, 4 + std::size_t{len}) != be32(type + 4 + len)) {
        throw_input_error(
            path, "corrupt PNG: checksum (CRC) mismatch in chunk '" + name + "' at byte " + std::to_string(pos));
      }
      if (copying) storage.insert(storage.end(), chunk, chunk + chunk_bytes);
      idat = idat || std::memcmp(type, "IDAT", 4) == 0;
      if (std::memcmp(type, "IEND", 4) == 0) {
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
