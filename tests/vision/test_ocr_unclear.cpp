// Words OCR is unsure of: the kiosk reads the worker's answer (the wire format of vision/src/ocr_wire.hpp, built
// here as a worker would send it); a word under the confidence threshold is still said as read (real text such as
// code words is often read right with a low confidence), a mark with no letter or digit under it is kUnclearWord;
// every box still counts as text (masked out of the curves).
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "ocr_wire.hpp"
#include "vision/ocr.hpp"

namespace hk::vision {
namespace {

/// A worker's answer of one block of one line: `words` as (text, confidence).
worker::WorkerRun answer(const std::vector<std::pair<std::string, double>>& words) {
  worker::WireWriter out;
  out.u32(kOcrMagic);
  out.u8(0);
  out.u32(static_cast<std::uint32_t>(words.size()));  // words seen
  out.u32(1);                                         // blocks
  out.u32(1);                                         // lines
  out.u32(static_cast<std::uint32_t>(words.size()));
  double x = 10;
  for (const auto& [text, confidence] : words) {
    out.str(text);
    out.f64(x);
    out.f64(20);
    out.f64(30);
    out.f64(12);
    out.f64(confidence);
    x += 40;
  }
  worker::WorkerRun run;
  run.answer = out.bytes();
  return run;
}

TEST(OcrUnclear, AWordUnderTheThresholdIsSaidAndAMarkIsUnclear) {
  OcrParams p;
  p.min_word_confidence = 0.6;
  const OcrResult r = read_ocr_answer(
      answer({{"The", 0.95}, {"mime.cache", 0.41}, {"opens", 0.9}, {"at", 0.88}, {"|~", 0.35}, {"--", 0.32}}), "page",
      p);
  ASSERT_EQ(r.blocks.size(), 1u);
  const std::string u(kUnclearWord);
  EXPECT_EQ(r.blocks[0].text, "The mime.cache opens at " + u + " " + u);
  ASSERT_EQ(r.words.size(), 6u) << "every word's box is kept: it is text, not a shape";
  EXPECT_EQ(r.blocks[0].box_px, cv::Rect2d(10, 20, 230, 12)) << "the block covers its unclear marks too";
  // A sure mark is said as read; with the threshold at 0.3 every mark here is.
  p.min_word_confidence = 0.3;
  EXPECT_EQ(read_ocr_answer(answer({{"The", 0.95}, {"|~", 0.41}}), "page", p).blocks[0].text, "The |~");
}

}  // namespace
}  // namespace hk::vision
