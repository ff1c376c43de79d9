// Fuzz harness: the OCR worker's input path (vision/ocr.hpp), both ends of it.
//
// In the kiosk, Tesseract runs only in the worker process hk-ocr-worker on a stranger's pixels, and the
// kiosk reads the worker's answer. Byte 0 of an input picks which end is fuzzed:
//  - even: the worker. Bytes 1 and 2 give a picture of 1–96 x 1–96 pixels, the rest are its grey values
//    (repeated to fill it). The worker's own read_page (vision/worker/ocr_engine.cpp, compiled into this
//    file: its functions are internal to it, nothing in it is changed) reads it with one Tesseract engine
//    started once, its records gathered as the pipe would carry them; then the kiosk's read_ocr_answer must accept that
//    answer: every word of a block with text, a finite box and a confidence in [0, 1], the mean confidence in [0, 1]; a
//    refusal must be of a kind the kiosk accepts, with a one-line problem.
//  - odd: the kiosk. The rest is a worker's answer (magic, then records) as it comes down the pipe: read_ocr_answer
//    either reads it
//    into a result with the same properties or refuses it with an OcrError whose what() is one line; it
//    never reads past the end or allocates what the sizes claim before checking them.
#include "ocr_engine.cpp"  // vision/worker/ocr_engine.cpp, for its internal start_engine() and read_page()

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "fuzz_common.hpp"

namespace hk::vision {
namespace {

/// What every result the kiosk accepts holds.
void check_result(const OcrResult& r) {
  std::size_t words = 0;
  for (const OcrBlock& b : r.blocks) {
    FUZZ_CHECK(!b.text.empty() && b.lines >= 1, b.text);
    FUZZ_CHECK(b.confidence >= 0 && b.confidence <= 1, b.text);
    FUZZ_CHECK(std::isfinite(b.box_px.x) && std::isfinite(b.box_px.y) && b.box_px.width >= 0 && b.box_px.height >= 0,
               b.text);
  }
  for (const OcrWord& w : r.words) {
    FUZZ_CHECK(w.confidence >= 0 && w.confidence <= 1, w.text);
    FUZZ_CHECK(std::isfinite(w.box_px.x) && std::isfinite(w.box_px.y) && w.box_px.width >= 0 && w.box_px.height >= 0,
               w.text);
    ++words;
  }
  FUZZ_CHECK(r.blocks.size() <= words, "more blocks than words");
  std::size_t lines = 0;
  for (const OcrBlock& b : r.blocks) lines += static_cast<std::size_t>(b.lines);
  FUZZ_CHECK(lines <= words, "more lines than words");
  FUZZ_CHECK(r.mean_confidence >= 0 && r.mean_confidence <= 1, std::to_string(r.mean_confidence));
  FUZZ_CHECK(r.words_seen >= 0, std::to_string(r.words_seen));
}

/// The kiosk reads `answer` as the worker's; an OcrError must be one line.
void read_as_kiosk(const std::string& answer, bool must_parse) {
  worker::WorkerRun run;
  run.answer = answer;
  run.status = 0;  // the worker exited with 0, as it does after writing its answer
  try {
    check_result(read_ocr_answer(run, "fuzz", OcrParams{}));
  } catch (const OcrError& e) {
    FUZZ_CHECK(hk::fuzz::is_one_line(e.what()), e.what());
    FUZZ_CHECK(std::string(e.what()).rfind("ocr 'fuzz': ", 0) == 0, e.what());
    FUZZ_CHECK(!must_parse || std::string(e.what()).find("no usable answer") == std::string::npos, e.what());
  }
}

tesseract::TessBaseAPI& engine() {
  static tesseract::TessBaseAPI* api = [] {
    auto* a = new tesseract::TessBaseAPI;  // kept for the process's life, as the worker keeps its one engine
    start_engine(*a, OcrParams{});
    return a;
  }();
  return *api;
}

void read_as_worker(const std::uint8_t* data, std::size_t size) {
  const int w = 1 + data[0] % 96, h = 1 + data[1] % 96;
  std::vector<std::uint8_t> px(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 255);
  if (size > 2)
    for (std::size_t i = 0; i < px.size(); ++i) px[i] = data[2 + i % (size - 2)];
  worker::WireWriter magic;
  magic.u32(kOcrMagic);
  std::string answer = magic.bytes();
  const Emit emit = [&answer](const std::string& record) { answer += record; };
  try {
    read_page(engine(), px.data(), w, h, OcrParams{}, emit);
  } catch (const Refusal& r) {
    FUZZ_CHECK(r.kind <= OcrError::Kind::WorkerCrashed, r.problem);
    emit(refusal(r.kind, r.problem));
  }
  read_as_kiosk(answer, true);
}

}  // namespace
}  // namespace hk::vision

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  hk::vision::engine();  // Tesseract's models load once, not per run
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  if (data[0] % 2 == 0) {
    hk::vision::read_as_worker(data + 1, size - 1);
  } else {
    hk::vision::read_as_kiosk(std::string(reinterpret_cast<const char*>(data + 1), size - 1), false);
  }
  return 0;
}
