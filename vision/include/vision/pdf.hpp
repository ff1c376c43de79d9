#pragma once
/// @file pdf.hpp
/// PDF pages as pictures, with their text.
///
/// A PDF from a stick is hostile input, and poppler is a large parser: every poppler call runs in a
/// worker process, the executable hk-pdf-worker started with posix_spawn (not a fork of the kiosk, whose
/// other threads may hold locks a forked child would wait on forever), with RLIMIT_CPU and a wall-clock
/// kill, so a PDF that crashes or hangs poppler takes down only its worker. The worker is found as
/// $HK_PDF_WORKER, else beside the running executable, else where the build put it. The kiosk process itself never
/// calls poppler. The worker sends its answer back through a pipe; the parent reads it with poll(2) against the
/// deadline, then SIGKILLs and reaps the worker in every case (wait4, for the worker's peak memory).
///
/// Order inside the worker: poppler::document::load_from_raw_data, then is_locked() before anything
/// else (a locked document crashes pages() in Debian 12's poppler 22.12), then the page count (capped),
/// then the page: its words (page::text_list), then the page rendered in grey (poppler::page_renderer,
/// antialiasing on) at the DPI that keeps it within the pixel budget (or, with words and
/// text_layer_max_side_px set, within that side), the words put in the same pixel frame.

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>
#include "hk/error.hpp"

#include <opencv2/core.hpp>

namespace hk::vision {

/// Test hook: makes the worker fail on purpose as soon as it has started, before it touches poppler, so tests of
/// "a worker that crashes or hangs" need no special PDF. Never set outside tests.
enum class PdfFault {
  None,   ///< normal work
  Crash,  ///< the worker raises SIGSEGV (with the default action, so it dies of signal 11 even under ASan)
  Hang,   ///< the worker spins on the CPU forever (until RLIMIT_CPU or the wall-clock kill)
};

/// Limits of PDF work. Defaults are the config's (`[stick]`). All must be positive (worker_max_memory_mb and
/// text_layer_max_side_px may be 0).
struct PdfLimits {
  std::int64_t max_file_bytes = 200LL << 20;  ///< largest PDF [bytes]
  int max_pages = 1000;                       ///< pages offered; a longer document offers its first max_pages
  double max_page_pixels = 4e6;               ///< render budget [px]: DPI chosen so width x height <= this
  double max_dpi = 300.0;                     ///< never rendered finer than this [dots per inch]
  /// A page with a text layer (poppler finds words on it) is drawn with its long side at most this [px],
  /// below the budget's DPI, never above it: the size a screen shows it, since its text comes from the layer
  /// and not from OCR, which wants every pixel. A page without words is drawn at the full budget. 0 = always
  /// the full budget.
  double text_layer_max_side_px = 0.0;
  double worker_cpu_s = 5.0;   ///< RLIMIT_CPU of the worker [s]
  double worker_wall_s = 5.0;  ///< the worker is killed after this wall-clock time [s]
  /// Address space the worker may add to its size at start [MiB] (RLIMIT_AS, set in the worker to its size
  /// with the document mapped, plus this). Applied only in builds without AddressSanitizer (ASan reserves terabytes
  /// of shadow memory); there memory is only reported (worker_max_rss_kb). 0 = no limit.
  double worker_max_memory_mb = 2048.0;
  PdfFault fault = PdfFault::None;  ///< test hook only (PdfFault); None in the kiosk
};

/// What a PDF is, without rendering any page.
/// Longest document title passed on [bytes]: a longer Info /Title is no title a person would hear, and is dropped.
inline constexpr std::size_t kMaxPdfTitleBytes = 1024;

/// Longest language tag passed on [bytes] (BCP 47 tags the kiosk takes: hk::is_language_tag).
inline constexpr std::size_t kMaxLanguageTagBytes = 35;

/// A PDF's /Lang as a language tag the kiosk takes ("fr", "de-CH"): '_' made '-', the language subtag lower case;
/// "" when it is not a tag (hk::is_language_tag) or longer than kMaxLanguageTagBytes.
std::string pdf_language_tag(std::string_view lang);

struct PdfInfo {
  int pages = 0;  ///< pages offered (min(real pages, max_pages)), >= 1
  /// The document's title as its Info dictionary gives it (poppler's document::get_title, UTF-8), as written:
  /// unchecked text from a stranger's file — check it before speaking it (app::usable_note). Empty when it has
  /// none or it is longer than kMaxPdfTitleBytes.
  std::string title;
  /// The document's language, its catalog's /Lang as pdf_language_tag makes it ("fr"); "" when it does not say.
  std::string language;
  int pages_in_file = 0;       ///< pages the document has
  bool capped = false;         ///< pages_in_file > max_pages
  double worker_ms = 0.0;      ///< wall time of the worker [ms]
  long worker_max_rss_kb = 0;  ///< the worker's peak resident memory [KiB] (wait4's ru_maxrss)
};

/// One word (poppler text box) on a rendered page, in the page image's pixels (u right, v down, origin at
/// the top-left pixel's corner). Boxes are clipped to the page; words wholly outside it are dropped. The boxes
/// come from the font's metrics: with a substituted (not embedded) font, glyphs may spill a little over them.
struct PdfWord {
  std::string text;   ///< UTF-8
  cv::Rect2d box_px;  ///< bounding box [px]
  /// poppler's has_space_after(): false when the next word follows with no space on the same line (as
  /// "globs2" then "," in "globs2,"); group_text_blocks then joins the two without a space, as pdftotext
  /// does, when their boxes are less than 0.3 line heights apart.
  bool space_after = true;
};

/// A block of text (a paragraph or a heading): words grouped into lines, lines into blocks
/// (group_text_blocks).
struct TextBlock {
  cv::Rect2d box_px;  ///< union of its words' boxes [px]
  std::string text;   ///< its lines in reading order, words joined with single spaces (none after a word
                      ///< whose space_after is false and that the next word on its line touches)
  int lines = 0;      ///< number of lines
};

/// A rendered page.
struct PdfPage {
  cv::Mat grey;      ///< CV_8UC1, the page on white
  double dpi = 0.0;  ///< the DPI it was rendered at
  /// Drawn smaller than the budget allows, for its text layer (PdfLimits::text_layer_max_side_px). Reading
  /// text the layer leaves out needs the page drawn again at the full budget.
  bool screen_sized = false;
  double width_pt = 0, height_pt = 0;  ///< page size [pt] (1/72 inch), after its rotation
  std::vector<PdfWord> words;          ///< every word on the page, in poppler's reading order
  std::vector<TextBlock> blocks;       ///< words grouped (group_text_blocks)
  int pages = 0;                       ///< pages offered by the document (as PdfInfo::pages)
  std::string title;                   ///< the document's title, unchecked (as PdfInfo::title)
  std::string language;                ///< the document's language (as PdfInfo::language)
  double worker_ms = 0.0;              ///< wall time of the worker [ms]
  long worker_max_rss_kb = 0;          ///< the worker's peak resident memory [KiB] (as PdfInfo's)
};

/// A refused or unreadable PDF or page. what() is one line: "pdf '<name>': <problem>", e.g.
/// "pdf 'report.pdf': protected by a password", "pdf 'x.pdf': page 3 took longer than 5 s to draw".
class PdfError : public hk::Error {
 public:
  /// NotPdf: no "%PDF-" header; Damaged: poppler cannot read it; Locked: needs a password; NoSuchPage;
  /// TooLarge: a file, page or memory limit; Timeout: wall-clock or CPU limit; WorkerCrashed: the worker died.
  enum class Kind { NotPdf, Damaged, Locked, NoSuchPage, TooLarge, Timeout, WorkerCrashed };
  PdfError(Kind kind, const std::string& what) : hk::Error(what), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

/// Opens the document in a worker and counts its pages.
/// @param name   how to name it in errors (made printable on one line)
/// @throws PdfError (NotPdf: no "%PDF-" header; Damaged: poppler cannot load it or it has no page;
///         Locked: needs a password; TooLarge: over max_file_bytes; Timeout / WorkerCrashed);
///         hk::ArgumentError when a limit is not positive.
PdfInfo probe_pdf(std::span<const std::uint8_t> bytes, const std::string& name, const PdfLimits& limits);

/// Renders page `page` (from 1) in a worker: grey, at dpi = min(max_dpi, 72 · sqrt(max_page_pixels /
/// (width_pt · height_pt))) (lowered by a fraction of a percent when rounding up to whole pixels would
/// overshoot the budget), or lower for a page with a text layer when text_layer_max_side_px asks
/// (PdfPage::screen_sized), with its words and text blocks.
/// @throws PdfError as probe_pdf, plus NoSuchPage (page outside [1, pages offered]) and TooLarge (a page so
///         large that even 1 DPI would exceed the budget). Timeout: the worker outlived worker_wall_s or
///         used up worker_cpu_s; WorkerCrashed: it died (a signal, or an exit without an answer).
PdfPage render_pdf_page(std::span<const std::uint8_t> bytes, const std::string& name, int page,
                        const PdfLimits& limits);

/// Groups words into lines and lines into blocks, the way a reader sees paragraphs:
/// - a word joins a line when its vertical extent overlaps the line's by at least half of the smaller
///   height and the horizontal gap to the line's last word is under 1.5 x the line's height;
/// - a line joins a block when the vertical gap to the block's last line is under 1.0 x the line height,
///   the heights differ by less than a factor 1.5, and the lines overlap horizontally.
/// Blocks come out in reading order (top to bottom, then left to right).
std::vector<TextBlock> group_text_blocks(const std::vector<PdfWord>& words);

/// True when `bytes` start with "%PDF-" (after up to 1024 bytes of leading junk, as readers allow).
bool looks_like_pdf(std::span<const std::uint8_t> bytes);

/// Entry point of the worker executable (vision/worker/pdf_worker_main.cpp), not for other callers: maps the
/// document from descriptor 3, limits itself, runs poppler for the request in argv (page, max_pages,
/// max_page_pixels, max_dpi, text_layer_max_side_px, worker_cpu_s, worker_max_memory_mb, fault, document size), writes
/// the answer to descriptor 4 and exits. Returns 64-66 (never reaching poppler) for a malformed request.
int pdf_worker_entry(int argc, char** argv);

}  // namespace hk::vision
