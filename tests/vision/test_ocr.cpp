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
#include <iterator>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "hk/error.hpp"
#include "image_pdf.hpp"
#include "scans.hpp"
#include "test_paths.hpp"
#include "vision/ocr.hpp"

namespace fs = std::filesystem;

namespace hk::vision {
namespace {

const fs::path kData = HK_TEST_DATA_DIR;

using test::have_poppler_utils;
using test::words_of;

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hk_ocr_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string all_text(const OcrResult& r) {
  std::string t;
  for (const OcrBlock& b : r.blocks) t += b.text + "\n";
  return t;
}

struct ScanCase {
  int page;
  int dpi;
  double degrees;
};

class OcrScans : public ::testing::TestWithParam<ScanCase> {};

TEST_P(OcrScans, ReadsAScannedPageAsItsTextLayerSaysWithRecallOver90Percent) {
  if (!have_poppler_utils()) GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  const ScanCase c = GetParam();
  const fs::path dir = scratch("scan");
  const fs::path pdf = kData / "documents" / "shared-mime-info-spec.pdf";
  const cv::Mat grey = cv::imdecode(test::scan_jpeg(pdf, c.page, c.dpi, c.degrees, dir), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(grey.empty());
  EXPECT_TRUE(looks_like_text_page(grey)) << "a page of text is seen as one from its pixels";
  OcrParams p;
  std::vector<std::string> handed;  // each block as the worker sent it, before the page was done
  p.on_block = [&handed](const OcrBlock& b) { handed.push_back(b.text); };
  const OcrResult r = recognise_text(grey, "scan.jpg", p);
  std::vector<std::string> blocks;
  for (const OcrBlock& b : r.blocks) blocks.push_back(b.text);
  EXPECT_EQ(handed, blocks) << "every block handed on as read, in reading order, and only those";
  const std::vector<std::string> truth = words_of(test::pdftotext_page(pdf, c.page, dir));
  ASSERT_GT(truth.size(), 100u);
  const double got = test::word_recall(truth, words_of(all_text(r)));
  EXPECT_GE(got, 0.9) << r.words.size() << " words kept of " << r.words_seen
                      << "; text: " << all_text(r).substr(0, 600);
  EXPECT_GE(r.mean_confidence, 0.8);
  EXPECT_GE(r.blocks.size(), 3u) << "paragraphs, headings: more than one block";
  for (const OcrBlock& b : r.blocks) {
    EXPECT_GE(b.confidence, 0.6) << b.text;
    EXPECT_TRUE((cv::Rect2d(0, 0, grey.cols, grey.rows) & b.box_px) == b.box_px) << "inside the picture: " << b.text;
  }
  fs::remove_all(dir);
}

/// The words of 3 or more letters or digits among `words`: what recall is counted on against the tesseract command.
std::vector<std::string> long_words(const std::vector<std::string>& words) {
  std::vector<std::string> out;
  for (const std::string& w : words)
    if (w.size() >= 3) out.push_back(w);
  return out;
}

TEST_P(OcrScans, EveryWordTesseractReadsReachesTheVisitor) {
  // The kiosk's blocks (what is said) against the `tesseract` command on the same JPEG: no filter of the kiosk's
  // may cut real text (a word read with low confidence is said; an unclear-word mark counts as no word).
  if (!have_poppler_utils()) GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  if (test::shell("command -v tesseract >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "the tesseract command is not installed (scripts/install-deps.sh installs tesseract-ocr)";
  const ScanCase c = GetParam();
  const fs::path dir = scratch("cli");
  const fs::path pdf = kData / "documents" / "shared-mime-info-spec.pdf";
  const std::vector<std::uint8_t> jpeg = test::scan_jpeg(pdf, c.page, c.dpi, c.degrees, dir);
  std::ofstream(dir / "scan.jpg", std::ios::binary)
      .write(reinterpret_cast<const char*>(jpeg.data()), static_cast<std::streamsize>(jpeg.size()));
  ASSERT_EQ(
      test::shell("tesseract '" + (dir / "scan.jpg").string() + "' '" + (dir / "cli").string() + "' >/dev/null 2>&1"),
      0);
  std::ifstream cli_file(dir / "cli.txt");
  const std::string cli_text((std::istreambuf_iterator<char>(cli_file)), std::istreambuf_iterator<char>());
  const std::vector<std::string> truth = long_words(words_of(test::pdftotext_page(pdf, c.page, dir)));
  const OcrResult r = recognise_text(cv::imdecode(jpeg, cv::IMREAD_GRAYSCALE), "scan.jpg", {});
  const double kiosk = test::word_recall(truth, long_words(words_of(all_text(r))));
  const double command = test::word_recall(truth, long_words(words_of(cli_text)));
  EXPECT_GE(kiosk, command - 0.02) << "kiosk " << kiosk << ", tesseract " << command;
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Pages, OcrScans,
                         ::testing::Values(ScanCase{3, 150, 1.5}, ScanCase{3, 300, -1.5}, ScanCase{5, 150, -1.5},
                                           ScanCase{5, 300, 1.5}),
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

TEST(Ocr, TheWordsOfAStreetSignInAPhotographAreRead) {
  // White capitals on a green sign over a photograph of fruit: no page layout, light on dark.
  cv::Mat photo = cv::imread((kData / "images" / "fruits.jpg").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(photo.empty());
  cv::resize(photo, photo, cv::Size(1200, 800));
  cv::rectangle(photo, cv::Rect(150, 200, 900, 400), cv::Scalar(30, 90, 20), cv::FILLED);
  cv::putText(photo, "MAIN STREET", {200, 350}, cv::FONT_HERSHEY_DUPLEX, 3.2, cv::Scalar(255, 255, 255), 8,
              cv::LINE_AA);
  cv::putText(photo, "CITY MUSEUM", {200, 520}, cv::FONT_HERSHEY_DUPLEX, 3.2, cv::Scalar(255, 255, 255), 8,
              cv::LINE_AA);
  cv::Mat grey;
  cv::cvtColor(photo, grey, cv::COLOR_BGR2GRAY);
  EXPECT_TRUE(looks_like_text_page(grey)) << "a sign's line of large letters is text worth reading";
  const OcrResult r = recognise_text(grey, "sign.jpg", {});
  EXPECT_EQ(words_of(all_text(r)), (std::vector<std::string>{"main", "street", "city", "museum"})) << all_text(r);
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
  EXPECT_NE(ocr_languages_problem(p).find("no 'xyz' (no xyz.traineddata in /usr/share/tesseract-ocr/5/tessdata)"),
            std::string::npos)
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

TEST(Ocr, AWorkerThatCrashesOrHangsCostsTheTextInOneLine) {
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
  // Running out of memory (RLIMIT_AS, which AddressSanitizer builds do not set): tests/worker_limits.
  // And the next picture is read as before.
  EXPECT_FALSE(recognise_text(grey, "page.png", {}).blocks.empty());
}

TEST(Ocr, BadArgumentsAreRefusedBeforeAnyWorkerStarts) {
  EXPECT_THROW((void)recognise_text(cv::Mat(), "x", {}), hk::ArgumentError);
  EXPECT_THROW((void)recognise_text(cv::Mat(10, 10, CV_8UC3), "x", {}), hk::ArgumentError);
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

/// A one-page PDF (A4) of `lines` in Helvetica 13 pt, each a line of UTF-8 text within Latin-1 (written in the PDF's
/// WinAnsi encoding), its cross-reference table computed: a printed page in another language, made in the test.
std::string pdf_of_lines(const std::vector<std::string>& lines) {
  std::string content = "BT /F1 13 Tf 16 TL 60 780 Td\n";
  for (const std::string& line : lines) {
    content += "(";
    for (std::size_t i = 0; i < line.size(); ++i) {
      const auto c = static_cast<unsigned char>(line[i]);
      if (c == 0xC3 && i + 1 < line.size()) {  // a two-byte UTF-8 letter of Latin-1: é, à, ç, ...
        char octal[8];
        std::snprintf(octal, sizeof octal, "\\%03o", 0x40 + static_cast<unsigned char>(line[++i]));
        content += octal;
      } else if (c == '(' || c == ')' || c == '\\') {
        content += '\\';
        content += static_cast<char>(c);
      } else {
        content += static_cast<char>(c);
      }
    }
    content += ") Tj T*\n";
  }
  content += "ET\n";
  const std::vector<std::string> objects = {
      "<< /Type /Catalog /Pages 2 0 R >>", "<< /Type /Pages /Kids [3 0 R] /Count 1 >>",
      "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 595 842] /Resources << /Font << /F1 4 0 R >> >> /Contents 5 0 R >>",
      "<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica /Encoding /WinAnsiEncoding >>",
      "<< /Length " + std::to_string(content.size()) + " >>\nstream\n" + content + "endstream"};
  return test::pdf_of_objects(objects);
}

TEST(Ocr, AFrenchScanIsReadWithTheFrenchDataAndSaysItIsFrench) {
  if (!have_poppler_utils()) GTEST_SKIP() << "poppler-utils is not installed (scripts/install-deps.sh installs it)";
  OcrParams p;
  p.languages = "fra+eng";  // what a French visitor's kiosk reads with
  if (!ocr_languages_problem(p).empty()) GTEST_SKIP() << ocr_languages_problem(p);
  const std::vector<std::string> lines = {
      "Le musée est ouvert tous les jours de neuf heures à dix-sept heures.",
      "Les visiteurs aveugles ou malvoyants peuvent toucher les sculptures de la salle trois.",
      "Une borne tactile leur permet de sentir les contours de chaque tableau.",
      "Les enfants sont les bienvenus ; les chiens guides aussi.",
      "Pour toute question, adressez-vous à l'accueil, près de l'entrée principale.",
      "Nous vous souhaitons une très agréable visite dans nos galeries.",
  };
  const fs::path dir = scratch("french");
  std::ofstream(dir / "page.pdf", std::ios::binary) << pdf_of_lines(lines);
  const std::vector<std::uint8_t> jpeg = test::scan_jpeg(dir / "page.pdf", 1, 150, 1.0, dir);
  const cv::Mat grey = cv::imdecode(jpeg, cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(grey.empty());
  const OcrResult r = recognise_text(grey, "french.jpg", p);
  std::string truth;
  for (const std::string& l : lines) truth += l + "\n";
  const double got = test::word_recall(words_of(truth), words_of(all_text(r)));
  EXPECT_GE(got, 0.9) << all_text(r);
  EXPECT_NE(all_text(r).find("musée"), std::string::npos) << "its accents read: " << all_text(r);
  ASSERT_FALSE(r.blocks.empty());
  // Most of the page is read by the French model (a plain word such as "sont" may be read by the English one, so
  // a short block may say "eng"; the kiosk takes the page's language from its letters, most first).
  std::map<std::string, std::size_t> letters;
  for (const OcrBlock& b : r.blocks) letters[b.language] += b.text.size();
  EXPECT_GT(letters["fra"], letters["eng"]) << all_text(r);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hk::vision
