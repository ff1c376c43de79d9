// The worker side of OCR (vision/ocr.hpp): Tesseract on the pixels of descriptor 3, the answer on
// descriptor 4. Built only into hk-ocr-worker; the kiosk process never links Tesseract.
//
// Answer: u32 magic 'HKOC', then records as they are read (ocr_wire.hpp): a block record for each text block
// (sent the moment it is read), then an end record, or a refusal record when the work fails.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <new>
#include <span>
#include <string>
#include <vector>

#include <leptonica/allheaders.h>
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
  std::string language;  // the Tesseract language whose model read it ("fra"), "" when not said
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
    if (const char* language = it->WordRecognitionLanguage()) w.language = language;
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

/// Sends one record of the answer at once (the kiosk reads each as it comes).
using Emit = std::function<void(const std::string& record)>;

/// The language most of `b`'s words were read in ("" when none says).
std::string block_language(const Block& b) {
  std::map<std::string, int> votes;
  for (const Word& w : b.words)
    if (!w.language.empty()) ++votes[w.language];
  std::string best;
  int most = 0;
  for (const auto& [language, n] : votes)
    if (n > most) {
      most = n;
      best = language;
    }
  return best;
}

void send_block(const Block& b, const Emit& emit) {
  worker::WireWriter out;
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
  out.str(block_language(b));
  emit(ocr_record(OcrRecord::block, out));
}

/// One text block of the layout: the picture's pixels over its box, white outside its polygon grown by the
/// margins (so no piece of a neighbouring block, tilted into the box on a turned page, is read with it).
struct BlockImage {
  int l = 0, t = 0, w = 0, h = 0;  ///< its box in the picture [px]
  std::vector<std::uint8_t> grey;  ///< w x h, row after row
};

/// Pixel columns of row `y` + 0.5 inside `polygon` (even-odd rule), as [from, to) spans.
std::vector<std::pair<int, int>> row_spans(const std::vector<std::pair<int, int>>& polygon, int y) {
  std::vector<double> xs;
  const double yc = y + 0.5;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const auto [x0, y0] = polygon[i];
    const auto [x1, y1] = polygon[(i + 1) % polygon.size()];
    if ((y0 <= yc) == (y1 <= yc)) continue;
    xs.push_back(x0 + (yc - y0) * (x1 - x0) / static_cast<double>(y1 - y0));
  }
  std::sort(xs.begin(), xs.end());
  std::vector<std::pair<int, int>> spans;
  for (std::size_t i = 0; i + 1 < xs.size(); i += 2)
    spans.push_back({static_cast<int>(std::floor(xs[i])), static_cast<int>(std::ceil(xs[i + 1]))});
  return spans;
}

/// The block the iterator is at, cut out of the `width` x `height` `pixels`: its polygon (its box when it has
/// none) grown by `mx` columns and `my` rows.
BlockImage cut_block(const tesseract::PageIterator& it, const std::uint8_t* pixels, int width, int height, int mx,
                     int my) {
  std::vector<std::pair<int, int>> polygon;
  if (Pta* pta = it.BlockPolygon()) {
    for (int i = 0; i < ptaGetCount(pta); ++i) {
      int x = 0, y = 0;
      if (ptaGetIPt(pta, i, &x, &y) == 0) polygon.push_back({x, y});
    }
    ptaDestroy(&pta);
  }
  int l = 0, t = 0, r = 0, b = 0;
  it.BoundingBox(tesseract::RIL_BLOCK, &l, &t, &r, &b);
  if (polygon.size() < 3) polygon = {{l, t}, {r, t}, {r, b}, {l, b}};
  BlockImage out;
  out.l = std::max(0, l - mx);
  out.t = std::max(0, t - my);
  out.w = std::min(width, r + mx) - out.l;
  out.h = std::min(height, b + my) - out.t;
  if (out.w <= 0 || out.h <= 0) return {};
  out.grey.assign(static_cast<std::size_t>(out.w) * static_cast<std::size_t>(out.h), 255);
  std::vector<std::vector<std::pair<int, int>>> spans(static_cast<std::size_t>(out.h));
  for (int y = out.t; y < out.t + out.h; ++y) spans[static_cast<std::size_t>(y - out.t)] = row_spans(polygon, y);
  for (int y = out.t; y < out.t + out.h; ++y) {
    std::uint8_t* row = out.grey.data() + static_cast<std::size_t>(y - out.t) * static_cast<std::size_t>(out.w);
    const std::uint8_t* src = pixels + static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
    for (int yy = std::max(out.t, y - my); yy <= std::min(out.t + out.h - 1, y + my); ++yy)
      for (const auto& [from, to] : spans[static_cast<std::size_t>(yy - out.t)]) {
        const int x0 = std::max(out.l, from - mx), x1 = std::min(out.l + out.w, to + mx);
        for (int x = x0; x < x1; ++x) row[x - out.l] = src[x];
      }
  }
  return out;
}

/// The text blocks of Tesseract's layout analysis of the `width` x `height` `pixels` (set as the image), in its
/// reading order.
std::vector<BlockImage> text_blocks(tesseract::TessBaseAPI& api, const std::uint8_t* pixels, int width, int height) {
  std::vector<BlockImage> blocks;
  std::unique_ptr<tesseract::PageIterator> it(api.AnalyseLayout());
  if (!it) return blocks;
  const int side = std::max(width, height);
  const int mx = std::max(kBlockMarginMinPx, static_cast<int>(kBlockMargin * side));
  const int my = std::max(kBlockMarginMinPx / 2, static_cast<int>(kBlockMargin / 4 * side));
  do {
    if (!PTIsTextType(it->BlockType())) continue;
    BlockImage b = cut_block(*it, pixels, width, height, mx, my);
    if (!b.grey.empty()) blocks.push_back(std::move(b));
  } while (it->Next(tesseract::RIL_BLOCK));
  return blocks;
}

/// Moves the words of `blocks` by (dx, dy) [px]: from a block's own image into the picture's.
void shift(std::vector<Block>& blocks, int dx, int dy) {
  for (Block& b : blocks)
    for (Word& w : b.words) {
      w.l += dx;
      w.r += dx;
      w.t += dy;
      w.b += dy;
    }
}

/// Reads the `width` x `height` grey `pixels` with a started engine, sending each block as it is read and then
/// the end record; a Refusal thrown when Tesseract fails.
void read_page(tesseract::TessBaseAPI& api, const std::uint8_t* pixels, int width, int height, const OcrParams& p,
               const Emit& emit) {
  api.SetImage(pixels, width, height, 1, width);
  api.SetSourceResolution(300);
  api.SetPageSegMode(tesseract::PSM_AUTO);
  const std::vector<BlockImage> cut = text_blocks(api, pixels, width, height);
  // Each block of the layout on its own, sent as soon as the page has shown it is a page (kEnoughForALayout
  // clear words): until then held, since a sign or a poster in a photograph is no page layout.
  std::uint32_t seen = 0;
  std::vector<Block> held;
  std::size_t kept = 0;
  bool sending = false;
  for (const BlockImage& c : cut) {
    api.SetImage(c.grey.data(), c.w, c.h, 1, c.w);
    api.SetSourceResolution(300);
    api.SetPageSegMode(tesseract::PSM_SINGLE_BLOCK);
    if (api.Recognize(nullptr) != 0)
      throw Refusal{OcrError::Kind::WorkerCrashed, "Tesseract could not read the picture"};
    std::vector<Block> read = read_blocks(api, p, seen);
    shift(read, c.l, c.t);
    for (Block& b : read) {
      for (const Word& w : b.words) kept += w.confidence >= p.min_word_confidence;
      held.push_back(std::move(b));
    }
    sending = sending || kept >= kEnoughForALayout;
    if (sending) {
      for (const Block& b : held) send_block(b, emit);
      held.clear();
    }
  }
  if (!sending) {
    // (Almost) nothing as a page: sparse text (words wherever they stand) on the whole picture, the better taken.
    api.SetImage(pixels, width, height, 1, width);
    api.SetSourceResolution(300);
    api.SetPageSegMode(tesseract::PSM_SPARSE_TEXT);
    if (api.Recognize(nullptr) != 0)
      throw Refusal{OcrError::Kind::WorkerCrashed, "Tesseract could not read the picture"};
    std::uint32_t sparse_seen = 0;
    std::vector<Block> sparse = read_blocks(api, p, sparse_seen);
    if (kept_words(sparse, p) > kept) {
      held = std::move(sparse);
      seen = sparse_seen;
    }
    for (const Block& b : held) send_block(b, emit);
  }
  worker::WireWriter end;
  end.u32(seen);
  emit(ocr_record(OcrRecord::end, end));
}

/// The worker's work: its records sent with `emit`, or a Refusal thrown.
void work(const std::uint8_t* pixels, int width, int height, const OcrParams& p, const Emit& emit) {
  tesseract::TessBaseAPI api;
  start_engine(api, p);
  read_page(api, pixels, width, height, p, emit);
  api.End();
}

/// The refusal record of `kind` and `problem`.
std::string refusal(OcrError::Kind kind, const std::string& problem) {
  worker::WireWriter out;
  out.u8(static_cast<std::uint8_t>(kind));
  out.str(problem);
  return ocr_record(OcrRecord::refusal, out);
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
  worker::WireWriter magic;
  magic.u32(kOcrMagic);
  worker::write_all(worker::kAnswerFd, magic.bytes());
  const Emit emit = [](const std::string& record) { worker::write_all(worker::kAnswerFd, record); };
  try {
    if (rq.params.fault != OcrFault::None) fail_on_purpose(rq.params.fault);
    work(pixels.data(), rq.width, rq.height, rq.params, emit);
  } catch (const Refusal& r) {
    emit(refusal(r.kind, r.problem));
  } catch (const std::bad_alloc&) {
    emit(refusal(OcrError::Kind::TooLarge,
                 "the text reader ran out of memory (limit " + worker::arg(rq.params.worker_max_memory_mb) + " MiB)"));
  } catch (...) {
    emit(refusal(OcrError::Kind::WorkerCrashed, "Tesseract failed on it"));
  }
  ::_exit(0);
}

}  // namespace hk::vision
