// The PDF and OCR workers' memory limit (RLIMIT_AS), which an AddressSanitizer build cannot host: ASan
// reserves terabytes of shadow memory, so the workers of such a build are started without the limit (the
// memory is only reported there). This suite is therefore built only without sanitizers: in a developer's
// build, and in CI beside the package's Release build (scripts/test.sh, HK_WORKER_LIMIT_TESTS).
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "test_paths.hpp"
#include "vision/ocr.hpp"
#include "vision/pdf.hpp"

#if defined(__SANITIZE_ADDRESS__)
#error "test_worker_limits is built without AddressSanitizer only (tests/CMakeLists.txt)"
#endif

namespace hk::vision {
namespace {

const std::string kData = HK_TEST_DATA_DIR;

std::vector<std::uint8_t> read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  EXPECT_TRUE(f.good()) << path;
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// The default limits, with a minute for the worker: these tests are about memory, not time.
PdfLimits generous() {
  PdfLimits l;
  l.worker_wall_s = 60.0;
  l.worker_cpu_s = 60.0;
  return l;
}

TEST(PdfWorkerLimits, MemoryLimitEndsInADefinedErrorAndTheNextPageRenders) {
  // 2 MiB on top of what the worker inherits: poppler's Splash returns a 1 x 1 bitmap (TooLarge) or, with a
  // little more room, crashes on a failed allocation (WorkerCrashed); either way the caller lives on.
  const auto spec = read_file(kData + "/documents/shared-mime-info-spec.pdf");
  PdfLimits limits = generous();
  limits.worker_max_memory_mb = 2;
  try {
    (void)render_pdf_page(spec, "spec", 1, limits);
    FAIL() << "a page rendered within 2 MiB";
  } catch (const PdfError& e) {
    EXPECT_TRUE(e.kind() == PdfError::Kind::TooLarge || e.kind() == PdfError::Kind::WorkerCrashed) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
  const PdfPage page =
      render_pdf_page(read_file(kData + "/documents/horse_and_page.pdf"), "horse_and_page.pdf", 2, generous());
  EXPECT_EQ(page.pages, 2);
  EXPECT_GT(page.grey.cols, 100);
}

TEST(OcrWorkerLimits, AWorkerThatRunsOutOfMemoryCostsTheTextInOneLine) {
  const cv::Mat grey = cv::imread(kData + "/images/page.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(grey.empty());
  OcrParams p;
  p.fault = OcrFault::Memory;
  p.worker_max_memory_mb = 256;
  try {
    (void)recognise_text(grey, "page.png", p);
    FAIL() << "the memory hog gave an answer";
  } catch (const OcrError& e) {
    EXPECT_EQ(e.kind(), OcrError::Kind::TooLarge) << e.what();
    EXPECT_NE(std::string(e.what()).find("ran out of memory (limit 256 MiB)"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
  // And the next picture is read as before.
  EXPECT_FALSE(recognise_text(grey, "page.png", {}).blocks.empty());
}

}  // namespace
}  // namespace hk::vision
