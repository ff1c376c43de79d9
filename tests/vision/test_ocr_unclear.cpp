// Words OCR is unsure of: the kiosk reads the worker's answer (the wire format of vision/src/ocr_wire.hpp, built
// here as a worker would send it); a word under the confidence threshold is still said as read (real text such as
// code words is often read right with a low confidence), a mark with no letter or digit under it is kUnclearWord;
// every box still counts as text (masked out of the curves).
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "ocr_wire.hpp"
#include "vision/ocr.hpp"

namespace hk::vision {
namespace {

/// A worker's answer of one block of one line: `words` as (text, confidence).
worker::WorkerRun answer(const std::vector<std::pair<std::string, double>>& words) {
  worker::WireWriter block;
  block.u32(1);  // lines
  block.u32(static_cast<std::uint32_t>(words.size()));
  double x = 10;
  for (const auto& [text, confidence] : words) {
    block.str(text);
    block.f64(x);
    block.f64(20);
    block.f64(30);
    block.f64(12);
    block.f64(confidence);
    x += 40;
  }
  block.str("eng");  // the language most of its words were read in
  worker::WireWriter end;
  end.u32(static_cast<std::uint32_t>(words.size()));  // words seen
  worker::WireWriter out;
  out.u32(kOcrMagic);
  const std::string records = ocr_record(OcrRecord::block, block) + ocr_record(OcrRecord::end, end);
  out.raw(records.data(), records.size());
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

TEST(OcrAnswer, EachBlockIsHandedOnAsSoonAsItsRecordHasComeWhateverTheReadsCut) {
  // Two blocks and the end, as the pipe may cut them: byte by byte.
  const std::string one = answer({{"First", 0.9}, {"words", 0.9}}).answer;
  const std::string two = answer({{"Second", 0.9}}).answer;
  const std::size_t head = sizeof(std::uint32_t);  // the magic
  worker::WireWriter end;
  end.u32(3);
  // The first answer's block record, then the second's, then an end: records are [tag u8][size u32][payload].
  const auto record_at = [](const std::string& a, std::size_t at) {
    std::uint32_t size = 0;
    std::memcpy(&size, a.data() + at + 1, sizeof size);
    return a.substr(at, 5 + size);
  };
  const std::string whole =
      one.substr(0, head) + record_at(one, head) + record_at(two, head) + ocr_record(OcrRecord::end, end);
  std::vector<std::string> handed;
  std::vector<std::size_t> handed_at;  // bytes fed when each block was handed on
  OcrParams p;
  p.on_block = [&](const OcrBlock& b) { handed.push_back(b.text); };
  OcrAnswerReader reader(p);
  for (std::size_t n = 1; n <= whole.size(); ++n) {
    const std::size_t before = handed.size();
    ASSERT_TRUE(reader.feed(whole.substr(0, n))) << n;
    if (handed.size() > before) handed_at.push_back(n);
  }
  ASSERT_EQ(handed, (std::vector<std::string>{"First words", "Second"}));
  // Each at the very byte that completed its record, the end still to come.
  EXPECT_EQ(handed_at[0], head + record_at(one, head).size());
  EXPECT_EQ(handed_at[1], head + record_at(one, head).size() + record_at(two, head).size());
  EXPECT_TRUE(reader.ended());
  EXPECT_EQ(reader.result().blocks.size(), 2u);
  EXPECT_EQ(reader.result().words_seen, 3);
  // A record after the end, or a tag no worker writes, is a malformed answer.
  EXPECT_FALSE(OcrAnswerReader(p).feed(whole + ocr_record(OcrRecord::end, end)));
  std::string bad_tag = whole;
  bad_tag[head] = 7;
  EXPECT_FALSE(OcrAnswerReader(OcrParams{}).feed(bad_tag));
}

}  // namespace
}  // namespace hk::vision
