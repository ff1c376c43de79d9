#pragma once
// Shared helpers of the libFuzzer harnesses (fuzz/fuzz_*.cpp, built only with HK_FUZZ=ON under clang).
//
// A harness checks properties, not only "no crash": FUZZ_CHECK aborts (a crash libFuzzer records, with
// the input saved as crash-<sha1>) and prints which property failed and the text involved.

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace hk::fuzz {

[[noreturn]] inline void property_failed(const char* file, int line, const char* cond, std::string_view detail) {
  std::fprintf(stderr, "\n==FUZZ PROPERTY FAILED== %s:%d: %s\n", file, line, cond);
  if (!detail.empty()) {
    std::fprintf(stderr, "  detail (%zu bytes): ", detail.size());
    for (const char c : detail.substr(0, 2000)) {
      const auto u = static_cast<unsigned char>(c);
      if (u < 0x20 || u == 0x7F) {
        std::fprintf(stderr, "\\x%02X", u);
      } else {
        std::fputc(c, stderr);
      }
    }
    std::fputc('\n', stderr);
  }
  std::abort();
}

/// True when `s` prints on one line as hk::one_line (common/include/hk/text.hpp) promises: no C0 control
/// character (newline, carriage return, tab, escape...), no DEL, and no C1 control (U+0080-U+009F, UTF-8
/// C2 80..C2 9F, e.g. U+0085 NEXT LINE).
inline bool is_one_line(std::string_view s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto u = static_cast<unsigned char>(s[i]);
    if (u < 0x20 || u == 0x7F) return false;
    if (u == 0xC2 && i + 1 < s.size() && static_cast<unsigned char>(s[i + 1]) >= 0x80 &&
        static_cast<unsigned char>(s[i + 1]) <= 0x9F) {
      return false;
    }
  }
  return true;
}

/// Strict UTF-8 (Unicode table 3-7: no overlong forms, no surrogates, nothing above U+10FFFF).
/// Calls `each(code_point)` for every character; returns false at the first ill-formed sequence.
template <typename F>
bool for_each_utf8(std::string_view s, F&& each) {
  const auto* p = reinterpret_cast<const unsigned char*>(s.data());
  const std::size_t n = s.size();
  for (std::size_t i = 0; i < n;) {
    const unsigned char b = p[i];
    std::size_t len = 0;
    char32_t cp = 0;
    unsigned char lo = 0x80, hi = 0xBF;
    if (b < 0x80) {
      len = 1;
      cp = b;
    } else if (b >= 0xC2 && b <= 0xDF) {
      len = 2;
      cp = b & 0x1F;
    } else if (b >= 0xE0 && b <= 0xEF) {
      len = 3;
      cp = b & 0x0F;
      if (b == 0xE0) lo = 0xA0;
      if (b == 0xED) hi = 0x9F;
    } else if (b >= 0xF0 && b <= 0xF4) {
      len = 4;
      cp = b & 0x07;
      if (b == 0xF0) lo = 0x90;
      if (b == 0xF4) hi = 0x8F;
    } else {
      return false;
    }
    if (n - i < len) return false;
    for (std::size_t k = 1; k < len; ++k) {
      const unsigned char c = p[i + k];
      if (k == 1 ? (c < lo || c > hi) : (c < 0x80 || c > 0xBF)) return false;
      cp = (cp << 6) | (c & 0x3F);
    }
    each(cp);
    i += len;
  }
  return true;
}

inline bool is_valid_utf8(std::string_view s) {
  return for_each_utf8(s, [](char32_t) {});
}

/// An anonymous in-memory file (memfd) that a path-only API can open as "/proc/self/fd/N", refilled per
/// run: no temporary file on disk, nothing left behind.
class MemFile {
 public:
  MemFile() : fd_(::memfd_create("hk-fuzz", MFD_CLOEXEC)) {
    if (fd_ < 0) property_failed(__FILE__, __LINE__, "memfd_create", "");
    path_ = "/proc/self/fd/" + std::to_string(fd_);
  }
  ~MemFile() { ::close(fd_); }
  MemFile(const MemFile&) = delete;
  MemFile& operator=(const MemFile&) = delete;

  /// Replaces the file's contents with `data`; returns its path.
  const std::string& set(const std::uint8_t* data, std::size_t size) {
    if (::ftruncate(fd_, 0) != 0) property_failed(__FILE__, __LINE__, "ftruncate", "");
    std::size_t off = 0;
    while (off < size) {
      const ssize_t w = ::pwrite(fd_, data + off, size - off, static_cast<off_t>(off));
      if (w <= 0) property_failed(__FILE__, __LINE__, "pwrite", "");
      off += static_cast<std::size_t>(w);
    }
    return path_;
  }
  const std::string& path() const { return path_; }

 private:
  int fd_;
  std::string path_;
};

}  // namespace hk::fuzz

/// Aborts with a report when `cond` is false; `detail` (a string) is printed with control characters escaped.
#define FUZZ_CHECK(cond, detail)                                                   \
  do {                                                                             \
    if (!(cond)) ::hk::fuzz::property_failed(__FILE__, __LINE__, #cond, (detail)); \
  } while (0)
