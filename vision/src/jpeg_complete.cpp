// JPEG completeness check.
//
// libjpeg treats a stream that stops early as a warning ("Premature end of JPEG file"), pads the
// missing rows with grey and OpenCV returns the image as if it were whole. On the kiosk that grey
// block would become a strong straight false edge, so a JPEG is refused unless its stream reaches
// the end-of-image marker. Walking the marker structure (rather than looking at the last two
// bytes) accepts the valid files that carry bytes after EOI and is not fooled by the EOI of an
// EXIF thumbnail embedded in an APP1 segment.

#include <cstring>

#include "image_header_detail.hpp"

namespace hk::vision::detail {

bool jpeg_is_complete(std::span<const std::uint8_t> d) {
  const std::size_t n = d.size();
  if (n < 4 || d[0] != 0xFF || d[1] != 0xD8) return false;
  std::size_t pos = 2;
  for (;;) {
    // A marker: one or more 0xFF (fill bytes, T.81 §B.1.1.2) and a code.
    if (pos >= n || d[pos] != 0xFF) return false;
    while (pos < n && d[pos] == 0xFF) ++pos;
    if (pos >= n) return false;
    const std::uint8_t marker = d[pos++];
    if (marker == 0xD9) return true;                                     // EOI
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // no length field
    if (marker == 0x00 || marker == 0xD8) return false;
    if (n - pos < 2) return false;
    const std::size_t len = (std::size_t{d[pos]} << 8) | d[pos + 1];
    if (len < 2 || len > n - pos) return false;
    pos += len;
    if (marker != 0xDA) continue;
    // After a scan header (SOS) comes entropy-coded data, in which 0xFF is followed by a stuffed
    // 0x00 or a restart marker RSTn; any other code ends the scan (T.81 §B.1.1.5, F.1.2.3).
    for (;;) {
      if (pos >= n) return false;
      const void* ff = std::memchr(d.data() + pos, 0xFF, n - pos);
      if (ff == nullptr) return false;
      std::size_t q = static_cast<std::size_t>(static_cast<const std::uint8_t*>(ff) - d.data()) + 1;
      while (q < n && d[q] == 0xFF) ++q;
      if (q >= n) return false;
      if (d[q] == 0x00 || (d[q] >= 0xD0 && d[q] <= 0xD7)) {
        pos = q + 1;
        continue;
      }
      pos = q - 1;  // the 0xFF just before the code
      break;
    }
  }
}

}  // namespace hk::vision::detail
