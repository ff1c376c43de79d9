// Fuzz harness: PDF documents from a stranger's stick (vision/pdf.hpp), the poppler part.
//
// In the kiosk, poppler runs only in the worker process hk-pdf-worker (pdf.cpp's worker side: `work()`,
// called by worker_main after it has limited itself). This harness runs that same `work()` in-process, so
// poppler's parsing and rendering is fuzzed with AddressSanitizer watching: pdf.cpp is compiled into this
// file (its worker functions are internal to it), nothing in it is changed. Then it checks what the
// kiosk side relies on:
//  - a refusal has a kind the parent accepts and a problem of at most kMaxProblemBytes bytes (the parent
//    turns a longer one into "no usable answer"), one line;
//  - an answer has the exact layout the parent parses (probe: page count, title; render: page size, dpi,
//    screen-sized flag, w x h grey bytes within the pixel budget, words with finite boxes inside the page), and the
//    parent's group_text_blocks (which runs in the kiosk process) digests the words.
// The budget is lower than the kiosk's (40000 px instead of 4 MP) so that a run takes milliseconds.

#include "pdf.cpp"  // vision/src/pdf.cpp, for its internal worker function work()

#include <cstddef>
#include <cstdint>

#include "fuzz_common.hpp"
#include "hk/language.hpp"

namespace hk::vision {  // pdf.cpp's internals (Writer, Reader, Refusal, work) live in its anonymous namespace here
namespace {

void check_words_and_blocks(Reader& in, int w, int h) {
  std::uint32_t count = 0;
  FUZZ_CHECK(in.u32(count) && count <= kMaxWords, "word count");
  std::vector<hk::vision::PdfWord> words;
  for (std::uint32_t i = 0; i < count; ++i) {
    hk::vision::PdfWord word;
    std::uint8_t space = 0;
    FUZZ_CHECK(in.str(word.text, kMaxWordBytes) && !word.text.empty(), "word text");
    FUZZ_CHECK(
        in.f64(word.box_px.x) && in.f64(word.box_px.y) && in.f64(word.box_px.width) && in.f64(word.box_px.height),
        word.text);
    FUZZ_CHECK(in.u8(space) && space <= 1, word.text);
    const cv::Rect2d& b = word.box_px;
    FUZZ_CHECK(
        b.width > 0 && b.height > 0 && b.x >= 0 && b.y >= 0 && b.x + b.width <= w + 1e-6 && b.y + b.height <= h + 1e-6,
        word.text);
    words.push_back(std::move(word));
  }
  FUZZ_CHECK(in.left() == 0, "trailing bytes in the answer");
  const std::vector<hk::vision::TextBlock> blocks = hk::vision::group_text_blocks(words);
  FUZZ_CHECK(blocks.size() <= words.size(), "more blocks than words");
  std::size_t lines = 0;
  for (const hk::vision::TextBlock& b : blocks) {
    FUZZ_CHECK(b.lines >= 1 && !b.text.empty(), b.text);
    FUZZ_CHECK(std::isfinite(b.box_px.x) && std::isfinite(b.box_px.y) && b.box_px.width > 0 && b.box_px.height > 0,
               b.text);
    lines += static_cast<std::size_t>(b.lines);
  }
  FUZZ_CHECK(lines <= words.size(), "more lines than words");
}

/// Runs the worker's work for `page` (0 = probe); returns the pages in the file, or 0 after a refusal.
int run(std::span<const std::uint8_t> bytes, int page, const PdfLimits& limits) {
  Writer out;
  try {
    work(bytes, page, limits, out);
  } catch (const Refusal& r) {
    FUZZ_CHECK(static_cast<int>(r.kind) >= 0 && r.kind <= PdfError::Kind::WorkerCrashed, r.problem);
    FUZZ_CHECK(!r.problem.empty() && r.problem.size() <= kMaxProblemBytes, r.problem);
    FUZZ_CHECK(hk::fuzz::is_one_line(r.problem), r.problem);
    return 0;
  } catch (const std::bad_alloc&) {
    return 0;  // the worker reports TooLarge
  } catch (const std::exception&) {
    return 0;  // the worker reports "poppler failed on it"
  }
  Reader in(out.bytes());
  std::int32_t n = 0;
  std::string title;
  FUZZ_CHECK(in.i32(n) && n > 0, "page count");
  FUZZ_CHECK(in.str(title, hk::vision::kMaxPdfTitleBytes), "title");
  std::string language;  // the catalog's /Lang, as pdf_language_tag makes it: a tag the kiosk takes, or ""
  FUZZ_CHECK(in.str(language, hk::vision::kMaxLanguageTagBytes), "language");
  FUZZ_CHECK(language.empty() || hk::is_language_tag(language), language);
  if (page == 0) {
    FUZZ_CHECK(in.left() == 0, "trailing bytes after a probe");
    return n;
  }
  double w_pt = 0, h_pt = 0, dpi = 0;
  std::int32_t w = 0, h = 0;
  std::uint8_t screen_sized = 0;
  FUZZ_CHECK(n >= page, "rendered a page beyond the count");
  FUZZ_CHECK(
      in.f64(w_pt) && in.f64(h_pt) && in.f64(dpi) && in.u8(screen_sized) && screen_sized <= 1 && in.i32(w) && in.i32(h),
      "page header");
  FUZZ_CHECK(w > 0 && h > 0 && static_cast<double>(w) * h <= limits.max_page_pixels,
             std::to_string(w) + "x" + std::to_string(h));
  FUZZ_CHECK(screen_sized == 0 || std::max(w, h) <= limits.text_layer_max_side_px + 2.0,
             std::to_string(w) + "x" + std::to_string(h));
  FUZZ_CHECK(dpi > 0 && dpi <= limits.max_dpi, std::to_string(dpi));
  FUZZ_CHECK(std::abs(w - w_pt * dpi / 72.0) <= 2.0 && std::abs(h - h_pt * dpi / 72.0) <= 2.0, std::to_string(w_pt));
  std::vector<std::uint8_t> grey(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  FUZZ_CHECK(in.raw(grey.data(), grey.size()), "grey bytes");
  check_words_and_blocks(in, w, h);
  return n;
}

}  // namespace
}  // namespace hk::vision

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  poppler::set_debug_error_function(hk::vision::no_poppler_output, nullptr);
  cv::setNumThreads(1);
  // poppler-cpp creates its GlobalParams (font set-up) when the first document opens and destroys it when the
  // last one closes. A worker opens one document in its life; here one tiny document stays open so that every
  // run does not pay that set-up again (10x faster).
  static const char kTiny[] =
      "%PDF-1.4\n1 0 obj<</Type/Catalog/Pages 2 0 R>>endobj 2 0 obj<</Type/Pages/Kids[3 0 R]/Count 1>>endobj\n"
      "3 0 obj<</Type/Page/Parent 2 0 R/MediaBox[0 0 10 10]>>endobj\ntrailer<</Root 1 0 R>>\n%%EOF\n";
  static const std::unique_ptr<poppler::document> keep(poppler::document::load_from_raw_data(kTiny, sizeof kTiny - 1));
  if (!keep) std::fprintf(stderr, "fuzz_pdf: the tiny document did not load; runs will be slower\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  // The parent's own checks come first: the worker only ever sees what passes them.
  if (size == 0 || !hk::vision::looks_like_pdf(bytes)) return 0;
  hk::vision::PdfLimits limits;
  limits.max_page_pixels = 4e4;
  limits.text_layer_max_side_px = 120;  // a page with words is drawn smaller still (the kiosk's screen size)
  const int n = hk::vision::run(bytes, 0, limits);
  if (n > 0) hk::vision::run(bytes, 1, limits);
  return 0;
}
