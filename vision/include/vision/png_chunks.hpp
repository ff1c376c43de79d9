#pragma once
/// @file png_chunks.hpp
/// The one walk over a PNG's chunks (W3C PNG 2nd edition: §5.2 the 8-byte signature, §5.3 each chunk a
/// length (4 bytes, big-endian, at most 2^31 − 1), a type (4), its data and the CRC-32 of type and data
/// (4)). Whatever looks inside a PNG without decoding it walks with PngChunkWalker: the decoder's check and
/// clean-up (png_decodable), the header check (image_header_problem: tRNS), the strip decoder's test for
/// eXIf (png_decodes_by_rows) and a picture's own title and description (app/formats png_text).

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string_view>

namespace hk::vision {

/// The 8 bytes every PNG starts with.
inline constexpr std::array<std::uint8_t, 8> kPngSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
/// The largest chunk length a sound PNG has [bytes].
inline constexpr std::uint32_t kPngMaxChunkLength = 0x7FFFFFFFU;

/// A chunk's header and where it stands. Its length is as the file has it: a damaged file's may exceed
/// kPngMaxChunkLength or run past the end of the bytes (the caller judges).
struct PngChunk {
  std::uint64_t offset = 0;    ///< of its length field [bytes from the start of the file]
  std::uint32_t length = 0;    ///< its data [bytes]
  std::array<char, 4> type{};  ///< as the file has it: four letters in a sound file, anything in a damaged one
  std::string_view name() const { return {type.data(), type.size()}; }
  bool is(std::string_view t) const { return name() == t; }
  /// A critical chunk (upper-case first letter): a decoder must understand it.
  bool critical() const { return (static_cast<unsigned char>(type[0]) & 0x20U) == 0; }
  std::uint64_t data_offset() const { return offset + 8; }
  /// Just past its CRC: where the next chunk starts.
  std::uint64_t end() const { return offset + 12 + std::uint64_t{length}; }
};

/// Copies `n` bytes at `offset` to `out`; false when they are not all there (past the end, or unreadable).
using PngRead = std::function<bool(std::uint64_t offset, std::size_t n, std::uint8_t* out)>;

/// Walks a PNG's chunks, one header at a time; reads nothing of their data.
class PngChunkWalker {
 public:
  /// From the chunk at `first` [bytes] (8: the first chunk, after the signature, which the caller checks).
  explicit PngChunkWalker(PngRead read, std::uint64_t first = kPngSignature.size())
      : read_(std::move(read)), next_(first) {}
  /// The next chunk (the one at `first`, then each at the previous one's end()); nullopt when its 8 header
  /// bytes are not all there.
  std::optional<PngChunk> next();

 private:
  PngRead read_;
  std::uint64_t next_;
};

/// A PngRead over bytes in memory (not owned: they outlive the reader).
PngRead png_read_of(std::span<const std::uint8_t> bytes);

/// A big-endian 32-bit number (PNG's byte order).
std::uint32_t png_u32(const std::uint8_t* p);

/// The CRC-32 PNG chunks carry (Annex D: zlib's, the ISO 3309 polynomial) of `n` bytes: a chunk's type and data.
std::uint32_t png_crc(const std::uint8_t* data, std::size_t n);

}  // namespace hk::vision
