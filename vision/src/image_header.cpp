// Image header parsing without decoding.
//
// Why by hand and not cv::imread's own checks: OpenCV's decoders allocate the full pixel buffer
// from the declared size before reading a single row (OpenCV's built-in cap is 2^30 pixels, i.e.
// gigabytes), and a kiosk that takes files from strangers must refuse a decompression bomb from
// the few bytes that declare its size. Every read here is bounds-checked; nothing is trusted.

#include <array>
#include <climits>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <system_error>
#include <vector>

#include <unistd.h>

#include <cerrno>

#include "image_header_detail.hpp"
#include "input_error.hpp"
#include "vision/png_chunks.hpp"

namespace hk::vision {
namespace detail {

bool MemorySource::read(std::uint64_t offset, std::size_t n, std::uint8_t* out) {
  if (offset > bytes_.size() || n > bytes_.size() - offset) return false;
  if (n > 0) std::memcpy(out, bytes_.data() + offset, n);
  return true;
}

namespace {

/// Reads a file through a one-block cache: the JPEG marker walk reads a few bytes at scattered
/// offsets, and fill-byte runs are read byte by byte.
class FileSource final : public ByteSource {
 public:
  FileSource(const std::string& path, std::uint64_t size) : file_(path, std::ios::binary), size_(size) {}
  bool is_open() const { return file_.is_open(); }
  std::uint64_t size() const override { return size_; }

  bool read(std::uint64_t offset, std::size_t n, std::uint8_t* out) override {
    if (offset > size_ || n > size_ - offset) return false;
    while (n > 0) {
      const std::uint64_t block_start = offset - offset % kBlock;
      if (block_start != cached_start_ && !load(block_start)) return false;
      const std::uint64_t in_block = offset - block_start;
      if (in_block >= cached_len_) return false;
      const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(n, cached_len_ - in_block));
      std::memcpy(out, block_.data() + in_block, take);
      out += take;
      offset += take;
      n -= take;
    }
    return true;
  }

 private:
  static constexpr std::uint64_t kBlock = 4096;

  bool load(std::uint64_t block_start) {
    cached_start_ = std::numeric_limits<std::uint64_t>::max();
    file_.clear();
    file_.seekg(static_cast<std::streamoff>(block_start));
    if (!file_) return false;
    file_.read(reinterpret_cast<char*>(block_.data()), static_cast<std::streamsize>(kBlock));
    cached_len_ = static_cast<std::uint64_t>(file_.gcount());
    cached_start_ = block_start;
    return cached_len_ > 0;
  }

  std::ifstream file_;
  std::uint64_t size_;
  std::array<std::uint8_t, kBlock> block_{};
  std::uint64_t cached_start_ = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t cached_len_ = 0;
};

/// Bounds-checked integer reads for one format; any read outside the file is a truncated header.
class Reader {
 public:
  Reader(ByteSource& src, const std::string& path, const char* format_name)
      : src_(src), path_(path), format_(format_name) {}

  std::uint64_t size() const { return src_.size(); }
  const std::string& path() const { return path_; }

  void bytes(std::uint64_t offset, std::size_t n, std::uint8_t* out) {
    if (!src_.read(offset, n, out)) {
      throw_input_error(path_, std::string("truncated ") + format_ + " header (the file ends at byte " +
                                   std::to_string(src_.size()) + ")");
    }
  }
  std::uint8_t u8(std::uint64_t off) {
    std::uint8_t b = 0;
    bytes(off, 1, &b);
    return b;
  }
  std::uint16_t u16(std::uint64_t off, bool little) { return uint_at<std::uint16_t>(off, little); }
  std::uint32_t u32(std::uint64_t off, bool little) { return uint_at<std::uint32_t>(off, little); }
  std::uint64_t u64(std::uint64_t off, bool little) { return uint_at<std::uint64_t>(off, little); }
  [[noreturn]] void corrupt(const std::string& what) {
    throw_input_error(path_, std::string("corrupt ") + format_ + " header: " + what);
  }

 private:
  /// The unsigned integer of sizeof(T) bytes at `off`, little- or big-endian.
  template <typename T>
  T uint_at(std::uint64_t off, bool little) {
    std::uint8_t b[sizeof(T)];
    bytes(off, sizeof(T), b);
    T v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      v |= static_cast<T>(static_cast<T>(b[little ? i : sizeof(T) - 1 - i]) << (8 * i));
    return v;
  }

  ByteSource& src_;
  const std::string& path_;
  const char* format_;
};

/// Declared sizes arrive as up to 64-bit unsigned values; the public header holds int.
ImageHeader make_header(Reader& r, std::uint64_t w, std::uint64_t h, const char* format) {
  if (w == 0 || h == 0) {
    r.corrupt("declares an empty image (" + std::to_string(w) + " x " + std::to_string(h) + " px)");
  }
  if (w > static_cast<std::uint64_t>(INT_MAX) || h > static_cast<std::uint64_t>(INT_MAX)) {
    throw_input_error(r.path(),
                      "declared size " + std::to_string(w) + " x " + std::to_string(h) + " px is out of range");
  }
  return ImageHeader{static_cast<int>(w), static_cast<int>(h), format};
}

// ---- PNG (W3C PNG 2nd edition: §5.2 signature, §5.3 chunk layout, §11.2.2 IHDR, §11.3.2.1 tRNS)

HeaderDetails parse_png(ByteSource& src, const std::string& path) {
  Reader r(src, path, "PNG");
  std::uint8_t ihdr[17];  // chunk type + 13 data bytes, the CRC's input
  r.bytes(12, sizeof ihdr, ihdr);
  if (r.u32(8, false) != 13 || std::memcmp(ihdr, "IHDR", 4) != 0) {
    r.corrupt("the first chunk is not a 13-byte IHDR");
  }
  if (png_crc(ihdr, sizeof ihdr) != r.u32(29, false)) r.corrupt("IHDR checksum (CRC) mismatch");
  const std::uint32_t w = r.u32(16, false);
  const std::uint32_t h = r.u32(20, false);
  if (w > 0x7FFFFFFFU || h > 0x7FFFFFFFU) r.corrupt("IHDR size exceeds 2^31 - 1");
  HeaderDetails d{make_header(r, w, h, "png"), false};
  const std::uint8_t colour_type = ihdr[4 + 9];
  d.may_have_alpha = colour_type == 4 || colour_type == 6;
  // A tRNS chunk (transparency for grey, RGB or palette images) must come before IDAT; a few
  // chunk headers are cheap to walk. Stop at the first problem: this is only a hint.
  PngChunkWalker walker(
      [&src](std::uint64_t offset, std::size_t n, std::uint8_t* out) { return src.read(offset, n, out); }, 33);
  for (int i = 0; i < 256 && !d.may_have_alpha; ++i) {
    const std::optional<PngChunk> c = walker.next();
    if (!c || c->is("IDAT") || c->is("IEND")) break;
    if (c->is("tRNS")) d.may_have_alpha = true;
  }
  return d;
}

// ---- JPEG (ITU-T T.81 | ISO/IEC 10918-1, Annex B: marker segments; B.2.2 frame header)

bool is_sof_marker(std::uint8_t m) {
  // SOF0..SOF15 except DHT (C4), JPG (C8) and DAC (CC), which share the range.
  return m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC;
}

HeaderDetails parse_jpeg(ByteSource& src, const std::string& path) {
  Reader r(src, path, "JPEG");
  std::uint64_t pos = 2;  // after SOI
  // Each iteration consumes at least one byte, so the walk ends within the file.
  for (;;) {
    if (pos >= r.size()) {
      throw_input_error(path, "truncated JPEG header: the file ends before the frame header (SOF)");
    }
    std::uint8_t b = r.u8(pos);
    if (b != 0xFF) r.corrupt("expected a marker at byte " + std::to_string(pos));
    while (b == 0xFF) b = r.u8(++pos);  // fill bytes (T.81 §B.1.1.2)
    const std::uint8_t marker = b;
    ++pos;
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // no length field
    if (marker == 0x00 || marker == 0xD8) r.corrupt("unexpected marker at byte " + std::to_string(pos - 1));
    if (marker == 0xD9) r.corrupt("end of image before the frame header (SOF)");
    if (marker == 0xDA) r.corrupt("scan (SOS) before the frame header (SOF)");
    const std::uint16_t len = r.u16(pos, false);
    if (len < 2) r.corrupt("segment length " + std::to_string(len) + " at byte " + std::to_string(pos));
    if (is_sof_marker(marker)) {
      if (len < 8) r.corrupt("frame header (SOF) too short");
      const std::uint16_t h = r.u16(pos + 3, false);
      const std::uint16_t w = r.u16(pos + 5, false);
      if (h == 0 && w != 0) {
        throw_input_error(path, "JPEG declares its height later (DNL marker), which is not supported");
      }
      return HeaderDetails{make_header(r, w, h, "jpeg"), false};
    }
    pos += len;
  }
}

// ---- BMP (Microsoft Learn, "Bitmap Header Types": BITMAPFILEHEADER, BITMAPCOREHEADER,
//      BITMAPINFOHEADER / V4 / V5; OS/2 2.x headers of 16..64 bytes share the 32-bit layout)

HeaderDetails parse_bmp(ByteSource& src, const std::string& path) {
  Reader r(src, path, "BMP");
  const std::uint32_t dib_size = r.u32(14, true);
  std::int64_t w = 0;
  std::int64_t h = 0;
  if (dib_size == 12) {
    w = r.u16(18, true);
    h = r.u16(20, true);
  } else if (dib_size >= 16 && dib_size <= 1024) {
    w = static_cast<std::int32_t>(r.u32(18, true));
    h = static_cast<std::int32_t>(r.u32(22, true));
  } else {
    r.corrupt("unknown info header size " + std::to_string(dib_size));
  }
  if (w < 0) r.corrupt("negative width " + std::to_string(w));
  if (h < 0) h = -h;  // negative height = rows stored top-down
  return HeaderDetails{make_header(r, static_cast<std::uint64_t>(w), static_cast<std::uint64_t>(h), "bmp"), false};
}

// ---- TIFF 6.0 (Adobe, 1992: §2 header and IFD; tags 256 ImageWidth, 257 ImageLength,
//      338 ExtraSamples) and BigTIFF (64-bit offsets, magic 43)

HeaderDetails parse_tiff(ByteSource& src, const std::string& path) {
  Reader r(src, path, "TIFF");
  std::uint8_t order[2];
  r.bytes(0, 2, order);
  const bool le = order[0] == 'I';
  const bool big = r.u16(2, le) == 43;
  std::uint64_t ifd = 0;
  std::uint64_t count = 0;
  std::uint64_t entry_size = 12;
  std::uint64_t value_at = 8;  // offset of the value field within an entry
  if (big) {
    if (r.u16(4, le) != 8 || r.u16(6, le) != 0) r.corrupt("BigTIFF offset size is not 8");
    ifd = r.u64(8, le);
    count = r.u64(ifd, le);
    ifd += 8;
    entry_size = 20;
    value_at = 12;
  } else {
    ifd = r.u32(4, le);
    count = r.u16(ifd, le);
    ifd += 2;
  }
  if (count == 0) r.corrupt("the first image directory is empty");
  if (count > 65535) r.corrupt("the first image directory claims " + std::to_string(count) + " entries");
  std::uint64_t w = 0;
  std::uint64_t h = 0;
  bool extra_samples = false;
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::uint64_t e = ifd + i * entry_size;
    const std::uint16_t tag = r.u16(e, le);
    if (tag != 256 && tag != 257 && tag != 338) continue;
    if (tag == 338) {
      extra_samples = true;
      continue;
    }
    const std::uint16_t type = r.u16(e + 2, le);
    std::uint64_t v = 0;
    if (type == 3) {
      v = r.u16(e + value_at, le);  // SHORT, left-justified in the value field
    } else if (type == 4) {
      v = r.u32(e + value_at, le);  // LONG
    } else if (type == 16 && big) {
      v = r.u64(e + value_at, le);  // LONG8
    } else {
      r.corrupt("image size tag " + std::to_string(tag) + " has field type " + std::to_string(type));
    }
    (tag == 256 ? w : h) = v;
  }
  if (w == 0 && h == 0) r.corrupt("no ImageWidth/ImageLength in the first image directory");
  return HeaderDetails{make_header(r, w, h, "tiff"), extra_samples};
}

// ---- WebP (RFC 9649 "WebP Image Format": RIFF container, VP8X extended header, VP8L header;
//      RFC 6386 §9.1: VP8 key frame start code and 14-bit sizes)

HeaderDetails parse_webp(ByteSource& src, const std::string& path) {
  Reader r(src, path, "WebP");
  std::uint8_t fourcc[4];
  r.bytes(12, 4, fourcc);
  std::uint64_t w = 0;
  std::uint64_t h = 0;
  bool alpha = false;
  if (std::memcmp(fourcc, "VP8 ", 4) == 0) {
    std::uint8_t start[3];
    r.bytes(23, 3, start);
    if (start[0] != 0x9D || start[1] != 0x01 || start[2] != 0x2A) r.corrupt("missing VP8 start code");
    w = r.u16(26, true) & 0x3FFFU;
    h = r.u16(28, true) & 0x3FFFU;
  } else if (std::memcmp(fourcc, "VP8L", 4) == 0) {
    if (r.u8(20) != 0x2F) r.corrupt("missing VP8L signature");
    const std::uint32_t bits = r.u32(21, true);
    w = (bits & 0x3FFFU) + 1;
    h = ((bits >> 14) & 0x3FFFU) + 1;
    alpha = ((bits >> 28) & 1U) != 0;
  } else if (std::memcmp(fourcc, "VP8X", 4) == 0) {
    alpha = (r.u8(20) & 0x10U) != 0;
    std::uint8_t b[6];
    r.bytes(24, 6, b);
    w = (std::uint64_t{b[0]} | (std::uint64_t{b[1]} << 8) | (std::uint64_t{b[2]} << 16)) + 1;
    h = (std::uint64_t{b[3]} | (std::uint64_t{b[4]} << 8) | (std::uint64_t{b[5]} << 16)) + 1;
  } else {
    r.corrupt("unknown first chunk (expected VP8, VP8L or VP8X)");
  }
  return HeaderDetails{make_header(r, w, h, "webp"), alpha};
}

}  // namespace

HeaderDetails parse_image_header(ByteSource& src, const std::string& path) {
  if (src.size() == 0) throw_input_error(path, "file is empty (0 bytes)");
  std::uint8_t m[12] = {};
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(src.size(), sizeof m));
  if (!src.read(0, n, m)) throw_input_error(path, "cannot read the file");
  const auto starts = [&](const char* sig, std::size_t len) { return n >= len && std::memcmp(m, sig, len) == 0; };
  if (starts("\x89PNG\r\n\x1A\n", 8)) return parse_png(src, path);
  if (starts("\xFF\xD8\xFF", 3)) return parse_jpeg(src, path);
  if (starts("BM", 2)) return parse_bmp(src, path);
  if (starts("II*\0", 4) || starts("MM\0*", 4) || starts("II+\0", 4) || starts("MM\0+", 4)) {
    return parse_tiff(src, path);
  }
  if (starts("RIFF", 4) && n >= 12 && std::memcmp(m + 8, "WEBP", 4) == 0) return parse_webp(src, path);
  throw_input_error(path, "unknown image format (the file is not PNG, JPEG, BMP, TIFF or WebP)");
}

std::uint64_t checked_file_size(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) throw_input_error(path, "file not found");
  if (ec) throw_input_error(path, "cannot access the file (" + ec.message() + ")");
  if (!fs::is_regular_file(st)) throw_input_error(path, "not a regular file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw_input_error(path, "cannot read the file size (" + ec.message() + ")");
  if (size == 0) throw_input_error(path, "file is empty (0 bytes)");
  return size;
}

}  // namespace detail

namespace {

/// The bytes of an open file, read with pread where the parser asks (a JPEG's walk skips its segments).
class FdSource final : public detail::ByteSource {
 public:
  FdSource(int fd, std::uint64_t size) : fd_(fd), size_(size) {}
  std::uint64_t size() const override { return size_; }
  bool read(std::uint64_t offset, std::size_t n, std::uint8_t* out) override {
    if (offset > size_ || n > size_ - offset) return false;
    std::size_t done = 0;
    while (done < n) {
      const long got = ::pread(fd_, out + done, n - done, static_cast<off_t>(offset + done));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) return false;
      done += static_cast<std::size_t>(got);
    }
    return true;
  }

 private:
  int fd_;
  std::uint64_t size_;
};

}  // namespace

std::string image_header_problem(int fd, std::uint64_t size_bytes, const std::string& name) {
  FdSource src(fd, size_bytes);
  try {
    detail::parse_image_header(src, name);
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

ImageHeader read_image_header(const std::string& path) {
  const std::uint64_t size = detail::checked_file_size(path);
  detail::FileSource src(path, size);
  if (!src.is_open()) detail::throw_input_error(path, "cannot open the file for reading");
  return detail::parse_image_header(src, path).header;
}

}  // namespace hk::vision
