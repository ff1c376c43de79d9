// PDF pages in a poppler worker process (see vision/pdf.hpp for the contract).
//
// The parent (the kiosk) never calls poppler. Each probe or render starts the worker executable
// hk-pdf-worker with posix_spawn(3) (no fork of the kiosk: a fork of a process whose other threads hold locks
// - the allocator's, a sanitizer's - can deadlock in the child; observed under AddressSanitizer), with the
// document in a sealed memfd as descriptor 3, the answer pipe as descriptor 4 and the request (page and
// limits) in its arguments. The worker
//   1. limits itself (RLIMIT_CPU; RLIMIT_AS only in builds without AddressSanitizer, see PdfLimits),
//      closes every inherited descriptor but its pipe, sends its stdout/stderr to /dev/null, silences
//      poppler's error callback and asks to be killed if the kiosk dies (PR_SET_PDEATHSIG);
//   2. does the poppler work (load_from_raw_data, is_locked() first, pages(), render, text_list);
//   3. writes one answer to the pipe and leaves with _exit (no atexit handlers, no return into the caller).
// The parent reads the answer with poll(2) against worker_wall_s, SIGKILLs the worker in every case and
// reaps it with wait4(2) (its ru_maxrss is reported). The answer is a small binary format, every size in it
// checked against the limits before anything is allocated:
//   u32 magic 'HKPD', u8 status (0 = answer, 1 = refusal)
//   refusal: u8 PdfError::Kind, str problem
//   answer:  i32 pages_in_file, str title (the Info dictionary's, UTF-8, at most kMaxPdfTitleBytes, else
//            empty), str language (the catalog's /Lang, read with qpdf, as pdf_language_tag gives it, else
//            empty); for a render also f64 width_pt, height_pt, dpi, i32 width, height,
//            width*height grey bytes, u32 word count, per word: str text, f64 x, y, w, h [px], u8 space_after
//   str = u32 length + bytes; numbers in the machine's byte order (the worker runs on the same machine).
// Coordinates: poppler's text_list() boxes are in points, y down, in the frame of the page's crop box
// after the page's /Rotate (the same frame page_renderer draws in); pixels = points x dpi / 72. The tests
// check this on a rotated page with an offset crop box (tests/data/documents/rotated_text.pdf).

#include "vision/pdf.hpp"

#include "pdf_language.hpp"

#include "hk/language.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <poppler/cpp/poppler-document.h>
#include <poppler/cpp/poppler-global.h>
#include <poppler/cpp/poppler-image.h>
#include <poppler/cpp/poppler-page-renderer.h>
#include <poppler/cpp/poppler-page.h>
#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"
#include "input_error.hpp"
#include "worker_process.hpp"

namespace hk::vision {
namespace {

using Writer = worker::WireWriter;
using Reader = worker::WireReader;
using worker::WorkerRun;

constexpr std::uint32_t kMagic = 0x44504B48;      // "HKPD"
constexpr std::uint32_t kMaxWords = 200000;       // words accepted per page
constexpr std::uint32_t kMaxWordBytes = 4096;     // UTF-8 bytes accepted per word
constexpr std::uint32_t kMaxProblemBytes = 512;   // bytes accepted in a worker's refusal
constexpr std::size_t kMaxTextBytes = 64u << 20;  // bound on the words' share of an answer

std::string fmt_num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

[[noreturn]] void fail(PdfError::Kind kind, const std::string& name, const std::string& problem) {
  throw PdfError(kind, "pdf '" + hk::one_line(name) + "': " + problem);
}

// ---------------------------------------------------------------------------------------------------
// Worker side.

/// A refusal decided inside the worker (kind + one-line problem, no name).
struct Refusal {
  PdfError::Kind kind;
  std::string problem;
};

void no_poppler_output(const std::string&, void*) {}

/// Dots per inch that keep a w x h pt page within `budget` pixels after rounding up to whole pixels.
double dpi_for(double w_pt, double h_pt, const PdfLimits& limits) {
  double dpi = std::min(limits.max_dpi, 72.0 * std::sqrt(limits.max_page_pixels / (w_pt * h_pt)));
  for (int i = 0; i < 100; ++i) {
    const double px = std::ceil(w_pt * dpi / 72.0) * std::ceil(h_pt * dpi / 72.0);
    if (px <= limits.max_page_pixels) break;
    dpi *= 0.999;
  }
  return dpi;
}

/// Renders `pg` in grey at `dpi`; an empty Mat when poppler draws nothing.
cv::Mat render_grey(const poppler::page& pg, double dpi) {
  poppler::page_renderer renderer;
  renderer.set_render_hint(poppler::page_renderer::antialiasing, true);
  renderer.set_render_hint(poppler::page_renderer::text_antialiasing, true);
  renderer.set_paper_color(0xFFFFFFFFu);
  for (const auto format : {poppler::image::format_gray8, poppler::image::format_argb32}) {
    renderer.set_image_format(format);
    const poppler::image img = renderer.render_page(&pg, dpi, dpi);
    if (!img.is_valid() || img.width() <= 0 || img.height() <= 0) continue;
    const int w = img.width(), h = img.height(), stride = img.bytes_per_row();
    const char* data = img.const_data();
    if (img.format() == poppler::image::format_gray8 && stride >= w) {
      cv::Mat grey(h, w, CV_8UC1);
      for (int y = 0; y < h; ++y)
        std::memcpy(grey.ptr(y), data + static_cast<std::ptrdiff_t>(y) * stride, static_cast<std::size_t>(w));
      return grey;
    }
    if (img.format() == poppler::image::format_argb32 && stride >= 4 * w) {
      // argb32 is one native-endian 32-bit word per pixel: B, G, R, A in memory on little-endian machines.
      const cv::Mat bgra(h, w, CV_8UC4, const_cast<char*>(data), static_cast<std::size_t>(stride));
      cv::Mat grey;
      cv::cvtColor(bgra, grey, cv::COLOR_BGRA2GRAY);
      return grey;
    }
  }
  return {};
}

/// The document's title (UTF-8, trailing NULs dropped), or "" when it is longer than kMaxPdfTitleBytes (a
/// "title" that long is no title).
std::string pdf_title(const poppler::document& doc) {
  const poppler::byte_array utf8 = doc.get_title().to_utf8();
  std::string t(utf8.begin(), utf8.end());
  while (!t.empty() && t.back() == '\0') t.pop_back();
  return t.size() <= kMaxPdfTitleBytes ? t : std::string();
}

/// The document's language (pdf_language.hpp), as pdf_language_tag makes it.
std::string pdf_language(std::span<const std::uint8_t> bytes) {
  return pdf_language_tag(pdf_catalog_language(bytes.data(), bytes.size()));
}

/// Refuses (NoSuchPage) a page number past the `offered` first of the document's n pages, saying which.
void check_page_number(int page, int n, int offered) {
  if (page <= offered) return;
  if (offered < n) {
    throw Refusal{PdfError::Kind::NoSuchPage, "page " + std::to_string(page) + " is beyond the first " +
                                                  std::to_string(offered) + " pages offered (the document has " +
                                                  std::to_string(n) + ")"};
  }
  throw Refusal{PdfError::Kind::NoSuchPage, "page " + std::to_string(page) + " does not exist (the document has " +
                                                std::to_string(n) + (n == 1 ? " page)" : " pages)")};
}

/// A page's size as it is shown [pt]: its crop box, turned for landscape and seascape pages.
struct PageSize {
  double w_pt = 0, h_pt = 0;
};

/// The page's size (PageSize), refused as Damaged when it is not a usable size (under 1e-3 pt or not finite).
PageSize page_size(const poppler::page& pg, const std::string& pname) {
  const poppler::rectf r = pg.page_rect(poppler::crop_box);
  double w_pt = std::abs(r.width()), h_pt = std::abs(r.height());
  const auto orient = pg.orientation();
  if (orient == poppler::page::landscape || orient == poppler::page::seascape) std::swap(w_pt, h_pt);
  if (!(w_pt >= 1e-3 && h_pt >= 1e-3 && std::isfinite(w_pt * h_pt))) {
    throw Refusal{PdfError::Kind::Damaged,
                  pname + " has no usable size (" + fmt_num(w_pt) + " x " + fmt_num(h_pt) + " pt)"};
  }
  return {w_pt, h_pt};
}

/// The resolution to draw the page at (dpi_for), refused as TooLarge when even 1 dpi would exceed the
/// pixel budget.
double page_dpi(PageSize size, const PdfLimits& limits, const std::string& pname) {
  const double dpi = dpi_for(size.w_pt, size.h_pt, limits);
  if (!(dpi >= 1.0)) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "%s: page size %g x %g pt would need %.2g dpi to stay within %.0f pixels",
                  pname.c_str(), size.w_pt, size.h_pt, dpi, limits.max_page_pixels);
    throw Refusal{PdfError::Kind::TooLarge, buf};
  }
  return dpi;
}

/// The resolution to draw a page with a text layer at when text_layer_max_side_px asks: the highest that keeps
/// its long side within that many whole pixels, but never above `full` (the budget's) nor below 1 dpi.
double text_layer_dpi(PageSize size, double full, const PdfLimits& limits) {
  const double side_pt = std::max(size.w_pt, size.h_pt);
  double dpi = std::min(full, 72.0 * limits.text_layer_max_side_px / side_pt);
  for (int i = 0; i < 100 && std::ceil(side_pt * dpi / 72.0) > limits.text_layer_max_side_px; ++i) dpi *= 0.999;
  return std::max(dpi, std::min(full, 1.0));
}

/// The page drawn in grey at `dpi`, checked: refused as Damaged when not drawn, as TooLarge when poppler
/// returned another size than asked (Splash answers a failed bitmap allocation under RLIMIT_AS with a
/// 1 x 1 picture) or more pixels than the budget.
cv::Mat render_checked(const poppler::page& pg, PageSize size, double dpi, const PdfLimits& limits,
                       const std::string& pname) {
  const cv::Mat grey = render_grey(pg, dpi);
  if (grey.empty()) throw Refusal{PdfError::Kind::Damaged, pname + " could not be drawn"};
  const double want_w = size.w_pt * dpi / 72.0, want_h = size.h_pt * dpi / 72.0;
  if (std::abs(grey.cols - want_w) > 2.0 || std::abs(grey.rows - want_h) > 2.0) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "%s could not be drawn at %.0f x %.0f px (poppler returned %d x %d; out of memory?)",
                  pname.c_str(), want_w, want_h, grey.cols, grey.rows);
    throw Refusal{PdfError::Kind::TooLarge, buf};
  }
  if (static_cast<double>(grey.cols) * grey.rows > limits.max_page_pixels) {
    throw Refusal{PdfError::Kind::TooLarge, pname + " came out " + std::to_string(grey.cols) + " x " +
                                                std::to_string(grey.rows) + " px, over the budget of " +
                                                fmt_num(limits.max_page_pixels) + " pixels"};
  }
  return grey;
}

/// Writes the page's words (`text`, its page::text_list) to `out`: their count, then each word's text (at most
/// kMaxWordBytes), box in the drawn page's pixels (pt × k, clipped to `frame`; words with nothing visible dropped) and
/// whether a space follows it; at most kMaxWords words and about kMaxTextBytes bytes.
void write_words(const std::vector<poppler::text_box>& text, double k, const cv::Rect2d& frame, Writer& out) {
  Writer words;
  std::uint32_t count = 0;
  for (const poppler::text_box& tb : text) {
    if (count >= kMaxWords || words.bytes().size() > kMaxTextBytes) break;
    const poppler::byte_array utf8 = tb.text().to_utf8();
    std::string text(utf8.begin(), utf8.end());
    while (!text.empty() && text.back() == '\0') text.pop_back();
    if (text.empty()) continue;
    if (text.size() > kMaxWordBytes) text.resize(kMaxWordBytes);
    const poppler::rectf b = tb.bbox();
    const cv::Rect2d box =
        cv::Rect2d(b.x() * k, b.y() * k, b.width() * k, b.height() * k) & frame;  // invisible parts dropped
    if (!(box.width > 0 && box.height > 0)) continue;
    words.str(text);
    words.f64(box.x);
    words.f64(box.y);
    words.f64(box.width);
    words.f64(box.height);
    words.u8(tb.has_space_after() ? 1 : 0);
    ++count;
  }
  out.u32(count);
  out.raw(words.bytes().data(), words.bytes().size());
}

/// The worker's work: an answer in `out` (page 0: the page count and title; else those, the page's size
/// [pt], dpi, whether it was drawn screen-sized, grey picture and words), or a Refusal thrown.
void work(std::span<const std::uint8_t> bytes, int page, const PdfLimits& limits, Writer& out) {
  std::unique_ptr<poppler::document> doc(poppler::document::load_from_raw_data(
      reinterpret_cast<const char*>(bytes.data()), static_cast<int>(bytes.size())));
  if (!doc) throw Refusal{PdfError::Kind::Damaged, "poppler cannot read it (damaged or not a PDF)"};
  if (doc->is_locked()) throw Refusal{PdfError::Kind::Locked, "protected by a password"};
  const int n = doc->pages();
  if (n <= 0) throw Refusal{PdfError::Kind::Damaged, "the document has no pages"};
  if (page == 0) {  // probe
    out.i32(n);
    out.str(pdf_title(*doc));
    out.str(pdf_language(bytes));
    return;
  }
  check_page_number(page, n, std::min(n, limits.max_pages));
  const std::unique_ptr<poppler::page> pg(doc->create_page(page - 1));
  const std::string pname = "page " + std::to_string(page);
  if (!pg) throw Refusal{PdfError::Kind::Damaged, pname + " cannot be read"};
  const PageSize size = page_size(*pg, pname);
  const std::vector<poppler::text_box> text = pg->text_list();
  const double full_dpi = page_dpi(size, limits, pname);
  const bool screen_sized = !text.empty() && limits.text_layer_max_side_px > 0;
  const double dpi = screen_sized ? text_layer_dpi(size, full_dpi, limits) : full_dpi;
  const cv::Mat grey = render_checked(*pg, size, dpi, limits, pname);

  out.i32(n);
  out.str(pdf_title(*doc));
  out.str(pdf_language(bytes));
  out.f64(size.w_pt);
  out.f64(size.h_pt);
  out.f64(dpi);
  out.u8(screen_sized && dpi < full_dpi ? 1 : 0);
  out.i32(grey.cols);
  out.i32(grey.rows);
  for (int y = 0; y < grey.rows; ++y) out.raw(grey.ptr(y), static_cast<std::size_t>(grey.cols));
  write_words(text, dpi / 72.0, cv::Rect2d(0, 0, grey.cols, grey.rows), out);
}

/// Everything the worker does once its document is mapped; never returns.
[[noreturn]] void worker_main(std::span<const std::uint8_t> bytes, int page, const PdfLimits& limits) {
  worker::confine_worker(limits.worker_cpu_s, limits.worker_max_memory_mb);
  if (limits.fault == PdfFault::Crash) worker::crash_on_purpose();
  if (limits.fault == PdfFault::Hang) worker::hang_on_purpose();

  poppler::set_debug_error_function(no_poppler_output, nullptr);
  const Writer out = worker::worker_answer<Refusal>(
      kMagic, [&](Writer& answer) { work(bytes, page, limits, answer); },
      std::pair{PdfError::Kind::TooLarge,
                "the reader ran out of memory (limit " + fmt_num(limits.worker_max_memory_mb) + " MiB)"},
      std::pair{PdfError::Kind::Damaged, std::string("poppler failed on it")});
  worker::write_all(worker::kAnswerFd, out.bytes());
  ::_exit(0);
}

// ---------------------------------------------------------------------------------------------------
// Parent side.

/// Runs the worker on `bytes` for `page` (0: open and count only); a worker that cannot start is a PdfError.
WorkerRun run_pdf_worker(std::span<const std::uint8_t> bytes, int page, const PdfLimits& limits,
                         const std::string& name, std::size_t max_answer) {
#ifdef HK_PDF_WORKER_PATH
  static const std::string path = worker::find_worker("HK_PDF_WORKER", "hk-pdf-worker", HK_PDF_WORKER_PATH);
#else
  static const std::string path = worker::find_worker("HK_PDF_WORKER", "hk-pdf-worker", "hk-pdf-worker");
#endif
  const std::vector<std::string> args{std::to_string(page),
                                      std::to_string(limits.max_pages),
                                      worker::arg(limits.max_page_pixels),
                                      worker::arg(limits.max_dpi),
                                      worker::arg(limits.text_layer_max_side_px),
                                      worker::arg(limits.worker_cpu_s),
                                      worker::arg(limits.worker_max_memory_mb),
                                      std::to_string(static_cast<int>(limits.fault)),
                                      std::to_string(bytes.size())};
  try {
    return worker::run_worker(path, args, bytes, limits.worker_wall_s, max_answer);
  } catch (const worker::WorkerStartFailure& f) {
    fail(PdfError::Kind::WorkerCrashed, name, "cannot start the reader (" + f.why + ")");
  }
}

/// Where the worker was when it stopped, for messages: "page 3" or "opening it".
std::string doing(int page) { return page == 0 ? "opening the document" : "page " + std::to_string(page); }

/// Throws the PdfError for a worker that gave no complete answer.
[[noreturn]] void fail_run(const WorkerRun& run, const std::string& name, int page, const PdfLimits& limits) {
  const double cpu_limit = std::ceil(std::max(limits.worker_cpu_s, 0.001));
  if (run.timed_out) {
    fail(PdfError::Kind::Timeout, name,
         (page == 0 ? std::string("opening it") : "page " + std::to_string(page)) + " took longer than " +
             fmt_num(limits.worker_wall_s) + " s" + (page == 0 ? "" : " to draw"));
  }
  if (run.overflow) fail(PdfError::Kind::WorkerCrashed, name, "the reader sent an oversized answer for " + doing(page));
  if (WIFSIGNALED(run.status)) {
    const int sig = WTERMSIG(run.status);
    if (sig == SIGXCPU || (sig == SIGKILL && run.cpu_s >= cpu_limit)) {
      fail(PdfError::Kind::Timeout, name,
           doing(page) + " used more than " + fmt_num(cpu_limit) + " s of processor time");
    }
    const std::string where = page == 0 ? "while opening the document" : "on page " + std::to_string(page);
    fail(PdfError::Kind::WorkerCrashed, name, "the reader stopped " + where + " (signal " + std::to_string(sig) + ")");
  }
  const std::string where = page == 0 ? "while opening the document" : "on page " + std::to_string(page);
  if (WIFEXITED(run.status) && WEXITSTATUS(run.status) != 0) {
    fail(PdfError::Kind::WorkerCrashed, name,
         "the reader stopped " + where + " (exit status " + std::to_string(WEXITSTATUS(run.status)) + ")");
  }
  fail(PdfError::Kind::WorkerCrashed, name, "the reader gave no usable answer " + where);
}

/// Checks what every caller checks before starting a worker.
void check_input(std::span<const std::uint8_t> bytes, const std::string& name, const PdfLimits& limits) {
  if (!(limits.max_file_bytes > 0 && limits.max_pages > 0 && limits.max_page_pixels > 0 && limits.max_dpi > 0 &&
        limits.worker_cpu_s > 0 && limits.worker_wall_s > 0 && limits.worker_max_memory_mb >= 0 &&
        limits.text_layer_max_side_px >= 0)) {
    throw hk::ArgumentError("PdfLimits: every limit must be positive");
  }
  if (bytes.empty()) fail(PdfError::Kind::NotPdf, name, "the file is empty");
  if (!looks_like_pdf(bytes)) fail(PdfError::Kind::NotPdf, name, "not a PDF (no %PDF- header)");
  const auto cap = std::min<std::int64_t>(limits.max_file_bytes, INT_MAX);
  if (static_cast<std::int64_t>(bytes.size()) > cap) {
    fail(PdfError::Kind::TooLarge, name,
         "file of " + std::to_string(bytes.size()) + " bytes is over the limit of " + std::to_string(cap) + " bytes");
  }
}

/// Parses the common head of an answer; throws the worker's refusal as a PdfError.
void read_head(Reader& in, const WorkerRun& run, const std::string& name, int page, const PdfLimits& limits) {
  std::uint32_t magic = 0;
  std::uint8_t status = 0;
  if (!in.u32(magic) || magic != kMagic || !in.u8(status) || status > 1) fail_run(run, name, page, limits);
  if (status == 1) {
    std::uint8_t kind = 0;
    std::string problem;
    if (!in.u8(kind) || kind > static_cast<std::uint8_t>(PdfError::Kind::WorkerCrashed) ||
        !in.str(problem, kMaxProblemBytes)) {
      fail_run(run, name, page, limits);
    }
    for (char& c : problem) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = ' ';
    }
    fail(static_cast<PdfError::Kind>(kind), name, problem);
  }
}

}  // namespace

bool looks_like_pdf(std::span<const std::uint8_t> bytes) {
  static constexpr char kHeader[] = "%PDF-";
  const std::size_t n = sizeof kHeader - 1;
  if (bytes.size() < n) return false;
  const std::size_t last = std::min<std::size_t>(1024, bytes.size() - n);
  for (std::size_t i = 0; i <= last; ++i) {
    if (std::memcmp(bytes.data() + i, kHeader, n) == 0) return true;
  }
  return false;
}

int pdf_worker_entry(int argc, char** argv) {
  if (argc != 10) return 64;
  PdfLimits limits;
  const int page = std::atoi(argv[1]);
  limits.max_pages = std::atoi(argv[2]);
  limits.max_page_pixels = std::strtod(argv[3], nullptr);
  limits.max_dpi = std::strtod(argv[4], nullptr);
  limits.text_layer_max_side_px = std::strtod(argv[5], nullptr);
  limits.worker_cpu_s = std::strtod(argv[6], nullptr);
  limits.worker_max_memory_mb = std::strtod(argv[7], nullptr);
  const int fault = std::atoi(argv[8]);
  limits.fault = fault == 1 ? PdfFault::Crash : fault == 2 ? PdfFault::Hang : PdfFault::None;
  const auto size = static_cast<std::size_t>(std::strtoull(argv[9], nullptr, 10));
  const std::span<const std::uint8_t> bytes = worker::map_input(size);
  if (bytes.empty()) return 65;
  worker_main(bytes, page, limits);
}

PdfInfo probe_pdf(std::span<const std::uint8_t> bytes, const std::string& name, const PdfLimits& limits) {
  check_input(bytes, name, limits);
  const WorkerRun run = run_pdf_worker(bytes, 0, limits, name, 64 * 1024);
  Reader in(run.answer);
  read_head(in, run, name, 0, limits);
  std::int32_t n = 0;
  PdfInfo info;
  if (!in.i32(n) || n <= 0 || !in.str(info.title, kMaxPdfTitleBytes) || !in.str(info.language, kMaxLanguageTagBytes) ||
      in.left() != 0)
    fail_run(run, name, 0, limits);
  info.pages_in_file = n;
  info.pages = std::min(n, limits.max_pages);
  info.capped = n > limits.max_pages;
  info.worker_ms = run.ms;
  info.worker_max_rss_kb = run.max_rss_kb;
  return info;
}

PdfPage render_pdf_page(std::span<const std::uint8_t> bytes, const std::string& name, int page,
                        const PdfLimits& limits) {
  check_input(bytes, name, limits);
  if (page < 1)
    fail(PdfError::Kind::NoSuchPage, name, "page " + std::to_string(page) + " does not exist (pages count from 1)");
  const std::size_t max_answer = 1024 + static_cast<std::size_t>(std::min(limits.max_page_pixels, 1e10)) +
                                 kMaxTextBytes + 2 * (kMaxWordBytes + 40);
  const WorkerRun run = run_pdf_worker(bytes, page, limits, name, max_answer);
  Reader in(run.answer);
  read_head(in, run, name, page, limits);
  std::int32_t n = 0, w = 0, h = 0;
  std::uint8_t screen_sized = 0;
  PdfPage out;
  if (!in.i32(n) || n < page || !in.str(out.title, kMaxPdfTitleBytes) || !in.str(out.language, kMaxLanguageTagBytes) ||
      !in.f64(out.width_pt) || !in.f64(out.height_pt) || !in.f64(out.dpi) || !in.u8(screen_sized) || screen_sized > 1 ||
      (screen_sized == 1 && !(limits.text_layer_max_side_px > 0)) || !in.i32(w) || !in.i32(h) || w <= 0 || h <= 0 ||
      static_cast<double>(w) * h > limits.max_page_pixels || !(out.dpi > 0 && out.dpi <= limits.max_dpi) ||
      std::abs(w - out.width_pt * out.dpi / 72.0) > 2.0 || std::abs(h - out.height_pt * out.dpi / 72.0) > 2.0) {
    fail_run(run, name, page, limits);
  }
  out.screen_sized = screen_sized == 1;
  out.grey.create(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y) {
    if (!in.raw(out.grey.ptr(y), static_cast<std::size_t>(w))) fail_run(run, name, page, limits);
  }
  std::uint32_t count = 0;
  if (!in.u32(count) || count > kMaxWords) fail_run(run, name, page, limits);
  out.words.reserve(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    PdfWord word;
    std::uint8_t space = 0;
    if (!in.str(word.text, kMaxWordBytes) || !in.f64(word.box_px.x) || !in.f64(word.box_px.y) ||
        !in.f64(word.box_px.width) || !in.f64(word.box_px.height) || !in.u8(space) || space > 1) {
      fail_run(run, name, page, limits);
    }
    word.space_after = space == 1;
    out.words.push_back(std::move(word));
  }
  if (in.left() != 0) fail_run(run, name, page, limits);
  out.blocks = group_text_blocks(out.words);
  out.pages = std::min(n, limits.max_pages);
  out.worker_ms = run.ms;
  out.worker_max_rss_kb = run.max_rss_kb;
  return out;
}

// ---------------------------------------------------------------------------------------------------
// Text blocks.

namespace {

/// A line of text: its words and its box [px].
struct Line {
  std::vector<std::size_t> words;  // indices, left to right
  double left = 0, top = 0, right = 0, bottom = 0;
  double height() const { return bottom - top; }
};

/// How much the intervals [a0, a1] and [b0, b1] overlap (negative: the gap between them).
double overlap(double a0, double a1, double b0, double b1) { return std::min(a1, b1) - std::max(a0, b0); }

/// Words -> lines: words taken left to right, each joins the open line it overlaps most vertically when
/// the gap from that line's last word is under 1.5 line heights (a small overlap counts as no gap).
std::vector<Line> words_to_lines(const std::vector<PdfWord>& words) {
  std::vector<std::size_t> order(words.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return words[a].box_px.x < words[b].box_px.x; });
  std::vector<Line> lines;
  for (const std::size_t i : order) {
    const cv::Rect2d& b = words[i].box_px;
    Line* best = nullptr;
    double best_overlap = 0;
    for (Line& line : lines) {
      const double h = line.height();
      const double v = overlap(b.y, b.y + b.height, line.top, line.bottom);
      if (v < 0.5 * std::min(h, b.height) || v <= 0) continue;
      const double gap = b.x - line.right;
      if (gap >= 1.5 * h || gap < -0.5 * h) continue;
      if (v > best_overlap) {
        best_overlap = v;
        best = &line;
      }
    }
    if (best) {
      best->words.push_back(i);
      best->left = std::min(best->left, b.x);
      best->right = std::max(best->right, b.x + b.width);
      best->top = std::min(best->top, b.y);
      best->bottom = std::max(best->bottom, b.y + b.height);
    } else {
      lines.push_back(Line{{i}, b.x, b.y, b.x + b.width, b.y + b.height});
    }
  }
  return lines;
}

/// A block of text: indices of its lines, top to bottom.
struct Block {
  std::vector<std::size_t> lines;
};

/// Lines -> blocks: sorts the lines top to bottom; each joins the block whose last line is closest above it
/// when the gap is under one line height, the heights differ by less than 1.5x and they overlap horizontally.
std::vector<Block> lines_to_blocks(std::vector<Line>& lines) {
  std::stable_sort(lines.begin(), lines.end(),
                   [](const Line& a, const Line& b) { return a.top != b.top ? a.top < b.top : a.left < b.left; });
  std::vector<Block> blocks;
  for (std::size_t li = 0; li < lines.size(); ++li) {
    const Line& l = lines[li];
    Block* best = nullptr;
    double best_gap = 0;
    for (Block& blk : blocks) {
      const Line& last = lines[blk.lines.back()];
      const double h = l.height(), hl = last.height();
      const double gap = l.top - last.bottom;
      if (gap >= std::max(h, hl) * 1.0 || gap < -0.5 * std::min(h, hl)) continue;
      if (std::max(h, hl) >= 1.5 * std::min(h, hl)) continue;
      if (overlap(l.left, l.right, last.left, last.right) <= 0) continue;
      if (!best || gap < best_gap) {
        best = &blk;
        best_gap = gap;
      }
    }
    if (best) {
      best->lines.push_back(li);
    } else {
      blocks.push_back(Block{{li}});
    }
  }
  return blocks;
}

/// Each block's text (its words joined by spaces, except where poppler glued two words that touch), box
/// (the union of its words' boxes, px) and line count.
std::vector<TextBlock> block_texts(const std::vector<PdfWord>& words, const std::vector<Line>& lines,
                                   const std::vector<Block>& blocks) {
  std::vector<TextBlock> out;
  out.reserve(blocks.size());
  for (const Block& blk : blocks) {
    TextBlock tb;
    bool first = true;
    for (const std::size_t li : blk.lines) {
      const std::vector<std::size_t>& lw = lines[li].words;
      for (std::size_t k = 0; k < lw.size(); ++k) {
        const PdfWord& w = words[lw[k]];
        // No space after poppler's "no space after" word only if the next one really touches it: a bullet
        // flagged so but set off by an indent still reads as its own word (as pdftotext prints it).
        const bool glued = k > 0 && !words[lw[k - 1]].space_after &&
                           w.box_px.x - words[lw[k - 1]].box_px.br().x < 0.3 * lines[li].height();
        if (!first && !glued) tb.text += ' ';
        tb.text += w.text;
        tb.box_px = first ? w.box_px : (tb.box_px | w.box_px);
        first = false;
      }
    }
    tb.lines = static_cast<int>(blk.lines.size());
    out.push_back(std::move(tb));
  }
  return out;
}

/// Sorts blocks into reading order: top to bottom; blocks whose tops lie within half a line of the row's
/// first block form a row, read left to right.
void sort_reading_order(std::vector<TextBlock>& out) {
  std::stable_sort(out.begin(), out.end(),
                   [](const TextBlock& a, const TextBlock& b) { return a.box_px.y < b.box_px.y; });
  for (std::size_t row = 0; row < out.size();) {
    const double tol = 0.5 * out[row].box_px.height / std::max(out[row].lines, 1);
    std::size_t end = row + 1;
    while (end < out.size() && out[end].box_px.y - out[row].box_px.y <= tol) ++end;
    std::stable_sort(out.begin() + static_cast<std::ptrdiff_t>(row), out.begin() + static_cast<std::ptrdiff_t>(end),
                     [](const TextBlock& a, const TextBlock& b) { return a.box_px.x < b.box_px.x; });
    row = end;
  }
}

}  // namespace

std::vector<TextBlock> group_text_blocks(const std::vector<PdfWord>& words) {
  std::vector<Line> lines = words_to_lines(words);
  const std::vector<Block> blocks = lines_to_blocks(lines);
  std::vector<TextBlock> out = block_texts(words, lines, blocks);
  sort_reading_order(out);
  return out;
}

std::string pdf_language_tag(std::string_view lang) {
  std::string tag(lang.substr(0, std::min(lang.size(), kMaxLanguageTagBytes + 1)));
  for (char& c : tag) c = c == '_' ? '-' : c;
  const std::size_t dash = tag.find('-');
  for (std::size_t i = 0; i < std::min(dash, tag.size()); ++i)
    tag[i] = static_cast<char>(std::tolower(static_cast<unsigned char>(tag[i])));
  return hk::is_language_tag(tag) ? tag : std::string();
}

}  // namespace hk::vision
