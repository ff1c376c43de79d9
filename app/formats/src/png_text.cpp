// PNG text chunks (see png_text.hpp): the file is walked chunk by chunk (vision/png_chunks.hpp
// PngChunkWalker) and only the text chunks are read; the image data is skipped, not decoded, so a 20 MB photo
// costs a few hundred small reads and seeks rather than a second full decode. Each text chunk's CRC is
// checked (png_crc) and zlib inflates the compressed ones.

#include "formats/png_text.hpp"

#include "vision/png_chunks.hpp"

#include <zlib.h>

#include <array>
#include <climits>
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

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

}  // namespace

PngText read_png_text(const std::string& path) {
  PngText out;
  const std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
  if (!f) return out;
  const auto read = [file = f.get()](std::uint64_t offset, std::size_t n, std::uint8_t* to) {
    return offset <= static_cast<std::uint64_t>(LONG_MAX) &&
           std::fseek(file, static_cast<long>(offset), SEEK_SET) == 0 && std::fread(to, 1, n, file) == n;
  };
  std::array<std::uint8_t, 8> sig{};
  if (!read(0, sig.size(), sig.data()) || sig != vision::kPngSignature) return out;
  bool have_title = false, have_description = false;
  std::string data, keyword;
  vision::PngChunkWalker walker(read);
  for (int chunk = 0; chunk < kMaxChunks && !(have_title && have_description); ++chunk) {
    const std::optional<vision::PngChunk> c = walker.next();
    if (!c || c->length > vision::kPngMaxChunkLength || c->is("IEND")) break;
    const bool text = c->is("tEXt") || c->is("zTXt") || c->is("iTXt");
    if (!text || c->length > kMaxChunkBytes) continue;  // the image data and everything else: skipped
    // Its type, data and CRC, in one read.
    data.resize(4 + std::size_t{c->length} + 4);
    if (!read(c->offset + 4, data.size(), reinterpret_cast<std::uint8_t*>(data.data()))) break;
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(data.data());
    if (vision::png_crc(bytes, 4 + c->length) != vision::png_u32(bytes + 4 + c->length))
      continue;  // a damaged chunk says nothing
    const std::optional<std::string> value =
        chunk_text(c->name(), std::string_view(data).substr(4, c->length), keyword);
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
