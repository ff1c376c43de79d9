// PNG text chunks (see png_text.hpp): the file is walked chunk by chunk (PNG 2nd ed. §5.3: length, type,
// data, CRC-32) and only the text chunks are read; the image data is skipped, not decoded, so a 20 MB photo
// costs a few hundred small reads and seeks rather than a second full decode. zlib checks each text chunk's
// CRC and inflates the compressed ones.

#include "formats/png_text.hpp"

#include <zlib.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

namespace hk::app {
namespace {

constexpr std::size_t kMaxChunkBytes = 1u << 20;  // a text chunk, stored or inflated, larger than this is skipped
constexpr int kMaxChunks = 1 << 20;               // chunks looked at before giving up on a file
constexpr std::array<std::uint8_t, 8> kSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

/// Latin-1 (tEXt, zTXt) to UTF-8.
std::string latin1_to_utf8(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x80) {
      out.push_back(static_cast<char>(c));
    } else {
      out.push_back(static_cast<char>(0xC0 | (c >> 6)));
      out.push_back(static_cast<char>(0x80 | (c & 0x3F)));
    }
  }
  return out;
}

/// A zlib stream inflated, when it is whole and inflates to at most kMaxChunkBytes.
std::optional<std::string> inflated(std::string_view z) {
  z_stream zs{};
  if (inflateInit(&zs) != Z_OK) return std::nullopt;
  std::string out(kMaxChunkBytes, '\0');
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(z.data()));
  zs.avail_in = static_cast<uInt>(z.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  const int rc = inflate(&zs, Z_FINISH);
  const std::size_t n = zs.total_out;
  inflateEnd(&zs);
  if (rc != Z_STREAM_END) return std::nullopt;  // damaged, or larger than the limit (a bomb)
  out.resize(n);
  return out;
}

/// The text of a tEXt, zTXt or iTXt chunk's data, as UTF-8, under `keyword`; nullopt when the chunk is
/// malformed (PNG 2nd ed. §11.3.4: keyword, NUL, then per type: text | method, zlib | flag, method, language
/// NUL, translated keyword NUL, text or zlib).
std::optional<std::string> chunk_text(std::string_view type, std::string_view data, std::string& keyword) {
  const std::size_t nul = data.find('\0');
  if (nul == std::string_view::npos || nul == 0 || nul > 79) return std::nullopt;
  keyword.assign(data.substr(0, nul));
  std::string_view rest = data.substr(nul + 1);
  if (type == "tEXt") return latin1_to_utf8(rest);
  if (type == "zTXt") {
    if (rest.empty() || rest[0] != 0) return std::nullopt;
    const std::optional<std::string> t = inflated(rest.substr(1));
    return t ? std::optional<std::string>(latin1_to_utf8(*t)) : std::nullopt;
  }
  if (rest.size() < 2) return std::nullopt;  // iTXt
  const bool compressed = rest[0] != 0;
  if (compressed && rest[1] != 0) return std::nullopt;
  rest.remove_prefix(2);
  for (int field = 0; field < 2; ++field) {  // language tag, translated keyword
    const std::size_t end = rest.find('\0');
    if (end == std::string_view::npos) return std::nullopt;
    rest.remove_prefix(end + 1);
  }
  return compressed ? inflated(rest) : std::optional<std::string>(std::string(rest));
}

std::uint32_t big_endian(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

}  // namespace

PngText read_png_text(const std::string& path) {
  PngText out;
  const std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
  if (!f) return out;
  std::array<std::uint8_t, 8> sig{};
  if (std::fread(sig.data(), 1, sig.size(), f.get()) != sig.size() || sig != kSignature) return out;
  bool have_title = false, have_description = false;
  std::string data, keyword;
  for (int chunk = 0; chunk < kMaxChunks && !(have_title && have_description); ++chunk) {
    std::array<std::uint8_t, 8> head{};
    if (std::fread(head.data(), 1, head.size(), f.get()) != head.size()) break;
    const std::uint32_t length = big_endian(head.data());
    const std::string_view type(reinterpret_cast<const char*>(head.data() + 4), 4);
    if (length > 0x7fffffffu || type == "IEND") break;
    const bool text = type == "tEXt" || type == "zTXt" || type == "iTXt";
    if (!text || length > kMaxChunkBytes) {  // the image data and everything else: skipped, with its CRC
      if (std::fseek(f.get(), static_cast<long>(length) + 4, SEEK_CUR) != 0) break;
      continue;
    }
    data.resize(length);
    std::array<std::uint8_t, 4> crc{};
    if ((length > 0 && std::fread(data.data(), 1, length, f.get()) != length) ||
        std::fread(crc.data(), 1, 4, f.get()) != 4)
      break;
    uLong sum = crc32(0L, head.data() + 4, 4);
    sum = crc32(sum, reinterpret_cast<const Bytef*>(data.data()), static_cast<uInt>(length));
    if (sum != big_endian(crc.data())) continue;  // a damaged chunk says nothing
    const std::optional<std::string> value = chunk_text(type, data, keyword);
    if (!value) continue;
    if (keyword == "Title" && !have_title) {
      out.title = *value;
      have_title = true;
    } else if (keyword == "Description" && !have_description) {
      out.description = *value;
      have_description = true;
    }
  }
  return out;
}

}  // namespace hk::app
