#pragma once
/// @file stick_scan.hpp
/// What a USB stick offers: a bounded, symlink-proof walk of a mounted stick.
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
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>
#include "hk/error.hpp"

namespace hk::vision {

/// Limits of one scan. Defaults are the config's (`[stick]`). All must be positive.
struct ScanLimits {
  int max_depth = 8;                          ///< deepest folder entered; the root is depth 0
  long max_entries = 10000;                   ///< directory entries looked at, over the whole walk
  int max_documents = 500;                    ///< documents listed; later ones are refused
  std::int64_t max_file_bytes = 200LL << 20;  ///< largest document [bytes] (200 MB)
  double max_seconds = 2.0;                   ///< wall-clock time of the walk [s]
  /// When set, called for each picture (not a PDF) with its open file descriptor, its size [bytes] and its
  /// safe name; a non-empty answer (one line) refuses it as a document that cannot be read, so that what a
  /// stick offers is what can be shown. The kiosk passes vision::image_header_problem (intake.hpp); empty: the
  /// magic bytes alone decide. Kept as a function so the walk itself needs no image library.
  std::function<std::string(int fd, std::uint64_t size_bytes, const std::string& name)> picture_check;
};

/// Kind of a document, from its magic bytes.
enum class DocumentKind { Image, Pdf };

/// A document found on a stick.
struct StickDocument {
  std::string path;          ///< relative to the stick's root, '/'-separated, raw bytes as on the stick (for opening)
  std::string display_name;  ///< the path made safe for speech and display (safe_display_name)
  DocumentKind kind = DocumentKind::Image;
  std::string format;      ///< "png", "jpeg", "bmp", "tiff", "webp" or "pdf" (from the magic bytes)
  std::int64_t bytes = 0;  ///< file size [bytes]
};

/// An entry left out, and why.
struct RefusedEntry {
  std::string path;    ///< relative to the root, made safe (safe_display_name)
  std::string reason;  ///< one line, e.g. "a symbolic link (links are not followed)"
  /// A picture or PDF by its bytes that cannot be read (a damaged header, over the size limit, a PDF the
  /// worker refuses): what a visitor is told of, counted. Else a link, a device, another kind of file.
  bool document = false;
};

/// Result of a scan. Documents are sorted by path (byte order), so the order is stable between scans.
struct StickScan {
  std::vector<StickDocument> documents;
  std::vector<RefusedEntry> refused;
  long entries_scanned = 0;  ///< directory entries looked at ("." and ".." not counted); never above max_entries
  bool complete = true;      ///< false when a limit (entries, documents, time) stopped the walk early
  std::string stopped_by;    ///< when !complete: which limit, one line (also added to `refused` as path "")
  double seconds = 0.0;      ///< wall-clock time of the walk [s]
};

/// Refusal of the scan as a whole (the root cannot be opened, or is not a folder). One line naming it.
class StickError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// Walks the folder `root` (a mounted stick, or any folder for tests and `haptic-kiosk stick DIR`).
/// Never follows a symbolic link, never leaves the tree or its filesystem, reads of each regular file its
/// magic bytes and, with picture_check, what that reads of a picture (image_header_problem: its header, a few
/// hundred bytes, a JPEG's segments skipped), writes nothing.
///
/// Each folder's entries are sorted by name (byte order) before they are visited, so the walk, and what a
/// limit cuts off, is the same on every scan of an unchanged stick. FIFOs, sockets, device nodes and
/// symbolic links are refused from their directory entry type without being opened. Hidden entries (name
/// starting with '.', e.g. .Trash-1000, .fseventsd, macOS "._*" AppleDouble files) and the Windows system
/// folders "System Volume Information" and "$RECYCLE.BIN" are refused with a reason, never opened or
/// entered. A regular file is refused when empty, when its first bytes are not a document's, when it
/// is larger than max_file_bytes, or (picture_check) when it is a picture the check refuses (its line as the
/// reason), in that order; the last two are refusals of a document (RefusedEntry::document).
/// Limits while walking:
///  - a folder deeper than max_depth is refused ("folder deeper than 8 levels is not entered"), the walk goes on;
///  - entries: once max_entries entries have been counted and another one is met, the walk stops reading
///    folders; entries already read are still classified, folders among them are refused unentered;
///  - documents: the document after the max_documents-th is refused and the walk stops;
///  - time: the clock is read at every entry; past max_seconds the walk stops at once.
/// A stopping limit sets complete=false and stopped_by, which also ends `refused` (path "").
/// Failures on single entries (unreadable folder, open errors, entries vanishing) are refusals, not errors.
/// @throws StickError if root cannot be opened as a folder.
/// @throws hk::ArgumentError if a limit is not positive.
StickScan scan_stick(const std::string& root, const ScanLimits& limits);

/// The kind a file's first bytes announce: "png", "jpeg", "bmp", "tiff", "webp", "pdf", or "" (not a
/// document). `head` is the file's first bytes (16 are enough; fewer are fine for a short file).
/// PNG \x89PNG\r\n\x1a\n; JPEG FF D8 FF; TIFF "II*\0", "MM\0*" and BigTIFF "II+\0", "MM\0+";
/// WebP "RIFF" ???? "WEBP"; PDF "%PDF-" at offset 0; BMP "BM", and when 16 bytes are given, the low 16 bits
/// of the DIB header size at offset 14 must be a known size (12, 16, 40, 52, 56, 64, 108 or 124), since
/// "BM" alone also starts ordinary text.
std::string sniff_document_format(std::string_view head);

/// A file name or path (raw bytes) made safe to speak and show, on one line: invalid UTF-8 sequences
/// become U+FFFD; C0/C1 control characters, DEL, and the bidirectional controls (U+200E, U+200F,
/// U+202A..U+202E, U+2066..U+2069, U+061C) are removed; other invisible format characters (U+200B..U+200D,
/// U+FEFF) are removed; the result is cut at 255 bytes on a character boundary with "…".
/// Details: ill-formed UTF-8 (overlong forms, surrogates, values above U+10FFFF, truncated or stray bytes)
/// gives one U+FFFD per maximal subpart, as Unicode recommends; the line and paragraph separators U+2028,
/// U+2029 and the word joiner U+2060 are removed too; the result is always valid UTF-8 of at most 255
/// bytes, "…" included (a longer one keeps its longest prefix of at most 252 bytes that ends on a
/// character boundary, then "…"); a non-empty input that leaves nothing gives "\uFFFD", never "".
std::string safe_display_name(std::string_view raw);

/// Reads a whole document found by scan_stick, opening it again with the same openat2 rules relative to
/// `root` (so a link swapped in after the scan is refused), and checks it is still a regular file of at
/// most max_bytes.
/// `relative_path` is a StickDocument::path: relative, '/'-separated, raw bytes; an absolute path, or one
/// with an empty, "." or ".." component, is refused before anything is opened. The path is first looked
/// at with O_PATH (a device node, FIFO, socket or trailing link is refused without being opened), then
/// opened O_NONBLOCK and must still be the same regular file; one that shrinks or grows while read is refused.
/// @returns the file's bytes (its whole size, at most max_bytes).
/// @throws StickError (one line "stick file '<safe path>': <problem>"), also when max_bytes is not positive
///         or the root cannot be opened.
std::vector<std::uint8_t> read_stick_file(const std::string& root, const std::string& relative_path,
                                          std::int64_t max_bytes);

}  // namespace hk::vision
