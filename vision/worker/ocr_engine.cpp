// The worker side of OCR (vision/ocr.hpp): Tesseract on the pixels of descriptor 3, the answer on
// descriptor 4. Built only into hk-ocr-worker; the kiosk process never links Tesseract.
//
// Answer: u32 magic 'HKOC', u8 status (0 = answer, 1 = refusal)
//   refusal: u8 OcrError::Kind, str problem
//   answer:  u32 words seen, u32 blocks; per block: u32 lines, u32 words; per word: str text, f64 x, y, w, h
//            [px], f64 confidence [0, 1]
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <span>
#include <string>
#include <vector>

#include <tesseract/baseapi.h>
#include <tesseract/resultiterator.h>

#include "ocr_wire.hpp"
#include "vision/ocr.hpp"
#include "worker_process.hpp"

namespace hk::vision {
namespace {

struct Refusal {
  OcrError::Kind kind;
  std::string problem;
};

struct Word {
  std::string text;
  int l = 0, t = 0, r = 0, b = 0;
  double confidence = 0;
};

struct Block {
  std::vector<Word> words;
  int lines = 0;
};

/// Share of a text's characters that are letters or digits (every non-ASCII character counts as a letter:
/// umlauts and accents are letters).
double letter_share(const std::string& s) {
  int letters = 0, all = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if ((c & 0xC0) == 0x80) continue;  // inside a UTF-8 sequence
    if (c == ' ') continue;
    ++all;
    letters += c >= 0x80 || std::isalnum(c) != 0;
  }
  return all == 0 ? 0.0 : static_cast<double>(letters) / all;
}

/// Tesseract's paragraphs, each with its words above noise (kNoiseWordConfidence); those with no clear word
/// (at or above the threshold) and garbled ones left out.
std::vector<Block> read_blocks(tesseract::TessBaseAPI& api, const OcrParams& p, std::uint32_t& seen) {
  std::vector<Block> blocks;
  std::unique_ptr<tesseract::ResultIterator> it(api.GetIterator());
  if (!it) return blocks;
  constexpr auto kWord = tesseract::RIL_WORD;
  Block current;
  bool line_has_word = false;
  auto close_block = [&] {
    std::string clear;  // its clear words: what it is judged by
    for (const Word& w : current.words)
      if (w.confidence >= p.min_word_confidence) clear += w.text + ' ';
    if (!clear.empty() && letter_share(clear) >= p.min_letter_share) blocks.push_back(std::move(current));
    current = Block{};
  };
  do {
    if (it->Empty(kWord)) continue;
    if (it->IsAtBeginningOf(tesseract::RIL_PARA)) close_block();
    if (it->IsAtBeginningOf(tesseract::RIL_TEXTLINE)) line_has_word = false;
    std::unique_ptr<char[]> text(it->GetUTF8Text(kWord));
    if (!text || text[0] == '\0') continue;
    ++seen;
    Word w;
    w.text = text.get();
    w.confidence = it->Confidence(kWord) / 100.0;
    if (w.confidence < std::min(p.min_word_confidence, kNoiseWordConfidence) ||
        !it->BoundingBox(kWord, &w.l, &w.t, &w.r, &w.b))
      continue;
    if (!line_has_word) ++current.lines;
    line_has_word = true;
    current.words.push_back(std::move(w));
  } while (it->Next(kWord));
  close_block();
  return blocks;
}

/// Clear words (at or above the threshold) kept in `blocks`.
std::size_t kept_words(const std::vector<Block>& blocks, const OcrParams& p) {
  std::size_t n = 0;
  for (const Block& b : blocks)
    for (const Word& w : b.words) n += w.confidence >= p.min_word_confidence;
  return n;
}

/// Words the page layout must keep for sparse text not to be tried as well.
constexpr std::size_t kEnoughForALayout = 3;

/// Starts Tesseract with the languages of `p` (LSTM engine, one thread, no debug output); a Refusal thrown
/// when it cannot.
void start_engine(tesseract::TessBaseAPI& api, const OcrParams& p) {
  ::setenv("OMP_THREAD_LIMIT", "1", 1);  // one core: the servo thread and the window keep theirs
  if (api.Init(p.tessdata_dir.empty() ? nullptr : p.tessdata_dir.c_str(), p.languages.c_str(),
               tesseract::OEM_LSTM_ONLY) != 0) {
    throw Refusal{OcrError::Kind::Unavailable, "Tesseract cannot start with the languages '" + p.languages + "'"};
  }
  api.SetVariable("debug_file", "/dev/null");
}

/// Reads the `width` x `height` grey `pixels` with a started engine: the answer (after the status byte) in
/// `out`, or a Refusal thrown.
void read_page(tesseract::TessBaseAPI& api, const std::uint8_t* pixels, int width, int height, const OcrParams& p,
               worker::WireWriter& out) {
  api.SetImage(pixels, width, height, 1, width);
  api.SetSourceResolution(300);
  // Pages: Tesseract's layout analysis. A sign or a poster in a photograph is no page layout: where that
  // finds (almost) nothing, sparse text (words wherever they stand) is tried too, and the better taken.
  std::uint32_t seen = 0;
  std::vector<Block> blocks;
  for (const tesseract::PageSegMode mode : {tesseract::PSM_AUTO, tesseract::PSM_SPARSE_TEXT}) {
    api.SetPageSegMode(mode);
    if (api.Recognize(nullptr) != 0)
      throw Refusal{OcrError::Kind::WorkerCrashed, "Tesseract could not read the picture"};
    std::uint32_t mode_seen = 0;
    std::vector<Block> found = read_blocks(api, p, mode_seen);
    if (kept_words(found, p) > kept_words(blocks, p)) {
      blocks = std::move(found);
      seen = mode_seen;
    }
    if (kept_words(blocks, p) >= kEnoughForALayout) break;
  }
  out.u32(seen);
  out.u32(static_cast<std::uint32_t>(blocks.size()));
  for (const Block& b : blocks) {
    out.u32(static_cast<std::uint32_t>(b.lines));
    out.u32(static_cast<std::uint32_t>(b.words.size()));
    for (const Word& w : b.words) {
      out.str(w.text);
      out.f64(w.l);
      out.f64(w.t);
      out.f64(w.r - w.l);
      out.f64(w.b - w.t);
      out.f64(w.confidence);
    }
  }
}

/// The worker's work: an answer in `out`, or a Refusal thrown.
void work(const std::uint8_t* pixels, int width, int height, const OcrParams& p, worker::WireWriter& out) {
  tesseract::TessBaseAPI api;
  start_engine(api, p);
  read_page(api, pixels, width, height, p, out);
  api.End();
}

[[noreturn]] void fail_on_purpose(OcrFault fault) {
  if (fault == OcrFault::Crash) worker::crash_on_purpose();
  if (fault == OcrFault::Hang) worker::hang_on_purpose();
  // Memory: allocate and touch until the limit says no.
  std::vector<std::unique_ptr<char[]>> hog;
  for (;;) {
    hog.emplace_back(new char[64 << 20]);
    std::memset(hog.back().get(), 1, 64 << 20);
  }
}

}  // namespace

int ocr_worker_entry(int argc, char** argv) {
  OcrRequest rq;
  if (!parse_ocr_request(argc, argv, rq)) return 64;
  const std::span<const std::uint8_t> pixels =
      worker::map_input(static_cast<std::size_t>(rq.width) * static_cast<std::size_t>(rq.height));
  if (pixels.empty()) return 65;
  worker::confine_worker(rq.params.worker_cpu_s, rq.params.worker_max_memory_mb);
  const worker::WireWriter out = worker::worker_answer<Refusal>(
      kOcrMagic,
      [&](worker::WireWriter& answer) {
        if (rq.params.fault != OcrFault::None) fail_on_purpose(rq.params.fault);
        work(pixels.data(), rq.width, rq.height, rq.params, answer);
      },
      std::pair{OcrError::Kind::TooLarge,
                "the text reader ran out of memory (limit " + worker::arg(rq.params.worker_max_memory_mb) + " MiB)"},
      std::pair{OcrError::Kind::WorkerCrashed, std::string("Tesseract failed on it")});
  worker::write_all(worker::kAnswerFd, out.bytes());
  ::_exit(0);
}

}  // namespace hk::vision
