#pragma once
/// @file ocr.hpp
/// Text in pictures of pages, read with Tesseract (OCR), so that a scan, a photo of a page or a PDF whose
/// pages are images is read aloud instead of felt as bumps.
///
/// Tesseract is a large engine run on a stranger's pixels: it runs only in the worker executable
/// hk-ocr-worker (worker_process.hpp: posix_spawn, the pixels in a sealed memfd, RLIMIT_CPU and RLIMIT_AS,
/// a wall-clock kill), so a page that crashes, hangs or exhausts it costs the text, never the kiosk. The
/// worker is found as $HK_OCR_WORKER, else beside the running executable, else where the build put it.
///
/// In the worker: tesseract::TessBaseAPI with the LSTM engine on the grey pixels. Tesseract's layout analysis
/// finds the page's text blocks in reading order; each is recognised on its own (its polygon grown by kBlockMargin,
/// the rest of the picture white) and sent to the kiosk at once, so the first words come
/// in a fraction of a second while the rest are read; each block read back with its ResultIterator at paragraph,
/// line and word level (boxes and confidences). Where the layout finds (almost) nothing, as for a sign in a
/// photograph, the whole picture is read as sparse text instead. Every word is said as Tesseract read it, however
/// unsure (a code word such as "mime.cache" is often read right with a low confidence, and cutting it loses real text);
/// only a mark below the confidence threshold with no letter or digit in it is unclear: kept in its place in the
/// block's text as kUnclearWord (the kiosk says "unclear word" there). A word below kNoiseWordConfidence as well is
/// dropped as noise. A paragraph with no word at or above the threshold, or whose clear words are mostly not letters or
/// digits, is dropped; the rest are the text blocks, in Tesseract's reading order.

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "hk/error.hpp"

namespace hk::vision {

/// What stands in an OcrBlock's text for one unclear word (a mark with no letter or digit that Tesseract is less
/// sure of than OcrParams::min_word_confidence): U+FFFD, the replacement character, as a word of its own.
inline constexpr std::string_view kUnclearWord = "\xEF\xBF\xBD";
/// A word below this confidence, and below OcrParams::min_word_confidence, is noise: left out altogether [0, 1].
inline constexpr double kNoiseWordConfidence = 0.1;
/// How far each text block's polygon is grown to the left and right before it is recognised, as a share of the
/// picture's longer side (at least kBlockMarginMinPx), and a quarter of that up and down (at least half): a tight
/// polygon cuts the letters at its edge, a wide one takes in pieces of the lines of the next block.
inline constexpr double kBlockMargin = 0.01;
inline constexpr int kBlockMarginMinPx = 8;

struct OcrBlock;

/// Test hook: the worker fails on purpose as soon as it has started. Never set outside tests.
enum class OcrFault {
  None,    ///< normal work
  Crash,   ///< dies of SIGSEGV
  Hang,    ///< spins on the CPU until a limit stops it
  Memory,  ///< allocates until RLIMIT_AS refuses (reported as out of memory)
};

/// What OCR is asked to do, and its limits. Units in names.
struct OcrParams {
  /// Tesseract languages, '+'-joined ("eng", "eng+deu"): each needs LANG.traineddata in the data folder.
  std::string languages = "eng";
  /// Tesseract's data folder; empty: Tesseract's own default (Debian: /usr/share/tesseract-ocr/5/tessdata).
  std::string tessdata_dir;
  double min_word_confidence =
      0.6;  ///< below this (Tesseract's confidence / 100, [0, 1]) a mark with no letter or digit is unclear
            ///< (kUnclearWord) and a word does not count towards keeping its block; a word is still said
  double min_letter_share = 0.5;  ///< a block whose characters are less than this share letters or digits is dropped
  double max_pixels = 4e7;        ///< a larger picture is refused before the worker starts [px]
  double worker_cpu_s = 30.0;     ///< RLIMIT_CPU of the worker [s]
  double worker_wall_s = 30.0;    ///< the worker is killed after this wall-clock time [s]
  double worker_max_memory_mb =
      1536.0;  ///< address space the worker may add at start [MiB] (not under ASan); 0 = no limit
  /// When given and it becomes true, the worker is killed within worker::kCancelPoll_ms (50 ms) and
  /// recognise_text throws OcrError Cancelled (a newer page no longer needs this one's text).
  const std::atomic<bool>* cancel = nullptr;
  /// When given, called on recognise_text's thread with each block as soon as the worker has read it, in reading
  /// order, before recognise_text returns (the page's first words can be said while the rest is read). The
  /// blocks are those the result will hold; a reading that fails later has still called it for those before.
  std::function<void(const OcrBlock& block)> on_block;
  OcrFault fault = OcrFault::None;  ///< test hook only
};

/// One word Tesseract read, in the picture's pixels (u right, v down, origin at the top-left pixel's corner).
struct OcrWord {
  std::string text;       ///< UTF-8
  cv::Rect2d box_px;      ///< bounding box [px]
  double confidence = 0;  ///< [0, 1]
};

/// A block of text (one of Tesseract's paragraphs), in reading order.
struct OcrBlock {
  cv::Rect2d box_px;      ///< union of its kept words' boxes [px]
  std::string text;       ///< its kept words, line by line, joined by single spaces; each unclear word as kUnclearWord
  double confidence = 0;  ///< mean confidence of its kept words (unclear ones too), [0, 1]
  int lines = 0;          ///< lines with a kept word
  /// The Tesseract language whose model read most of its words ("fra", "eng"; "" when Tesseract does not say):
  /// with OcrParams::languages "fra+eng", which of the two the block is in.
  std::string language;
};

/// What OCR found in one picture.
struct OcrResult {
  std::vector<OcrWord> words;  ///< every kept word (in the blocks; unclear ones with their own text), in reading order
  std::vector<OcrBlock> blocks;  ///< the text blocks
  int words_seen = 0;            ///< words Tesseract read, kept or not
  double mean_confidence = 0;    ///< over the kept words, [0, 1]; 0 when none
  double ms = 0;                 ///< wall time of the worker [ms]
  long worker_max_rss_kb = 0;    ///< the worker's peak resident memory [KiB]
};

/// OCR could not run or gave no usable answer. what() is one line: "ocr '<name>': <problem>".
class OcrError : public hk::Error {
 public:
  /// Unavailable: a language's traineddata is missing, or the engine cannot start; TooLarge: the picture or
  /// the worker's memory; Timeout: wall-clock or CPU limit; WorkerCrashed: the worker died or answered badly;
  /// Cancelled: OcrParams::cancel was raised (never sent by a worker).
  enum class Kind { Unavailable, TooLarge, Timeout, WorkerCrashed, Cancelled };
  OcrError(Kind kind, const std::string& what) : hk::Error(what), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

/// Whether every language of `params` has its traineddata: "" when it does, else one line naming the
/// missing file and the folder looked in, e.g. "Tesseract has no 'fra' (no fra.traineddata in
/// /usr/share/tesseract-ocr/5/tessdata)". Also refuses a malformed language list.
std::string ocr_languages_problem(const OcrParams& params);

/// Reads the text of `grey` (CV_8UC1, the picture at the resolution to read it at) in a worker.
/// @param name how to name the picture in errors (made printable on one line)
/// @throws OcrError as its kinds say; hk::ArgumentError for an empty or non-CV_8UC1 picture or a limit
///         that is not positive.
OcrResult recognise_text(const cv::Mat& grey, const std::string& name, const OcrParams& params);

/// Whether `grey` holds text worth reading, judged from the picture alone, binarised (Otsu):
/// - a page of text: its dark connected components of letter size (height 0.6–6 % of the shorter side, not
///   much wider than 3 heights) number at least 60, are at least 40 % of all components, and half of them
///   stand on a baseline shared with two others within two letter heights (within a fifth of the median
///   letter height);
/// - or a sign or poster: five letter-like components, light on dark or dark on light, of one height (3–30 %
///   of the shorter side) on one baseline, side by side.
/// Photographs and silhouettes have neither. Cost: one threshold and three connected-component passes.
bool looks_like_text_page(const cv::Mat& grey);

/// Where the letters of printed lines lie in `grey` (CV_8UC1), judged as looks_like_text_page judges a page
/// of text: CV_8UC1 of grey's size, 255 over the box of each letter-sized component that stands on a baseline
/// shared with two others, grown by half the median letter height on every side (which joins the letters of a
/// word and the words of a line); an empty Mat when `grey` is not a page of text. Cheap (one threshold, one
/// connected-component pass): it keeps the letters' outlines out of a page's curves for the seconds before
/// OCR has read where its words are. Signs and posters (large letters) are left to OCR.
cv::Mat printed_letters_mask(const cv::Mat& grey);

/// Entry point of the worker executable (vision/worker/ocr_worker_main.cpp), not for other callers.
int ocr_worker_entry(int argc, char** argv);

}  // namespace hk::vision
