// Text read from pictures of pages (OCR with Tesseract in its worker): scans made here from the shipped
// PDFs as a scanner and a phone make them (pdftoppm at 150 and 300 dpi, turned ±1.5°, sensor noise, JPEG
// quality 80) are read with a word recall of at least 0.9 against pdftotext of the same page; photographs
// and silhouettes give no text; a worker that crashes, hangs or runs out of memory costs the text in one
// line, never the caller; a missing language is named.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vision/ocr.hpp"

namespace fs = std::filesystem;

namespace hk::vision {
namespace {

const fs::path kData = HK_TEST_DATA_DIR;

int sh(const std::string& cmd) {
  const int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
}

bool have(const char* tool) { return sh(std::string("command -v ") + tool + " >/dev/null 2>&1") == 0; }

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hk_ocr_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

/// The words of `text`: lower case, letters and digits only, empty ones left out.
std::vector<std::string> words_of(const std::string& text) {
  std::vector<std::string> out;
  std::string w;
  for (char c : text + " ") {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      w += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!w.empty()) {
      out.push_back(w);
      w.clear();
    }
  }
  return out;
}

/// Share of the words of `truth` that `read` has too (each read word counts once: a multiset intersection).
double recall(const std::vector<std::string>& truth, const std::vector<std::string>& read) {
  std::map<std::string, int> have;
  for (const std::string& w : read) ++have[w];
  int found = 0;
  for (const std::string& w : truth)
    if (have[w] > 0) {
      --have[w];
      ++found;
    }
  return truth.empty() ? 0.0 : static_cast<double>(found) / static_cast<double>(truth.size());
}

std::string all_text(const OcrResult& r) {
  std::string t;
  for (const OcrBlock& b : r.blocks) t += b.text + "\n";
  return t;
}

/// A scan of `page` of `pdf` as a scanner or a phone gives it: drawn at `dpi`, turned by `degrees`, with
/// Gaussian sensor noise (sigma 6 grey levels) and saved as JPEG at quality 80, read back in grey.
cv::Mat scan(const fs::path& pdf, int page, int dpi, double degrees, const fs::path& dir) {
  const fs::path stem = dir / ("p" + std::to_string(page) + "_" + std::to_string(dpi));
  EXPECT_EQ(sh("pdftoppm -gray -r " + std::to_string(dpi) + " -f " + std::to_string(page) + " -l " + std::to_string(page) +
               " -singlefile -png '" + pdf.string() + "' '" + stem.string() + "'"),
            0);
  cv::Mat grey = cv::imread(stem.string() + ".png", cv::IMREAD_GRAYSCALE);
  if (grey.empty()) return grey;
  const cv::Mat turn = cv::getRotationMatrix2D(cv::Point2f(grey.cols / 2.0f, grey.rows / 2.0f), degrees, 1.0);
  cv::warpAffine(grey, grey, turn, grey.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(255));
  cv::Mat noise(grey.size(), CV_16SC1);
  cv::randn(noise, 0, 6);
  cv::Mat noisy;
  grey.convertTo(noisy, CV_16SC1);
  noisy += noise;
  noisy.convertTo(grey, CV_8UC1);
  std::vector<std::uint8_t> jpeg;
  cv::imencode(".jpg", grey, jpeg, {cv::IMWRITE_JPEG_QUALITY, 80});
  return cv::imdecode(jpeg, cv::IMREAD_GRAYSCALE);
}

std::string pdftotext(const fs::path& pdf, int page, const fs::path& dir) {
  const fs::path out = dir / "truth.txt";
  EXPECT_EQ(sh("pdftotext -f " + std::to_string(page) + " -l " + std::to_string(page) + " '" + pdf.string() + "' '" + out.string() + "'"), 0);
  std::ifstream f(out);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

struct ScanCase {
  int page;
  int dpi;
  double degrees;
};

class OcrScans : public ::testing::TestWithParam<ScanCase> {};

TEST_P(OcrScans, ReadsAScannedPageAsItsTextLayerSaysWithRecallOver90Percent) {
  if (!have("pdftoppm") || !have("pdftotext")) GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  const ScanCase c = GetParam();
  const fs::path dir = scratch("scan");
  const fs::path pdf = kData / "documents" / "shared-mime-info-spec.pdf";
  const cv::Mat grey = scan(pdf, c.page, c.dpi, c.degrees, dir);
  ASSERT_FALSE(grey.empty());
  EXPECT_TRUE(looks_like_text_page(grey)) << "a page of text is seen as one from its pixels";
  const OcrResult r = recognise_text(grey, "scan.jpg", {});
  const std::vector<std::string> truth = words_of(pdftotext(pdf, c.page, dir));
  ASSERT_GT(truth.size(), 100u);
  const double got = recall(truth, words_of(all_text(r)));
  EXPECT_GE(got, 0.9) << r.words.size() << " words kept of " << r.words_seen << "; text: " << all_text(r).substr(0, 600);
  EXPECT_GE(r.mean_confidence, 0.8);
  EXPECT_GE(r.blocks.size(), 3u) << "paragraphs, headings: more than one block";
  for (const OcrBlock& b : r.blocks) {
    EXPECT_GE(b.confidence, 0.6) << b.text;
    EXPECT_TRUE((cv::Rect2d(0, 0, grey.cols, grey.rows) & b.box_px) == b.box_px) << "inside the picture: " << b.text;
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Pages, OcrScans,
                         ::testing::Values(ScanCase{3, 150, 1.5}, ScanCase{3, 300, -1.5}, ScanCase{5, 150, -1.5}, ScanCase{5, 300, 1.5}),
                         [](const ::testing::TestParamInfo<ScanCase>& i) {
                           return "page" + std::to_string(i.param.page) + "_" + std::to_string(i.param.dpi) + "dpi_" +
                                  (i.param.degrees < 0 ? "ccw" : "cw");
                         });

TEST(Ocr, PhotographsAndSilhouettesAreNotPagesAndGiveNoText) {
  int pictures = 0;
  for (const auto& e : fs::directory_iterator(kData / "images")) {
    const std::string name = e.path().filename().string();
    if (name == "page.png" || (e.path().extension() != ".png" && e.path().extension() != ".jpg")) continue;
    const cv::Mat grey = cv::imread(e.path().string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(grey.empty()) << name;
    EXPECT_FALSE(looks_like_text_page(grey)) << name << " was taken for a page of text";
    ++pictures;
  }
  EXPECT_GE(pictures, 20);
}

TEST(Ocr, EvenWhenAskedAPhotographGivesNoGarbage) {
  // ocr = "always": Tesseract reads the picture anyway; the confidence and letter filters keep what it
  // makes of fur, fruit and fish out of the speech.
  for (const char* name : {"HappyFish.jpg", "fruits.jpg", "silhouette_3.png", "coins.png"}) {
    const cv::Mat grey = cv::imread((kData / "images" / name).string(), cv::IMREAD_GRAYSCALE);
    const OcrResult r = recognise_text(grey, name, {});
    EXPECT_TRUE(r.blocks.empty()) << name << ": " << all_text(r);
  }
}

TEST(Ocr, ThePageOfTextAmongTheTestPicturesIsRead) {
  const cv::Mat grey = cv::imread((kData / "images" / "page.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(grey.empty());
  EXPECT_TRUE(looks_like_text_page(grey));
  // A photo of a book page, 384 x 191 px under uneven light, its lines cut at the edges: what is whole is read.
  const OcrResult r = recognise_text(grey, "page.png", {});
  EXPECT_GE(r.words.size(), 15u) << all_text(r);
  const std::vector<std::string> words = words_of(all_text(r));
  for (const char* w : {"segmentation", "markers", "coins", "background"})
    EXPECT_NE(std::find(words.begin(), words.end(), w), words.end()) << w << " in: " << all_text(r);
}

TEST(Ocr, AMissingLanguageIsNamed) {
  OcrParams p;
  p.languages = "eng+xyz";
  EXPECT_NE(ocr_languages_problem(p).find("no 'xyz' (no xyz.traineddata in /usr/share/tesseract-ocr/5/tessdata)"), std::string::npos)
      << ocr_languages_problem(p);
  p.languages = "eng;rm -rf";
  EXPECT_NE(ocr_languages_problem(p).find("is not a '+'-joined list"), std::string::npos) << ocr_languages_problem(p);
  p.languages = "eng";
  EXPECT_EQ(ocr_languages_problem(p), "");
  p.languages = "xyz";
  const cv::Mat grey(100, 100, CV_8UC1, cv::Scalar(255));
  try {
    (void)recognise_text(grey, "blank.png", p);
    FAIL() << "a missing language was not refused";
  } catch (const OcrError& e) {
    EXPECT_EQ(e.kind(), OcrError::Kind::Unavailable);
    EXPECT_EQ(std::string(e.what()).rfind("ocr 'blank.png': Tesseract has no 'xyz'", 0), 0u) << e.what();
  }
}

TEST(Ocr, AWorkerThatCrashesHangsOrRunsOutOfMemoryCostsTheTextInOneLine) {
  const cv::Mat grey = cv::imread((kData / "images" / "page.png").string(), cv::IMREAD_GRAYSCALE);
  struct Case {
    OcrFault fault;
    OcrError::Kind kind;
    const char* says;
  };
  for (const Case c : {Case{OcrFault::Crash, OcrError::Kind::WorkerCrashed, "the text reader stopped (signal 11)"},
                       Case{OcrFault::Hang, OcrError::Kind::Timeout, "reading the text"}}) {
    OcrParams p;
    p.fault = c.fault;
    p.worker_cpu_s = 1;
    p.worker_wall_s = 2;
    try {
      (void)recognise_text(grey, "page.png", p);
      FAIL() << "the fault gave an answer";
    } catch (const OcrError& e) {
      EXPECT_EQ(e.kind(), c.kind) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.says), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
#if !defined(__SANITIZE_ADDRESS__)
  OcrParams p;
  p.fault = OcrFault::Memory;
  p.worker_max_memory_mb = 256;
  try {
    (void)recognise_text(grey, "page.png", p);
    FAIL() << "the memory hog gave an answer";
  } catch (const OcrError& e) {
    EXPECT_EQ(e.kind(), OcrError::Kind::TooLarge) << e.what();
    EXPECT_NE(std::string(e.what()).find("ran out of memory (limit 256 MiB)"), std::string::npos) << e.what();
  }
#endif
  // And the next picture is read as before.
  EXPECT_FALSE(recognise_text(grey, "page.png", {}).blocks.empty());
}

TEST(Ocr, BadArgumentsAreRefusedBeforeAnyWorkerStarts) {
  EXPECT_THROW((void)recognise_text(cv::Mat(), "x", {}), std::invalid_argument);
  EXPECT_THROW((void)recognise_text(cv::Mat(10, 10, CV_8UC3), "x", {}), std::invalid_argument);
  OcrParams p;
  p.max_pixels = 100;
  try {
    (void)recognise_text(cv::Mat(20, 20, CV_8UC1, cv::Scalar(255)), "big.png", p);
    FAIL();
  } catch (const OcrError& e) {
    EXPECT_EQ(e.kind(), OcrError::Kind::TooLarge);
    EXPECT_NE(std::string(e.what()).find("20 x 20 pixels is over the limit of 100"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hk::vision
