// With [vision] ocr = "auto", pages that are pictures of text are read, never felt: a scan made here from the shipped
// PDF (150 dpi, turned 1.5°, noise, JPEG 80) becomes text blocks read by OCR ("source": "ocr", with their confidence)
// whose words are 90 % of pdftotext's, with at most 5 curves left inside them; the same scan wrapped in an
// image-only PDF (no text layer, as scan-to-PDF apps write) gives the same text; every shipped photograph
// and silhouette gives no text block; [vision] ocr = "off" feels the page's words; explore writes it all.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <stdlib.h>

#include <opencv2/imgcodecs.hpp>

#include "image_pdf.hpp"
#include "kiosk_exe.hpp"
#include "pictures/documents.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/runtime_params.hpp"
#include "scans.hpp"
#include "test_paths.hpp"
#include "vision/pdf.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

const fs::path kData = HK_TEST_DATA_DIR;
const fs::path kSpec = kData / "documents" / "shared-mime-info-spec.pdf";
constexpr int kPage = 3;
constexpr int kDpi = 150;

/// The shipped settings with text reading on ("auto").
config::Settings reading() {
  config::Settings s;
  s.vision.ocr = "auto";
  return s;
}

std::string all_text(const ImageScene& is) {
  std::string t;
  for (const TextBlockM& b : is.text_blocks) t += b.text + "\n";
  return t;
}

/// Curves whose bounding box's centre lies inside a text block: what a hand would feel of the text.
int curves_in_text(const ImageScene& is) {
  int n = 0;
  for (const Polyline& p : is.polylines) {
    Vec2 lo = p.points_m[0], hi = p.points_m[0];
    for (Vec2 q : p.points_m) {
      lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
      hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
    }
    const Vec2 c = 0.5 * (lo + hi);
    for (const TextBlockM& b : is.text_blocks) {
      if (b.contains(c)) {
        ++n;
        break;
      }
    }
  }
  return n;
}

struct ScanRig {
  fs::path dir = test::fresh_dir("ocr_scene");
  std::vector<std::uint8_t> jpeg;
  std::vector<std::string> truth;
  ScanRig() {
    jpeg = test::scan_jpeg(kSpec, kPage, kDpi, 1.5, dir);
    truth = test::words_of(test::pdftotext_page(kSpec, kPage, dir));
  }
  ~ScanRig() { fs::remove_all(dir); }
};

TEST(OcrScene, AScannedPageIsReadAsTextBlocksNotFeltAsBumps) {
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  ScanRig r;
  ASSERT_FALSE(r.jpeg.empty());
  const config::Settings s = reading();
  const ImageScene is = build_image_scene_from_bytes(r.jpeg, "scan.jpg", s);
  EXPECT_TRUE(is.ocr.ran) << is.ocr.why;
  EXPECT_EQ(is.ocr.why, "a page of text");
  ASSERT_GE(is.text_blocks.size(), 3u);
  for (const TextBlockM& b : is.text_blocks) {
    EXPECT_EQ(b.source, "ocr");
    EXPECT_GE(b.confidence, 0.6);
    EXPECT_LE(b.confidence, 1.0);
    EXPECT_LT(b.lo_m.x, b.hi_m.x);
    EXPECT_LT(b.lo_m.y, b.hi_m.y);
  }
  EXPECT_GE(test::word_recall(r.truth, test::words_of(all_text(is))), 0.9) << all_text(is).substr(0, 800);
  EXPECT_LE(curves_in_text(is), 5) << "of " << is.polylines.size() << " curves";
  EXPECT_EQ(is.ocr.words, static_cast<int>(is.text_words_masked));
  EXPECT_GT(is.ocr.worker_max_rss_kb, 0);

  // [vision] ocr = "off": the words are felt as bumps again, as a check that the mask is what removed them.
  config::Settings off;
  off.vision.ocr = "off";
  const ImageScene felt = build_image_scene_from_bytes(r.jpeg, "scan.jpg", off);
  EXPECT_FALSE(felt.ocr.ran);
  EXPECT_EQ(felt.ocr.why, "off");
  EXPECT_TRUE(felt.text_blocks.empty());
  EXPECT_GT(felt.polylines.size(), 10u) << "outlines of words";
}

TEST(OcrScene, TheSameScanInAnImageOnlyPdfGivesTheSameText) {
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  ScanRig r;
  const cv::Mat grey = cv::imdecode(r.jpeg, cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(grey.empty());
  const std::string pdf = test::image_only_pdf(r.jpeg, grey.cols, grey.rows, kDpi);
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(pdf.data()), pdf.size());
  vision::PdfLimits limits;
  limits.max_dpi = kDpi;  // drawn at the scan's own resolution
  const vision::PdfPage page = vision::render_pdf_page(bytes, "scan.pdf", 1, limits);
  EXPECT_TRUE(page.words.empty()) << "no text layer";
  const config::Settings s = reading();
  const ImageScene from_pdf = build_page_scene(page, "scan.pdf", 1, s);
  EXPECT_TRUE(from_pdf.ocr.ran);
  EXPECT_EQ(from_pdf.ocr.why, "no text layer");
  const ImageScene from_jpeg = build_image_scene_from_bytes(r.jpeg, "scan.jpg", s);
  ASSERT_FALSE(from_pdf.text_blocks.empty());
  // Drawn again by poppler, the pixels differ a little, and Tesseract may split a paragraph differently.
  EXPECT_NEAR(static_cast<double>(from_pdf.text_blocks.size()), static_cast<double>(from_jpeg.text_blocks.size()),
              std::max(2.0, 0.2 * static_cast<double>(from_jpeg.text_blocks.size())));
  EXPECT_GE(test::word_recall(test::words_of(all_text(from_jpeg)), test::words_of(all_text(from_pdf))),
            0.93);  // measured 0.96
  EXPECT_GE(test::word_recall(r.truth, test::words_of(all_text(from_pdf))), 0.9);
  for (const TextBlockM& b : from_pdf.text_blocks) EXPECT_EQ(b.source, "ocr");
}

TEST(OcrScene, AStickPageIsDrawnAtTheScreenSideUnlessItsTextLayerLeavesTextForOcr) {
  constexpr int kSide = 1037;  // the picture side of a 1920 x 1080 screen
  const config::Settings s = reading();
  // A page whose text layer is its text: drawn at the screen side, with the blocks and the decision the
  // full drawing gives.
  const std::vector<std::uint8_t> spec = [] {
    std::ifstream f(kSpec, std::ios::binary);
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(f), {});
  }();
  const ImageScene small =
      build_pdf_page_scene(spec, "spec.pdf", kPage, s, vision::PdfFault::None, TextTiming::later, kSide);
  const ImageScene full =
      build_pdf_page_scene(spec, "spec.pdf", kPage, s, vision::PdfFault::None, TextTiming::later, 0);
  EXPECT_EQ(std::max(small.file_width_px, small.file_height_px), kSide);
  EXPECT_GT(std::max(full.file_width_px, full.file_height_px), 2000);
  EXPECT_EQ(small.ocr.why, "a text layer");
  EXPECT_EQ(full.ocr.why, "a text layer");
  EXPECT_FALSE(small.text_pending);
  ASSERT_EQ(small.text_blocks.size(), full.text_blocks.size());
  for (std::size_t i = 0; i < full.text_blocks.size(); ++i) {
    SCOPED_TRACE(full.text_blocks[i].text);
    EXPECT_EQ(small.text_blocks[i].text, full.text_blocks[i].text);
    EXPECT_NEAR(small.text_blocks[i].lo_m.x, full.text_blocks[i].lo_m.x, 1e-3);
    EXPECT_NEAR(small.text_blocks[i].lo_m.y, full.text_blocks[i].lo_m.y, 1e-3);
    EXPECT_NEAR(small.text_blocks[i].hi_m.x, full.text_blocks[i].hi_m.x, 1e-3);
    EXPECT_NEAR(small.text_blocks[i].hi_m.y, full.text_blocks[i].hi_m.y, 1e-3);
  }

  // A scan whose text layer is one stamped line: the layer covers little, so the page is drawn again at the
  // full budget and its text is left for OCR.
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  ScanRig r;
  const cv::Mat grey = cv::imdecode(r.jpeg, cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(grey.empty());
  const std::string pdf = test::image_only_pdf(r.jpeg, grey.cols, grey.rows, kDpi, "Scanned at the library");
  const std::vector<std::uint8_t> bytes(pdf.begin(), pdf.end());
  const ImageScene scan =
      build_pdf_page_scene(bytes, "scan.pdf", 1, s, vision::PdfFault::None, TextTiming::later, kSide);
  EXPECT_EQ(scan.ocr.why, "text layer covers little of the text");
  EXPECT_TRUE(scan.text_pending);
  const vision::PdfPage drawn = vision::render_pdf_page(bytes, "scan.pdf", 1, pdf_limits_from(s));
  EXPECT_EQ(scan.file_width_px, drawn.grey.cols);
  EXPECT_EQ(scan.file_height_px, drawn.grey.rows);
  EXPECT_GT(std::max(scan.file_width_px, scan.file_height_px), kSide);
}

TEST(OcrScene, APdfWithATextLayerKeepsItsOwnText) {
  const std::vector<std::uint8_t> bytes = [] {
    std::ifstream f(kSpec, std::ios::binary);
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(f), {});
  }();
  const vision::PdfPage page = vision::render_pdf_page(bytes, "spec.pdf", kPage, {});
  const ImageScene is = build_page_scene(page, "spec.pdf", kPage, reading());
  EXPECT_FALSE(is.ocr.ran);
  EXPECT_EQ(is.ocr.why, "a text layer");
  ASSERT_FALSE(is.text_blocks.empty());
  for (const TextBlockM& b : is.text_blocks) {
    EXPECT_EQ(b.source, "pdf");
    EXPECT_EQ(b.confidence, 1.0);
  }
}

TEST(OcrScene, PhotographsAndSilhouettesGiveNoTextBlock) {
  const config::Settings s = reading();
  for (const fs::path& p : test::test_images()) {
    if (p.filename() == "page.png") continue;  // a photo of a book page: text
    const ImageScene is = build_image_scene(p.string(), s);
    EXPECT_TRUE(is.text_blocks.empty()) << p.filename() << ": " << all_text(is);
    EXPECT_FALSE(is.ocr.ran) << p.filename() << " was taken for text: " << is.ocr.why;
  }
}

TEST(OcrScene, ExploreWritesTheBlocksWithTheirSourceAndTheOcrSummary) {
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  ScanRig r;
  {
    std::ofstream f(r.dir / "scan.jpg", std::ios::binary);
    f.write(reinterpret_cast<const char*>(r.jpeg.data()), static_cast<std::streamsize>(r.jpeg.size()));
  }
  std::ofstream(r.dir / "reading.toml") << "[vision]\nocr = \"auto\"\n";
  const test::ExeResult run = test::run_kiosk("explore " + test::quoted(r.dir / "scan.jpg") + " --config " +
                                                  test::quoted(r.dir / "reading.toml") + " --out " +
                                                  test::quoted(r.dir / "out") + " --duration 0.5",
                                              r.dir);
  ASSERT_EQ(run.status, 0) << run.err;
  std::ifstream sf(r.dir / "out" / "summary.json"), jf(r.dir / "out" / "scene.json");
  const nlohmann::json summary = nlohmann::json::parse(sf), scene = nlohmann::json::parse(jf);
  EXPECT_EQ(summary["ocr"]["ran"], true);
  EXPECT_EQ(summary["ocr"]["why"], "a page of text");
  EXPECT_GT(summary["ocr"]["words"].get<int>(), 200);
  EXPECT_GT(summary["ocr"]["mean_confidence"].get<double>(), 0.8);
  EXPECT_GT(summary["ocr"]["ms"].get<double>(), 0.0);
  ASSERT_GE(scene["text_blocks"].size(), 3u);
  for (const auto& b : scene["text_blocks"]) {
    EXPECT_EQ(b["source"], "ocr");
    EXPECT_GE(b["confidence"].get<double>(), 0.6);
    EXPECT_EQ(b["bbox_m"].size(), 4u);
  }
}

// A text reader that crashes (a worker killed by SIGSEGV, as a Tesseract bug on a stranger's pixels would
// kill it): the page is still felt, its text is reported unavailable in one line, and explore ends normally.
TEST(OcrScene, AWorkerThatCrashesCostsTheTextNeverThePage) {
  if (!test::have_poppler_utils())
    GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  ScanRig r;
  {
    std::ofstream f(r.dir / "scan.jpg", std::ios::binary);
    f.write(reinterpret_cast<const char*>(r.jpeg.data()), static_cast<std::streamsize>(r.jpeg.size()));
  }
  const fs::path crash = r.dir / "crashing-worker.sh";
  std::ofstream(crash) << "#!/bin/sh\nkill -SEGV $$\n";
  fs::permissions(crash, fs::perms::owner_all);
  ASSERT_EQ(::setenv("HK_OCR_WORKER", crash.c_str(), 1), 0);
  const test::ExeResult run = test::run_kiosk(
      "explore " + test::quoted(r.dir / "scan.jpg") + " --out " + test::quoted(r.dir / "out") + " --duration 0.5",
      r.dir);
  ::unsetenv("HK_OCR_WORKER");
  ASSERT_EQ(run.status, 0) << run.err;
  std::ifstream sf(r.dir / "out" / "summary.json"), jf(r.dir / "out" / "scene.json");
  const nlohmann::json summary = nlohmann::json::parse(sf), scene = nlohmann::json::parse(jf);
  EXPECT_EQ(summary["ocr"]["ran"], false);
  const std::string why = summary["ocr"]["why"];
  EXPECT_EQ(why, "failed: ocr '" + (r.dir / "scan.jpg").string() + "': the text reader stopped (signal 11)");
  EXPECT_TRUE(!scene.contains("text_blocks") || scene["text_blocks"].empty());
  EXPECT_GT(scene["curves"].size(), 0u) << "the page is still felt";
}

}  // namespace
}  // namespace hk::app
