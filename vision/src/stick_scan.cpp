// The scan of a USB stick handed in by a stranger: a bounded walk that cannot be
// led outside the stick, and the re-open of a document it found.
//
// Every folder and file is opened with openat2(2) relative to the folder that listed it, with
// RESOLVE_BENEATH | RESOLVE_NO_SYMLINKS | RESOLVE_NO_XDEV | RESOLVE_NO_MAGICLINKS and O_NOFOLLOW, so a
// symlink, a "..", a magic link or a mount point inside the stick is refused by the kernel. Entries are
// classified from the directory entry type (d_type; fstatat(AT_SYMLINK_NOFOLLOW) when the filesystem
// does not report it) before anything is opened, so a FIFO, a socket or a device node is never opened;
// files are opened O_NONBLOCK and checked with fstat after the open, which closes the race of an entry
// swapped between the listing and the open. Each folder's entries are read (within the entry budget),
// sorted by name and then visited, so the walk — and which entries a limit cuts off — is the same on
// every scan of the same stick.
//
// Hidden entries: a name starting with '.' (.Trash-1000, .fseventsd, .Spotlight-V100, macOS "._*"
// AppleDouble files) and the Windows system folders "System Volume Information" and "$RECYCLE.BIN" are
// refused with a reason, without being opened or entered.

#include "vision/stick_scan.hpp"
#include "hk/text.hpp"

#include "hk/error.hpp"
#include "hk/unique_fd.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <linux/openat2.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <system_error>
#include <utility>

namespace hk::vision {
namespace {

constexpr std::uint64_t kResolve = RESOLVE_BENEATH | RESOLVE_NO_SYMLINKS | RESOLVE_NO_XDEV | RESOLVE_NO_MAGICLINKS;
constexpr std::size_t kMagicBytes = 16;

using Fd = hk::UniqueFd;

std::string errno_text(int e) { return std::generic_category().message(e); }

/// openat2 with the walk's resolve rules; retried on EINTR and (a few times) on EAGAIN, which the kernel
/// returns when a concurrent rename raced a RESOLVE_BENEATH lookup. Returns the fd or -errno.
int open_beneath(int dirfd, const char* name, std::uint64_t flags) {
  open_how how;
  std::memset(&how, 0, sizeof how);
  how.flags = flags | O_NOFOLLOW | O_CLOEXEC;
  how.resolve = kResolve;
  for (int attempt = 0;; ++attempt) {
    const long fd = ::syscall(SYS_openat2, dirfd, name, &how, sizeof how);
    if (fd >= 0) return static_cast<int>(fd);
    const int e = errno;
    if (e == EINTR || (e == EAGAIN && attempt < 3)) continue;
    return -e;
  }
}

/// Reason for an entry that is not a regular file or folder, from its st_mode type bits; "" for a
/// regular file or folder.
std::string reason_for_mode(mode_t mode) {
  if (S_ISREG(mode) || S_ISDIR(mode)) return "";
  if (S_ISLNK(mode)) return "a symbolic link (links are not followed)";
  if (S_ISFIFO(mode)) return "a named pipe (FIFO), not a file";
  if (S_ISSOCK(mode)) return "a socket, not a file";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device node, not a file";
  return "not a regular file or folder";
}

/// Reason for a failed open of an entry that was listed as a file or folder.
std::string reason_for_open_error(int e, bool folder) {
  switch (e) {
    case ELOOP:
      return "a symbolic link (links are not followed)";
    case EXDEV:
      return "on another filesystem (mount points are not entered)";
    case ENOENT:
      return "vanished during the scan";
    case ENOTDIR:
      return "not a folder any more (changed during the scan)";
    case EAGAIN:
      return "changed during the scan (renamed while being opened)";
    default:
      return std::string(folder ? "the folder cannot be opened: " : "the file cannot be opened: ") + errno_text(e);
  }
}

bool ascii_iequal(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; };
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

/// Reason to leave out a hidden or system entry without opening it, or "".
std::string reason_for_hidden(std::string_view name, bool folder) {
  if (name.starts_with("._")) return "a macOS metadata file (name starts with \"._\"), not a document";
  if (name.starts_with("."))
    return folder ? "a hidden folder (name starts with '.'), not entered"
                  : "a hidden file (name starts with '.'), not listed";
  if (ascii_iequal(name, "System Volume Information") || ascii_iequal(name, "$RECYCLE.BIN")) {
    return folder ? "a Windows system folder, not entered" : "a Windows system file, not listed";
  }
  return "";
}

/// One directory entry: its name (raw bytes) and d_type.
struct Entry {
  std::string name;
  unsigned char type = DT_UNKNOWN;
};

using Clock = std::chrono::steady_clock;

/// The state of one scan.
class Walker {
 public:
  Walker(const ScanLimits& limits, StickScan& out) : limits_(limits), out_(out), start_(Clock::now()) {}

  /// Visits the folder `dirfd` at `depth` (the root is 0) whose path is `prefix` ("" for the root).
  void walk(int dirfd, const std::string& prefix, int depth) {
    std::vector<Entry> entries = read_entries(dirfd, prefix);
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.name < b.name; });
    for (const Entry& e : entries) {
      if (stopped_ || out_of_time()) return;
      visit(dirfd, prefix.empty() ? e.name : prefix + "/" + e.name, e, depth + 1);
    }
  }

  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  /// Stops the walk (the first limit met is the one reported).
  void stop(std::string why) {
    if (!out_.complete) return;
    out_.complete = false;
    out_.stopped_by = std::move(why);
  }

  bool out_of_time() {
    if (seconds() <= limits_.max_seconds) return false;
    char buf[128];
    std::snprintf(buf, sizeof buf,
                  "time limit: the walk took longer than %g s; the rest of the stick was not looked at",
                  limits_.max_seconds);
    stop(buf);
    stopped_ = true;
    return true;
  }

  void refuse(const std::string& path, std::string reason, bool document = false) {
    out_.refused.push_back({safe_display_name(path), std::move(reason), document});
  }

  /// The folder's entries (without "." and ".."), as many as the entry budget allows; counts them.
  std::vector<Entry> read_entries(int dirfd, const std::string& prefix) {
    std::vector<Entry> entries;
    alignas(8) char buf[32768];
    for (;;) {
      const long n = ::syscall(SYS_getdents64, dirfd, buf, sizeof buf);
      if (n < 0) {
        if (errno == EINTR) continue;
        refuse(prefix, "the folder cannot be read completely: " + errno_text(errno));
        return entries;
      }
      if (n == 0) return entries;
      for (long off = 0; off < n;) {
        dirent64 d;
        std::memcpy(&d, buf + off, offsetof(dirent64, d_name));  // the header; the name follows it
        const char* name = buf + off + offsetof(dirent64, d_name);
        off += d.d_reclen;
        if (std::strcmp(name, ".") == 0 || std::strcmp(name, "..") == 0) continue;
        if (stopped_ || out_of_time()) return entries;
        if (out_.entries_scanned >= limits_.max_entries) {
          entries_exhausted_ = true;
          stop("entry limit: the stick has more than " + std::to_string(limits_.max_entries) +
               " entries; the rest were not looked at");
          return entries;
        }
        ++out_.entries_scanned;
        entries.push_back({name, d.d_type});
      }
    }
  }

  void visit(int dirfd, const std::string& path, const Entry& e, int depth) {
    unsigned char type = e.type;
    if (type == DT_UNKNOWN) {  // the filesystem does not say: ask, without following a link
      struct stat st;
      if (::fstatat(dirfd, e.name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) {
        refuse(path, "cannot be examined: " + errno_text(errno));
        return;
      }
      type = S_ISDIR(st.st_mode)    ? DT_DIR
             : S_ISREG(st.st_mode)  ? DT_REG
             : S_ISLNK(st.st_mode)  ? DT_LNK
             : S_ISFIFO(st.st_mode) ? DT_FIFO
             : S_ISSOCK(st.st_mode) ? DT_SOCK
             : S_ISCHR(st.st_mode)  ? DT_CHR
             : S_ISBLK(st.st_mode)  ? DT_BLK
                                    : DT_WHT;
    }
    switch (type) {
      case DT_DIR:
        return visit_folder(dirfd, path, e.name, depth);
      case DT_REG:
        return visit_file(dirfd, path, e.name);
      case DT_LNK:
        return refuse(path, "a symbolic link (links are not followed)");
      case DT_FIFO:
        return refuse(path, "a named pipe (FIFO), not a file");
      case DT_SOCK:
        return refuse(path, "a socket, not a file");
      case DT_CHR:
      case DT_BLK:
        return refuse(path, "a device node, not a file");
      default:
        return refuse(path, "not a regular file or folder");
    }
  }

  void visit_folder(int dirfd, const std::string& path, const std::string& name, int depth) {
    if (std::string r = reason_for_hidden(name, true); !r.empty()) return refuse(path, std::move(r));
    if (depth > limits_.max_depth) {
      return refuse(path, "folder deeper than " + std::to_string(limits_.max_depth) + " levels is not entered");
    }
    if (entries_exhausted_) {
      return refuse(path,
                    "folder not entered: the limit of " + std::to_string(limits_.max_entries) + " entries was reached");
    }
    const Fd fd(open_beneath(dirfd, name.c_str(), O_RDONLY | O_DIRECTORY));
    if (!fd.ok()) return refuse(path, reason_for_open_error(-fd.get(), true));
    walk(fd.get(), path, depth);
  }

  void visit_file(int dirfd, const std::string& path, const std::string& name) {
    if (std::string r = reason_for_hidden(name, false); !r.empty()) return refuse(path, std::move(r));
    int fdn = -EPERM;
    if (try_noatime_) {  // leave the access time alone where we may (the owner, or CAP_FOWNER)
      fdn = open_beneath(dirfd, name.c_str(), O_RDONLY | O_NONBLOCK | O_NOATIME);
      if (fdn == -EPERM) try_noatime_ = false;
    }
    if (fdn == -EPERM) fdn = open_beneath(dirfd, name.c_str(), O_RDONLY | O_NONBLOCK);
    const Fd fd(fdn);
    if (!fd.ok()) return refuse(path, reason_for_open_error(-fd.get(), false));
    struct stat st;
    if (::fstat(fd.get(), &st) != 0) return refuse(path, "cannot be examined: " + errno_text(errno));
    if (std::string r = reason_for_mode(st.st_mode); !r.empty()) return refuse(path, std::move(r));
    if (S_ISDIR(st.st_mode)) return refuse(path, "changed into a folder during the scan");
    if (st.st_size == 0) return refuse(path, "empty file (0 bytes)");
    char head[kMagicBytes];
    long got;
    do {
      got = ::pread(fd.get(), head, sizeof head, 0);
    } while (got < 0 && errno == EINTR);
    if (got < 0) return refuse(path, "cannot be read: " + errno_text(errno));
    const std::string format = sniff_document_format(std::string_view(head, static_cast<std::size_t>(got)));
    if (format.empty()) return refuse(path, "not a picture or PDF (unknown format)");
    if (st.st_size > limits_.max_file_bytes) {
      return refuse(path,
                    "file size " + std::to_string(st.st_size) + " bytes exceeds the limit of " +
                        std::to_string(limits_.max_file_bytes) + " bytes",
                    true);
    }
    if (limits_.picture_check && format != "pdf") {  // refused here, with the others, not when visited
      std::string why =
          limits_.picture_check(fd.get(), static_cast<std::uint64_t>(st.st_size), safe_display_name(path));
      if (!why.empty()) return refuse(path, std::move(why), true);
    }
    if (static_cast<long>(out_.documents.size()) >= limits_.max_documents) {
      const std::string why =
          "document limit: more than " + std::to_string(limits_.max_documents) + " documents; the rest were not listed";
      refuse(path, "over the limit of " + std::to_string(limits_.max_documents) + " documents");
      stop(why);
      stopped_ = true;
      return;
    }
    StickDocument d;
    d.path = path;
    d.display_name = safe_display_name(path);
    d.kind = format == "pdf" ? DocumentKind::Pdf : DocumentKind::Image;
    d.format = format;
    d.bytes = st.st_size;
    out_.documents.push_back(std::move(d));
  }

  const ScanLimits& limits_;
  StickScan& out_;
  Clock::time_point start_;
  bool stopped_ = false;            ///< time or documents: nothing more is visited
  bool entries_exhausted_ = false;  ///< entries: what was read is still classified, no folder is entered
  bool try_noatime_ = true;
};

void check_limits(const ScanLimits& l) {
  auto bad = [](const std::string& what, const std::string& value) {
    throw hk::ArgumentError("scan_stick: limit " + what + " must be positive (got " + value + ")");
  };
  if (l.max_depth <= 0) bad("max_depth", std::to_string(l.max_depth));
  if (l.max_entries <= 0) bad("max_entries", std::to_string(l.max_entries));
  if (l.max_documents <= 0) bad("max_documents", std::to_string(l.max_documents));
  if (l.max_file_bytes <= 0) bad("max_file_bytes", std::to_string(l.max_file_bytes));
  if (!(l.max_seconds > 0.0) || !std::isfinite(l.max_seconds))
    bad("max_seconds (finite)", std::to_string(l.max_seconds));
}

/// The root folder, opened as a folder and checked to accept openat2 (Linux 5.6 or later).
int open_root(const std::string& root, const char* what) {
  const int plain = ::open(root.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (plain < 0) {
    const int e = errno;
    throw StickError(std::string(what) + " '" + safe_display_name(root) + "': " +
                     (e == ENOTDIR ? std::string("not a folder") : "cannot be opened as a folder: " + errno_text(e)));
  }
  const Fd guard(plain);
  const int fd = open_beneath(plain, ".", O_RDONLY | O_DIRECTORY);
  if (fd < 0) {
    throw StickError(std::string(what) + " '" + safe_display_name(root) + "': " +
                     (fd == -ENOSYS ? std::string("openat2 is not available (Linux 5.6 or later is needed)")
                                    : "cannot be opened with openat2: " + errno_text(-fd)));
  }
  return fd;
}

/// Appends the UTF-8 encoding of `cp` (a valid scalar value).
void put_utf8(std::string& out, char32_t cp) {
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

/// True for the characters safe_display_name drops.
bool dropped(char32_t cp) {
  return cp < 0x20 || (cp >= 0x7F && cp <= 0x9F)            // C0, DEL, C1
         || cp == 0x061C || cp == 0x200E || cp == 0x200F    // bidi marks
         || (cp >= 0x202A && cp <= 0x202E)                  // bidi embeddings and overrides
         || (cp >= 0x2066 && cp <= 0x2069)                  // bidi isolates
         || (cp >= 0x200B && cp <= 0x200D) || cp == 0xFEFF  // zero-width space, joiners, BOM
         || cp == 0x2028 || cp == 0x2029 || cp == 0x2060;   // line and paragraph separators, word joiner
}

}  // namespace

std::string sniff_document_format(std::string_view h) {
  auto at = [&](std::size_t off, std::string_view magic) {
    return h.size() >= off + magic.size() && h.substr(off, magic.size()) == magic;
  };
  if (at(0, std::string_view("\x89PNG\r\n\x1a\n", 8))) return "png";
  if (at(0, "\xFF\xD8\xFF")) return "jpeg";
  if (at(0, std::string_view("II*\0", 4)) || at(0, std::string_view("MM\0*", 4)) ||
      at(0, std::string_view("II+\0", 4)) || at(0, std::string_view("MM\0+", 4))) {
    return "tiff";
  }
  if (at(0, "RIFF") && at(8, "WEBP")) return "webp";
  if (at(0, "%PDF-")) return "pdf";
  if (at(0, "BM")) {
    // "BM" alone is weak (a text file may start so); when the first 16 bytes are there, the low half of
    // the DIB header size at offset 14 must be one of the known sizes.
    if (h.size() < 16) return "bmp";
    const unsigned dib =
        static_cast<unsigned char>(h[14]) | (static_cast<unsigned>(static_cast<unsigned char>(h[15])) << 8);
    for (unsigned known : {12u, 16u, 40u, 52u, 56u, 64u, 108u, 124u}) {
      if (dib == known) return "bmp";
    }
    return "";
  }
  return "";
}

std::string safe_display_name(std::string_view raw) {
  static constexpr char32_t kReplacement = 0xFFFD;
  static constexpr std::size_t kMaxBytes = 255;
  std::string out;
  out.reserve(std::min<std::size_t>(raw.size(), 2 * kMaxBytes));
  std::size_t cut = 0;  // the last character boundary at which "…" (3 bytes) still fits in kMaxBytes
  auto emit = [&](char32_t cp) {
    if (dropped(cp)) return;
    put_utf8(out, cp);
    if (out.size() + 3 <= kMaxBytes) cut = out.size();
  };
  // An ill-formed sequence is replaced, one U+FFFD per maximal subpart (hk::decode_utf8).
  for (std::size_t i = 0; i < raw.size() && out.size() <= kMaxBytes;) {
    const hk::Utf8Step u = hk::decode_utf8(raw, i);
    emit(u.well_formed ? u.code_point : kReplacement);
    i += u.length;
  }
  if (out.size() > kMaxBytes) {
    out.resize(cut);
    out += "\xE2\x80\xA6";  // …
  }
  if (out.empty() && !raw.empty()) put_utf8(out, kReplacement);  // never an empty name for a non-empty one
  return out;
}

StickScan scan_stick(const std::string& root, const ScanLimits& limits) {
  check_limits(limits);
  const Fd root_fd(open_root(root, "stick"));
  StickScan out;
  Walker walker(limits, out);
  walker.walk(root_fd.get(), "", 0);
  std::sort(out.documents.begin(), out.documents.end(),
            [](const StickDocument& a, const StickDocument& b) { return a.path < b.path; });
  if (!out.complete) out.refused.push_back({"", out.stopped_by});
  out.seconds = walker.seconds();
  return out;
}

std::vector<std::uint8_t> read_stick_file(const std::string& root, const std::string& relative_path,
                                          std::int64_t max_bytes) {
  auto fail = [&](const std::string& problem) -> StickError {
    return StickError("stick file '" + safe_display_name(relative_path) + "': " + problem);
  };
  if (max_bytes <= 0) throw fail("the size limit " + std::to_string(max_bytes) + " is not positive");
  if (relative_path.empty()) throw fail("empty path");
  if (relative_path.find('\0') != std::string::npos) throw fail("the path contains a NUL byte");
  if (relative_path.front() == '/') throw fail("the path is absolute, not relative to the stick");
  for (std::size_t start = 0; start <= relative_path.size();) {
    std::size_t end = relative_path.find('/', start);
    if (end == std::string::npos) end = relative_path.size();
    const std::string_view part(relative_path.data() + start, end - start);
    if (part.empty() || part == "." || part == "..") throw fail("the path has an empty, '.' or '..' component");
    start = end + 1;
  }
  int root_raw;
  try {
    root_raw = open_root(root, "stick");
  } catch (const StickError& e) {
    throw fail(e.what());
  }
  const Fd root_fd(root_raw);
  auto open_error = [&](int e) -> StickError {
    if (e == ELOOP) return fail("a symbolic link on the way (links are not followed)");
    if (e == EXDEV) return fail("leads outside the stick or into another filesystem");
    if (e == ENOENT) return fail("no such file");
    if (e == ENOTDIR) return fail("a part of the path is not a folder");
    return fail("cannot be opened: " + errno_text(e));
  };
  auto check_type = [&](const struct stat& st) {
    if (S_ISDIR(st.st_mode)) throw fail("a folder, not a file");
    if (std::string r = reason_for_mode(st.st_mode); !r.empty()) throw fail(r);
  };
  // First an O_PATH look (opens nothing: a device, FIFO or trailing link is seen, not opened), then the
  // real open, which must find the same file.
  struct stat seen;
  {
    const Fd path_fd(open_beneath(root_fd.get(), relative_path.c_str(), O_PATH));
    if (!path_fd.ok()) throw open_error(-path_fd.get());
    if (::fstat(path_fd.get(), &seen) != 0) throw fail("cannot be examined: " + errno_text(errno));
    check_type(seen);
  }
  const Fd fd(open_beneath(root_fd.get(), relative_path.c_str(), O_RDONLY | O_NONBLOCK));
  if (!fd.ok()) throw open_error(-fd.get());
  struct stat st;
  if (::fstat(fd.get(), &st) != 0) throw fail("cannot be examined: " + errno_text(errno));
  check_type(st);
  if (st.st_dev != seen.st_dev || st.st_ino != seen.st_ino) throw fail("changed while being opened");
  if (st.st_size > max_bytes) {
    throw fail("file size " + std::to_string(st.st_size) + " bytes exceeds the limit of " + std::to_string(max_bytes) +
               " bytes");
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(st.st_size));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const long got = ::read(fd.get(), bytes.data() + done, bytes.size() - done);
    if (got < 0) {
      if (errno == EINTR) continue;
      throw fail("cannot be read: " + errno_text(errno));
    }
    if (got == 0)
      throw fail("changed while being read (shorter than its size of " + std::to_string(st.st_size) + " bytes)");
    done += static_cast<std::size_t>(got);
  }
  std::uint8_t extra;
  long more;
  do {
    more = ::read(fd.get(), &extra, 1);
  } while (more < 0 && errno == EINTR);
  if (more > 0)
    throw fail("changed while being read (longer than its size of " + std::to_string(st.st_size) + " bytes)");
  return bytes;
}

}  // namespace hk::vision
