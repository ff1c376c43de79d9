#pragma once
/// @file stick_scan.hpp
/// What a USB stick offers: a bounded, symlink-proof walk of a mounted stick (issue 11, item 2).
///
/// A stick comes from a stranger, so the walk treats it as hostile: every open is an openat2(2) with
/// RESOLVE_BENEATH | RESOLVE_NO_SYMLINKS | RESOLVE_NO_XDEV | RESOLVE_NO_MAGICLINKS and
/// O_NOFOLLOW | O_CLOEXEC relative to the stick's root, so no name (symlink, "..", magic link, another
/// mount) can lead outside it; only regular files are taken; a document's kind is decided by its first
/// bytes (PNG, JPEG, BMP, TIFF, WebP, "%PDF-"), never by its name; every limit (depth, entries, documents,
/// file size, time) is enforced while walking, and every entry left out gets a one-line reason.
/// File names are bytes: they are kept as found for opening, and made safe for speech and display with
/// safe_display_name.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace hk::vision {

/// Limits of one scan. Defaults are the config's (`[stick]`). All must be positive.
struct ScanLimits {
  int max_depth = 8;                         ///< deepest folder entered; the root is depth 0
  long max_entries = 10000;                  ///< directory entries looked at, over the whole walk
  int max_documents = 500;                   ///< documents listed; later ones are refused
  std::int64_t max_file_bytes = 200LL << 20; ///< largest document [bytes] (200 MB)
  double max_seconds = 2.0;                  ///< wall-clock time of the walk [s]
};

/// Kind of a document, from its magic bytes.
enum class DocumentKind { Image, Pdf };

/// A document found on a stick.
struct StickDocument {
  std::string path;          ///< relative to the stick's root, '/'-separated, raw bytes as on the stick (for opening)
  std::string display_name;  ///< the path made safe for speech and display (safe_display_name)
  DocumentKind kind = DocumentKind::Image;
  std::string format;        ///< "png", "jpeg", "bmp", "tiff", "webp" or "pdf" (from the magic bytes)
  std::int64_t bytes = 0;    ///< file size [bytes]
};

/// An entry left out, and why.
struct RefusedEntry {
  std::string path;    ///< relative to the root, made safe (safe_display_name)
  std::string reason;  ///< one line, e.g. "a symbolic link (links are not followed)"
};

/// Result of a scan. Documents are sorted by path (byte order), so the order is stable between scans.
struct StickScan {
  std::vector<StickDocument> documents;
  std::vector<RefusedEntry> refused;
  long entries_scanned = 0;  ///< directory entries looked at
  bool complete = true;      ///< false when a limit (entries, documents, time) stopped the walk early
  std::string stopped_by;    ///< when !complete: which limit, one line (also added to `refused` as path "")
  double seconds = 0.0;      ///< wall-clock time of the walk [s]
};

/// Refusal of the scan as a whole (the root cannot be opened, or is not a folder). One line naming it.
class StickError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Walks the folder `root` (a mounted stick, or any folder for tests and `haptic-kiosk stick DIR`).
/// Never follows a symbolic link, never leaves the tree or its filesystem, reads at most 16 bytes of each
/// regular file (its magic bytes), writes nothing.
/// @throws StickError if root cannot be opened as a folder.
/// @throws std::invalid_argument if a limit is not positive.
StickScan scan_stick(const std::string& root, const ScanLimits& limits);

/// The kind a file's first bytes announce: "png", "jpeg", "bmp", "tiff", "webp", "pdf", or "" (not a
/// document). `head` is the file's first bytes (16 are enough; fewer are fine for a short file).
std::string sniff_document_format(std::string_view head);

/// A file name or path (raw bytes) made safe to speak and show, on one line: invalid UTF-8 sequences
/// become U+FFFD; C0/C1 control characters, DEL, and the bidirectional controls (U+200E, U+200F,
/// U+202A..U+202E, U+2066..U+2069, U+061C) are removed; other invisible format characters (U+200B..U+200D,
/// U+FEFF) are removed; the result is cut at 255 bytes on a character boundary with "…".
std::string safe_display_name(std::string_view raw);

/// Reads a whole document found by scan_stick, opening it again with the same openat2 rules relative to
/// `root` (so a link swapped in after the scan is refused), and checks it is still a regular file of at
/// most max_bytes.
/// @throws StickError (one line naming the document and the problem).
std::vector<std::uint8_t> read_stick_file(const std::string& root, const std::string& relative_path, std::int64_t max_bytes);

}  // namespace hk::vision
