// OCR in a worker process: the kiosk's side (vision/ocr.hpp for the contract, ocr_wire.hpp for the request,
// vision/worker/ocr_engine.cpp for the worker and its answer), and the page-of-text test.
#include "vision/ocr.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"
#include "hk/text.hpp"
#include "ocr_wire.hpp"
#include "worker_process.hpp"

namespace hk::vision {
namespace {

constexpr std::uint32_t kMaxWords = 200000;      // words accepted per picture
constexpr std::uint32_t kMaxWordBytes = 1024;    // UTF-8 bytes accepted per word
constexpr std::uint32_t kMaxProblemBytes = 512;  // bytes accepted in a worker's refusal
constexpr std::uint32_t kMaxLanguageBytes = 32;  // bytes accepted in a block's language
constexpr std::size_t kMaxAnswerBytes = 64u << 20;

[[noreturn]] void fail(OcrError::Kind kind, const std::string& name, const std::string& problem) {
  throw OcrError(kind, "ocr '" + hk::one_line(name) + "': " + problem);
}

/// Throws the OcrError for a worker that gave no complete answer.
[[noreturn]] void fail_run(const worker::WorkerRun& run, const std::string& name, const OcrParams& p) {
  const double cpu_limit = std::ceil(std::max(p.worker_cpu_s, 0.001));
  if (run.cancelled) fail(OcrError::Kind::Cancelled, name, "reading the text was cancelled");
  if (run.timed_out)
    fail(OcrError::Kind::Timeout, name, "reading the text took longer than " + worker::arg(p.worker_wall_s) + " s");
  if (run.overflow) fail(OcrError::Kind::WorkerCrashed, name, "the text reader sent an oversized answer");
  if (WIFSIGNALED(run.status)) {
    const int sig = WTERMSIG(run.status);
    if (sig == SIGXCPU || (sig == SIGKILL && run.cpu_s >= cpu_limit)) {
      fail(OcrError::Kind::Timeout, name,
           "reading the text used more than " + worker::arg(cpu_limit) + " s of processor time");
    }
    fail(OcrError::Kind::WorkerCrashed, name, "the text reader stopped (signal " + std::to_string(sig) + ")");
  }
  if (WIFEXITED(run.status) && WEXITSTATUS(run.status) != 0) {
    fail(OcrError::Kind::WorkerCrashed, name,
         "the text reader stopped (exit status " + std::to_string(WEXITSTATUS(run.status)) + ")");
  }
  fail(OcrError::Kind::WorkerCrashed, name, "the text reader gave no usable answer");
}

void check_params(const cv::Mat& grey, const OcrParams& p) {
  if (grey.empty() || grey.type() != CV_8UC1)
    throw hk::ArgumentError("recognise_text: the picture must be a non-empty CV_8UC1 image");
  if (!(p.max_pixels > 0 && p.worker_cpu_s > 0 && p.worker_wall_s > 0 && p.worker_max_memory_mb >= 0 &&
        p.min_word_confidence >= 0 && p.min_word_confidence <= 1 && p.min_letter_share >= 0 &&
        p.min_letter_share <= 1)) {
    throw hk::ArgumentError("OcrParams: limits must be positive and shares within [0, 1]");
  }
}

/// The picture's rows, packed (the worker reads width x height bytes).
std::vector<std::uint8_t> packed(const cv::Mat& grey) {
  std::vector<std::uint8_t> px(static_cast<std::size_t>(grey.cols) * static_cast<std::size_t>(grey.rows));
  for (int y = 0; y < grey.rows; ++y)
    std::copy_n(grey.ptr<std::uint8_t>(y), grey.cols, px.data() + static_cast<std::size_t>(y) * grey.cols);
  return px;
}

/// Whether `text` has an ASCII letter or digit, or a non-ASCII character (a letter of another script).
bool has_letter_or_digit(const std::string& text) {
  return std::any_of(text.begin(), text.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u >= 0x80 || std::isalnum(u) != 0;
  });
}

/// Reads one block of the answer into `out` (its words appended to out.words, the block to out.blocks); a mark
/// below p.min_word_confidence with no letter or digit stands in the block's text as kUnclearWord, every word as
/// read.
bool read_block(worker::WireReader& in, const OcrParams& p, OcrResult& out, double& confidence_sum) {
  std::uint32_t lines = 0, words = 0;
  if (!in.u32(lines) || !in.u32(words) || words == 0 || words > kMaxWords || out.words.size() + words > kMaxWords ||
      lines == 0 || lines > words) {
    return false;
  }
  OcrBlock b;
  b.lines = static_cast<int>(lines);
  double block_sum = 0;
  for (std::uint32_t i = 0; i < words; ++i) {
    OcrWord w;
    if (!in.str(w.text, kMaxWordBytes) || w.text.empty() || !in.f64(w.box_px.x) || !in.f64(w.box_px.y) ||
        !in.f64(w.box_px.width) || !in.f64(w.box_px.height) || !in.f64(w.confidence) || w.confidence < 0 ||
        w.confidence > 1 || w.box_px.width < 0 || w.box_px.height < 0) {
      return false;
    }
    b.box_px = i == 0 ? w.box_px : (b.box_px | w.box_px);
    const bool unclear = w.confidence < p.min_word_confidence && !has_letter_or_digit(w.text);
    b.text += (i == 0 ? "" : " ") + (unclear ? std::string(kUnclearWord) : w.text);
    block_sum += w.confidence;
    out.words.push_back(std::move(w));
  }
  b.confidence = block_sum / words;
  if (!in.str(b.language, kMaxLanguageBytes) || !std::all_of(b.language.begin(), b.language.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
      }))
    return false;
  confidence_sum += block_sum;
  out.blocks.push_back(std::move(b));
  return true;
}

}  // namespace

std::string ocr_languages_problem(const OcrParams& p) {
  if (p.languages.empty() || p.languages.size() > 200)
    return "the OCR languages must be 1 to 200 characters, e.g. \"eng\" or \"eng+deu\"";
  const std::string dir = p.tessdata_dir.empty() ? std::string("/usr/share/tesseract-ocr/5/tessdata") : p.tessdata_dir;
  std::size_t from = 0;
  while (from <= p.languages.size()) {
    const std::size_t plus = std::min(p.languages.find('+', from), p.languages.size());
    const std::string lang = p.languages.substr(from, plus - from);
    const bool name_ok = !lang.empty() && lang.size() <= 32 && std::all_of(lang.begin(), lang.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    });
    if (!name_ok)
      return "'" + hk::one_line(p.languages, 80) +
             "' is not a '+'-joined list of Tesseract languages, e.g. \"eng+deu\"";
    const std::string file = dir + "/" + lang + ".traineddata";
    if (::access(file.c_str(), R_OK) != 0)
      return "Tesseract has no '" + lang + "' (no " + lang + ".traineddata in " + hk::one_line(dir, 200) + ")";
    from = plus + 1;
  }
  return {};
}

bool OcrAnswerReader::feed(const std::string& answer) {
  if (bad_) return false;
  if (at_ == 0) {
    if (answer.size() < sizeof(std::uint32_t)) return true;
    worker::WireReader head(answer);
    std::uint32_t magic = 0;
    if (!head.u32(magic) || magic != kOcrMagic) return !(bad_ = true);
    at_ = sizeof magic;
  }
  constexpr std::size_t kHead = 1 + sizeof(std::uint32_t);  // tag, size
  while (answer.size() - at_ >= kHead) {
    if (ended_ || refused_) return !(bad_ = true);  // nothing may follow the last record
    const auto tag = static_cast<std::uint8_t>(answer[at_]);
    std::uint32_t size = 0;
    std::memcpy(&size, answer.data() + at_ + 1, sizeof size);
    if (tag > static_cast<std::uint8_t>(OcrRecord::block) || size > kMaxAnswerBytes) return !(bad_ = true);
    if (answer.size() - at_ - kHead < size) return true;  // the rest of it is still to come
    if (!read_record(static_cast<OcrRecord>(tag), answer.substr(at_ + kHead, size))) return !(bad_ = true);
    at_ += kHead + size;
  }
  return true;
}

bool OcrAnswerReader::read_record(OcrRecord tag, const std::string& payload) {
  worker::WireReader in(payload);
  switch (tag) {
    case OcrRecord::block: {
      if (!read_block(in, p_, out_, confidence_sum_) || in.left() != 0) return false;
      if (p_.on_block) p_.on_block(out_.blocks.back());
      return true;
    }
    case OcrRecord::end: {
      std::uint32_t seen = 0;
      if (!in.u32(seen) || seen > kMaxWords || out_.blocks.size() > seen || in.left() != 0) return false;
      out_.words_seen = static_cast<int>(seen);
      out_.mean_confidence = out_.words.empty() ? 0.0 : confidence_sum_ / static_cast<double>(out_.words.size());
      ended_ = true;
      return true;
    }
    case OcrRecord::refusal: {
      std::uint8_t kind = 0;
      if (!in.u8(kind) || kind > static_cast<std::uint8_t>(OcrError::Kind::WorkerCrashed) ||
          !in.str(refusal_problem_, kMaxProblemBytes) || in.left() != 0)
        return false;
      refusal_kind_ = static_cast<OcrError::Kind>(kind);
      refused_ = true;
      return true;
    }
  }
  return false;
}

namespace {

/// The result of a run whose answer `reader` has read (fed the whole answer here): the worker's refusal, or
/// what went wrong with the run, thrown as an OcrError.
OcrResult finish(OcrAnswerReader& reader, const worker::WorkerRun& run, const std::string& name, const OcrParams& p) {
  if (run.cancelled) fail_run(run, name, p);
  const bool parsed = reader.feed(run.answer);
  if (parsed && reader.refused())
    fail(reader.refusal_kind(), name, hk::one_line(reader.refusal_problem(), kMaxProblemBytes));
  if (!parsed || !reader.ended()) fail_run(run, name, p);
  OcrResult out = std::move(reader.result());
  out.ms = run.ms;
  out.worker_max_rss_kb = run.max_rss_kb;
  return out;
}

}  // namespace

OcrResult read_ocr_answer(const worker::WorkerRun& run, const std::string& name, const OcrParams& p) {
  OcrAnswerReader reader(p);
  return finish(reader, run, name, p);
}

OcrResult recognise_text(const cv::Mat& grey, const std::string& name, const OcrParams& p) {
  check_params(grey, p);
  const double pixels = static_cast<double>(grey.cols) * grey.rows;
  if (pixels > p.max_pixels) {
    fail(OcrError::Kind::TooLarge, name,
         std::to_string(grey.cols) + " x " + std::to_string(grey.rows) + " pixels is over the limit of " +
             worker::arg(p.max_pixels));
  }
  if (const std::string why = ocr_languages_problem(p); !why.empty()) fail(OcrError::Kind::Unavailable, name, why);
#ifdef HK_OCR_WORKER_PATH
  static const std::string path = worker::find_worker("HK_OCR_WORKER", "hk-ocr-worker", HK_OCR_WORKER_PATH);
#else
  static const std::string path = worker::find_worker("HK_OCR_WORKER", "hk-ocr-worker", "hk-ocr-worker");
#endif
  OcrAnswerReader reader(p);
  worker::AnswerSoFar on_data;
  if (p.on_block) on_data = [&reader](const std::string& answer) { reader.feed(answer); };  // blocks as they come
  worker::WorkerRun run;
  try {
    run = worker::run_worker(path, ocr_request_args(grey.cols, grey.rows, p), packed(grey), p.worker_wall_s,
                             kMaxAnswerBytes, p.cancel, on_data);
  } catch (const worker::WorkerStartFailure& f) {
    fail(OcrError::Kind::WorkerCrashed, name, "cannot start the text reader (" + f.why + ")");
  }
  return finish(reader, run, name, p);
}

namespace {

struct Blob {
  int bottom, left, right, height;
};

/// The connected components of `binary` (255 = the side looked at) with their boxes and areas. `labels` is
/// scratch (CV_32S, binary's size once allocated): the judgements below share one, since a fresh label image
/// of a 1600 px picture is 10 MB of new pages each time.
std::vector<std::pair<cv::Rect, int>> components(const cv::Mat& binary, cv::Mat& labels) {
  cv::Mat stats, centroids;
  const int n = cv::connectedComponentsWithStats(binary, labels, stats, centroids, 8, CV_32S);
  std::vector<std::pair<cv::Rect, int>> out;
  out.reserve(static_cast<std::size_t>(std::max(0, n - 1)));
  for (int i = 1; i < n; ++i) {
    out.push_back({cv::Rect(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                            stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT)),
                   stats.at<int>(i, cv::CC_STAT_AREA)});
  }
  return out;
}

/// The letters of printed lines in a binarised picture (see looks_like_text_page).
struct PrintedLetters {
  std::vector<Blob> on_lines;  ///< letter-sized dark components standing on a baseline shared with two others nearby
  double median_height = 0;    ///< of all letter-sized components [px]
  bool page = false;           ///< they make a page of text
};

PrintedLetters printed_letters(const cv::Mat& ink, double side, cv::Mat& labels) {
  PrintedLetters out;
  const auto all = components(ink, labels);
  std::vector<Blob> letters;  // by bottom
  for (const auto& [r, area] : all)
    if (r.height >= 0.006 * side && r.height <= 0.06 * side && r.width <= 3 * r.height)
      letters.push_back({r.y + r.height, r.x, r.x + r.width, r.height});
  if (letters.size() < 60 || static_cast<double>(letters.size()) < 0.4 * static_cast<double>(all.size())) return out;
  std::vector<int> heights;
  for (const Blob& l : letters) heights.push_back(l.height);
  std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2), heights.end());
  const double median = heights[heights.size() / 2];
  out.median_height = median;
  const double tolerance = std::max(1.0, 0.2 * median);
  std::sort(letters.begin(), letters.end(), [](const Blob& a, const Blob& b) { return a.bottom < b.bottom; });
  for (std::size_t i = 0, from = 0; i < letters.size(); ++i) {
    while (letters[i].bottom - letters[from].bottom > tolerance) ++from;
    int beside = 0;
    for (std::size_t j = from; j < letters.size() && letters[j].bottom - letters[i].bottom <= tolerance && beside < 2;
         ++j) {
      if (j == i) continue;
      const int gap = std::max(letters[j].left - letters[i].right, letters[i].left - letters[j].right);
      beside += gap <= 2 * median;
    }
    if (beside >= 2) out.on_lines.push_back(letters[i]);
  }
  out.page = 2 * out.on_lines.size() >= letters.size();
  return out;
}

/// A line of large letters (a sign, a poster), light on dark or dark on light: at least kSignLetters
/// letter-like components (height 3–30 % of the shorter side, width 15–120 % of it, filling 15–70 % of their
/// box: strokes, not discs) of one height (within 25 %) on one baseline (within 15 % of it), each no further
/// than a height from the next, and narrower than tall on the whole (the median width under 0.9 heights: a
/// row of coins or pebbles is as wide as tall).
bool a_line_of_large_letters(const cv::Mat& side_up, double side, cv::Mat& labels) {
  constexpr std::size_t kSignLetters = 5;
  std::vector<Blob> letters;
  for (const auto& [r, area] : components(side_up, labels)) {
    const double fill = static_cast<double>(area) / (static_cast<double>(r.width) * r.height);
    if (r.height >= 0.03 * side && r.height <= 0.3 * side && r.width >= 0.15 * r.height && r.width <= 1.2 * r.height &&
        fill >= 0.15 && fill <= 0.7)
      letters.push_back({r.y + r.height, r.x, r.x + r.width, r.height});
  }
  std::sort(letters.begin(), letters.end(), [](const Blob& a, const Blob& b) { return a.left < b.left; });
  for (std::size_t i = 0; i < letters.size(); ++i) {
    std::vector<double> aspects{static_cast<double>(letters[i].right - letters[i].left) / letters[i].height};
    Blob last = letters[i];
    for (std::size_t j = i + 1; j < letters.size() && aspects.size() < kSignLetters; ++j) {
      const Blob& b = letters[j];
      const bool same = std::abs(b.height - letters[i].height) <= 0.25 * letters[i].height &&
                        std::abs(b.bottom - letters[i].bottom) <= 0.15 * letters[i].height;
      if (!same) continue;
      if (b.left - last.right > letters[i].height) break;
      last = b;
      aspects.push_back(static_cast<double>(b.right - b.left) / b.height);
    }
    if (aspects.size() < kSignLetters) continue;
    std::nth_element(aspects.begin(), aspects.begin() + static_cast<std::ptrdiff_t>(aspects.size() / 2), aspects.end());
    if (aspects[aspects.size() / 2] < 0.9) return true;
  }
  return false;
}

}  // namespace

bool looks_like_text_page(const cv::Mat& grey) {
  if (grey.empty() || grey.type() != CV_8UC1) return false;
  cv::Mat ink;
  cv::threshold(grey, ink, 0, 255, cv::THRESH_BINARY_INV | cv::THRESH_OTSU);
  const double side = std::min(grey.cols, grey.rows);
  cv::Mat labels;
  if (printed_letters(ink, side, labels).page) return true;
  if (a_line_of_large_letters(ink, side, labels)) return true;
  cv::bitwise_not(ink, ink);  // light letters on a dark ground
  return a_line_of_large_letters(ink, side, labels);
}

cv::Mat printed_letters_mask(const cv::Mat& grey) {
  if (grey.empty() || grey.type() != CV_8UC1) return {};
  cv::Mat ink;
  cv::threshold(grey, ink, 0, 255, cv::THRESH_BINARY_INV | cv::THRESH_OTSU);
  cv::Mat labels;
  const PrintedLetters letters = printed_letters(ink, std::min(grey.cols, grey.rows), labels);
  if (!letters.page) return {};
  cv::Mat mask(grey.size(), CV_8UC1, cv::Scalar(0));
  const int grow = static_cast<int>(std::ceil(0.5 * letters.median_height));
  for (const Blob& b : letters.on_lines) {
    cv::rectangle(mask, cv::Point(b.left - grow, b.bottom - b.height - grow),
                  cv::Point(b.right - 1 + grow, b.bottom - 1 + grow), cv::Scalar(255), cv::FILLED);
  }
  return mask;
}

}  // namespace hk::vision
