// Fuzz harness: file names on a stranger's stick (vision/include/vision/stick_scan.hpp).
//
// Entry points: hk::vision::safe_display_name (a raw name made safe to speak and show) and
// hk::vision::sniff_document_format (a file's kind from its first bytes). Properties of the safe name:
//  - valid UTF-8, at most 255 bytes, no C0/C1 control, DEL, bidirectional control, invisible format
//    character or line/paragraph separator (the documented list);
//  - empty exactly when the input is empty;
//  - idempotent: a safe name stays as it is;
//  - equal to an independent reference implementation of the documented rules (maximal-subpart U+FFFD
//    replacement, removal, cut at the longest prefix of at most 252 bytes + "…" when over 255 bytes).
// sniff_document_format returns one of the documented kinds and only looks at the first 16 bytes.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_common.hpp"
#include "vision/stick_scan.hpp"

namespace {

bool dropped(char32_t cp) {
  return cp < 0x20 || (cp >= 0x7F && cp <= 0x9F) || cp == 0x061C || cp == 0x200E || cp == 0x200F ||
         (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069) || (cp >= 0x200B && cp <= 0x200D) ||
         cp == 0xFEFF || cp == 0x2028 || cp == 0x2029 || cp == 0x2060;
}

void put(std::string& out, char32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

/// Reference: the whole name cleaned (no cut), one character at a time; written independently of
/// stick_scan.cpp from the documented rules (Unicode 15 §3.9, "U+FFFD substitution of maximal subparts").
std::string reference_clean(std::string_view raw) {
  std::string out;
  std::size_t i = 0;
  while (i < raw.size()) {
    // The longest prefix of raw[i..] that is a prefix of some well-formed sequence.
    std::size_t best = 0;
    bool complete = false;
    char32_t cp = 0;
    for (std::size_t len = 1; len <= 4 && i + len <= raw.size(); ++len) {
      char32_t c = 0;
      bool whole = false;
      bool prefix_ok = false;
      // Is raw[i..i+len) a complete well-formed sequence, or a prefix of one?
      const std::string_view s = raw.substr(i, len);
      if (hk::fuzz::for_each_utf8(s, [&](char32_t x) { c = x; })) {
        whole = true;
        prefix_ok = true;
      } else {
        // A prefix of a well-formed sequence: some continuation makes it whole. Every allowed range of a
        // second byte (80-BF, A0-BF, 80-9F, 90-BF, 80-8F) holds one of 80, 90, A0.
        for (unsigned tail : {0x80u, 0x90u, 0xA0u}) {
          if (prefix_ok) break;
          std::string t(s);
          while (t.size() < 4) {
            t += static_cast<char>(tail);
            std::size_t count = 0;
            if (hk::fuzz::for_each_utf8(t, [&](char32_t) { ++count; }) && count == 1) {
              prefix_ok = true;
              break;
            }
          }
        }
      }
      if (!prefix_ok) break;
      best = len;
      if (whole) {
        complete = true;
        cp = c;
        break;
      }
    }
    if (complete) {
      if (!dropped(cp)) put(out, cp);
      i += best;
    } else {
      put(out, 0xFFFD);
      i += best == 0 ? 1 : best;
    }
  }
  return out;
}

std::string reference(std::string_view raw) {
  std::string clean = reference_clean(raw);
  if (clean.size() > 255) {
    std::size_t cut = 252;
    while (cut > 0 && (static_cast<unsigned char>(clean[cut]) & 0xC0) == 0x80) --cut;  // a character boundary
    clean.resize(cut);
    clean += "\xE2\x80\xA6";
  }
  if (clean.empty() && !raw.empty()) clean = "\xEF\xBF\xBD";
  return clean;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view raw(reinterpret_cast<const char*>(data), size);
  const std::string safe = hk::vision::safe_display_name(raw);
  FUZZ_CHECK(safe.size() <= 255, safe);
  FUZZ_CHECK(safe.empty() == raw.empty(), safe);
  bool clean = true;
  FUZZ_CHECK(hk::fuzz::for_each_utf8(safe, [&](char32_t cp) { clean = clean && !dropped(cp); }), safe);
  FUZZ_CHECK(clean, safe);
  FUZZ_CHECK(hk::fuzz::is_one_line(safe), safe);
  FUZZ_CHECK(hk::vision::safe_display_name(safe) == safe, safe);
  if (size <= 4096) {  // the reference is quadratic-ish; long names are covered by the properties above
    FUZZ_CHECK(safe == reference(raw), safe + " | reference: " + reference(raw));
  }

  const std::string kind = hk::vision::sniff_document_format(raw);
  FUZZ_CHECK(kind.empty() || kind == "png" || kind == "jpeg" || kind == "bmp" || kind == "tiff" || kind == "webp" ||
                 kind == "pdf",
             kind);
  FUZZ_CHECK(hk::vision::sniff_document_format(raw.substr(0, 16)) == kind, kind);
  return 0;
}
