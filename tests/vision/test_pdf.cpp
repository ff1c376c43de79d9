// PDF pages through the poppler worker process (vision/pdf.hpp), through the public API only:
// the shipped documents probe and render within the budget and agree with poppler's own tools (pdfinfo,
// pdftotext) and with the PNG a page was made from; words land on their ink, also on a rotated page with an
// offset crop box; every bad file and every failing worker ends in its PdfError, and the next good render
// still works; group_text_blocks on synthetic words.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
// qpdf 11: the std::shared_ptr API only, without its transition warning.
#define POINTERHOLDER_TRANSITION 4
#include <qpdf/QPDF.hh>
#include <qpdf/QPDFWriter.hh>

#include "image_pdf.hpp"
#include "test_paths.hpp"

#include "vision/pdf.hpp"

namespace hk::vision {
namespace {

/// The default limits, with a minute for the worker instead of 5 s: these tests are about what a page gives,
/// not about time, and ctest runs them beside other suites on a loaded 2-core machine under ASan.
PdfLimits generous() {
  PdfLimits l;
  l.worker_wall_s = 60.0;
  l.worker_cpu_s = 60.0;
  return l;
}

const std::string kData = HK_TEST_DATA_DIR;
const std::string kHorse = kData + "/documents/horse_and_page.pdf";
const std::string kSpec = kData + "/documents/shared-mime-info-spec.pdf";
const std::string kRotated = kData + "/documents/rotated_text.pdf";
const std::string kTitled = kData + "/documents/titled.pdf";

std::vector<std::uint8_t> read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  EXPECT_TRUE(f.good()) << path;
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// stdout of a shell command; empty when the command fails or prints nothing.
std::string run(const std::string& cmd) {
  std::string out;
  const std::unique_ptr<FILE, int (*)(FILE*)> p(::popen(cmd.c_str(), "r"), ::pclose);
  if (!p) return out;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, p.get())) > 0) out.append(buf, n);
  return out;
}

bool have_tool(const std::string& tool) {
  return std::system(("command -v " + tool + " >/dev/null 2>&1").c_str()) == 0;
}

std::vector<std::string> split_words(const std::string& s) {
  std::istringstream in(s);
  return {std::istream_iterator<std::string>(in), std::istream_iterator<std::string>()};
}

/// The kind of PdfError `f` throws, or fails the test.
template <class F>
PdfError::Kind error_kind(F&& f, std::string* what = nullptr) {
  try {
    f();
  } catch (const PdfError& e) {
    if (what) *what = e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return e.kind();
  }
  ADD_FAILURE() << "no PdfError";
  return PdfError::Kind::NotPdf;
}

/// A good render after a failure: the failure left nothing behind that breaks the next worker.
void expect_good_render_still_works() {
  const auto bytes = read_file(kHorse);
  const PdfPage p = render_pdf_page(bytes, "horse_and_page.pdf", 2, generous());
  EXPECT_EQ(p.grey.type(), CV_8UC1);
  EXPECT_GT(p.grey.cols, 100);
  EXPECT_EQ(p.pages, 2);
}

/// Fraction of pixels darker than 128 in `box` (clipped to the image).
double ink(const cv::Mat& grey, const cv::Rect2d& box) {
  const cv::Rect r = cv::Rect(cv::Point(static_cast<int>(std::floor(box.x)), static_cast<int>(std::floor(box.y))),
                              cv::Point(static_cast<int>(std::ceil(box.x + box.width)),
                                        static_cast<int>(std::ceil(box.y + box.height)))) &
                     cv::Rect(0, 0, grey.cols, grey.rows);
  if (r.area() == 0) return 0.0;
  return static_cast<double>(cv::countNonZero(grey(r) < 128)) / r.area();
}

// ---------------------------------------------------------------------------------------------------

TEST(PdfDocuments, ShippedDocumentsProbeLikePdfinfoAndRenderEveryPageWithinTheBudget) {
  const PdfLimits limits = generous();
  for (const std::string& path : {kHorse, kSpec, kRotated}) {
    SCOPED_TRACE(path);
    const auto bytes = read_file(path);
    const PdfInfo info = probe_pdf(bytes, path, limits);
    EXPECT_FALSE(info.capped);
    EXPECT_EQ(info.pages, info.pages_in_file);
    EXPECT_GT(info.worker_max_rss_kb, 0);
    if (have_tool("pdfinfo")) {
      const auto w = split_words(run("pdfinfo '" + path + "' 2>/dev/null | grep '^Pages:'"));
      ASSERT_EQ(w.size(), 2u);
      EXPECT_EQ(info.pages, std::stoi(w[1]));
    }
    for (int page = 1; page <= info.pages; ++page) {
      SCOPED_TRACE(page);
      const PdfPage p = render_pdf_page(bytes, path, page, limits);
      ASSERT_EQ(p.grey.type(), CV_8UC1);
      EXPECT_LE(static_cast<double>(p.grey.cols) * p.grey.rows, limits.max_page_pixels);
      EXPECT_LE(p.dpi, limits.max_dpi);
      EXPECT_GT(p.dpi, 1.0);
      EXPECT_NEAR(p.grey.cols, p.width_pt * p.dpi / 72.0, 1.0);
      EXPECT_NEAR(p.grey.rows, p.height_pt * p.dpi / 72.0, 1.0);
      EXPECT_EQ(p.pages, info.pages);
      EXPECT_GT(p.worker_max_rss_kb, 0);
      // The page is on white and has something drawn on it.
      double lo = 0, hi = 0;
      cv::minMaxLoc(p.grey, &lo, &hi);
      EXPECT_EQ(hi, 255.0);
      EXPECT_LT(lo, 128.0);
    }
  }
}

TEST(PdfDocuments, TheTitleComesFromTheInfoDictionaryAsUtf8) {
  // titled.pdf's /Title is UTF-16BE with a byte-order mark (tests/data/make_pdfs.py); pdfinfo reads the same.
  const std::string want = "A ring, drawn for the hand \u2014 caf\u00e9 edition";
  const auto bytes = read_file(kTitled);
  EXPECT_EQ(probe_pdf(bytes, "titled.pdf", generous()).title, want);
  EXPECT_EQ(render_pdf_page(bytes, "titled.pdf", 1, generous()).title, want);
  if (have_tool("pdfinfo")) {
    EXPECT_EQ(run("pdfinfo '" + kTitled + "' 2>/dev/null | sed -n 's/^Title: *//p'"), want + "\n");
  }
  EXPECT_EQ(probe_pdf(read_file(kHorse), "horse_and_page.pdf", generous()).title, "") << "no /Title";
  // A /Title of 2000 bytes is dropped, the document is not.
  const PdfInfo long_title =
      probe_pdf(read_file(kData + "/bad/title_2000_bytes.pdf"), "title_2000_bytes.pdf", generous());
  EXPECT_EQ(long_title.title, "");
  EXPECT_EQ(long_title.pages, 1);
}

/// `pdf` with its catalog's /Lang set to `lang` (a string), or to the name /fr when `as_name`, written by qpdf.
std::vector<std::uint8_t> with_lang(const std::vector<std::uint8_t>& pdf, const std::string& lang,
                                    bool as_name = false) {
  QPDF q;
  q.processMemoryFile("in", reinterpret_cast<const char*>(pdf.data()), pdf.size());
  q.getRoot().replaceKey("/Lang",
                         as_name ? QPDFObjectHandle::newName("/fr") : QPDFObjectHandle::newUnicodeString(lang));
  QPDFWriter w(q);
  w.setOutputMemory();
  w.write();
  std::shared_ptr<Buffer> b = w.getBufferSharedPointer();
  return {b->getBuffer(), b->getBuffer() + b->getSize()};
}

TEST(PdfDocuments, TheLanguageComesFromTheCatalogsLang) {
  const auto bytes = read_file(kTitled);
  EXPECT_EQ(probe_pdf(bytes, "titled.pdf", generous()).language, "") << "no /Lang";
  const auto fr = with_lang(bytes, "fr-FR");
  EXPECT_EQ(probe_pdf(fr, "fr.pdf", generous()).language, "fr-FR");
  EXPECT_EQ(render_pdf_page(fr, "fr.pdf", 1, generous()).language, "fr-FR");
  EXPECT_EQ(probe_pdf(with_lang(bytes, "DE_ch"), "de.pdf", generous()).language, "de-ch") << "made a tag";
  EXPECT_EQ(probe_pdf(with_lang(bytes, "not a language"), "x.pdf", generous()).language, "");
  EXPECT_EQ(probe_pdf(with_lang(bytes, "", true), "name.pdf", generous()).language, "") << "a name, not a string";
  EXPECT_EQ(pdf_language_tag("es"), "es");
  EXPECT_EQ(pdf_language_tag(std::string(40, 'a')), "");
}

TEST(PdfDocuments, HorsePageAtThePngResolutionMatchesThePng) {
  const cv::Mat png = cv::imread(kData + "/images/horse.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(png.empty());
  const auto bytes = read_file(kHorse);
  // The page's width in pt and the PNG's width in px give the DPI at which the page is the PNG again.
  PdfLimits probe_limits = generous();
  const PdfPage first = render_pdf_page(bytes, "horse", 1, probe_limits);
  PdfLimits limits = generous();
  limits.max_dpi = 72.0 * png.cols / first.width_pt;
  limits.max_page_pixels = 4.0 * png.cols * png.rows;
  const PdfPage p = render_pdf_page(bytes, "horse", 1, limits);
  EXPECT_DOUBLE_EQ(p.dpi, limits.max_dpi);
  ASSERT_EQ(p.grey.size(), png.size());
  cv::Mat diff;
  cv::absdiff(p.grey, png, diff);
  EXPECT_LT(cv::mean(diff)[0], 2.0);  // the same picture, resampled by poppler at scale 1
}

TEST(PdfDocuments, APageWithATextLayerIsDrawnAtTheScreenSideWithTheSameWordsInItsFrame) {
  const auto bytes = read_file(kSpec);
  const PdfPage full = render_pdf_page(bytes, "spec", 3, generous());
  PdfLimits screen = generous();
  screen.text_layer_max_side_px = 1000;
  const PdfPage small = render_pdf_page(bytes, "spec", 3, screen);
  ASSERT_GT(full.words.size(), 50u);
  EXPECT_FALSE(full.screen_sized);
  EXPECT_TRUE(small.screen_sized);
  // The highest DPI whose long side stays within 1000 whole pixels.
  const double side_pt = std::max(full.width_pt, full.height_pt);
  EXPECT_NEAR(small.dpi, 72.0 * 1000.0 / side_pt, 0.01);
  EXPECT_LE(std::max(small.grey.cols, small.grey.rows), 1000);
  EXPECT_GE(std::max(small.grey.cols, small.grey.rows), 999);
  EXPECT_LT(small.dpi, full.dpi);
  // The same words, their boxes the full drawing's scaled by the ratio of the DPIs.
  ASSERT_EQ(small.words.size(), full.words.size());
  const double k = small.dpi / full.dpi;
  for (std::size_t i = 0; i < full.words.size(); ++i) {
    SCOPED_TRACE(full.words[i].text);
    EXPECT_EQ(small.words[i].text, full.words[i].text);
    EXPECT_NEAR(small.words[i].box_px.x, k * full.words[i].box_px.x, 0.5);
    EXPECT_NEAR(small.words[i].box_px.y, k * full.words[i].box_px.y, 0.5);
    EXPECT_NEAR(small.words[i].box_px.width, k * full.words[i].box_px.width, 1.0);
    EXPECT_NEAR(small.words[i].box_px.height, k * full.words[i].box_px.height, 1.0);
  }
  ASSERT_EQ(small.blocks.size(), full.blocks.size());
  for (std::size_t i = 0; i < full.blocks.size(); ++i) EXPECT_EQ(small.blocks[i].text, full.blocks[i].text);

  // A side the budget already keeps to draws the page as the budget does.
  screen.text_layer_max_side_px = 1e5;
  const PdfPage roomy = render_pdf_page(bytes, "spec", 3, screen);
  EXPECT_FALSE(roomy.screen_sized);
  EXPECT_EQ(roomy.dpi, full.dpi);
  EXPECT_EQ(roomy.grey.size(), full.grey.size());
}

TEST(PdfDocuments, APageWithoutATextLayerIsDrawnAtTheFullBudgetForOcr) {
  const cv::Mat horse = cv::imread(kData + "/images/horse.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(horse.empty());
  std::vector<std::uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", horse, jpeg));
  const std::string pdf = test::image_only_pdf(jpeg, horse.cols, horse.rows, 72.0);
  const std::vector<std::uint8_t> bytes(pdf.begin(), pdf.end());
  PdfLimits screen = generous();
  screen.text_layer_max_side_px = 100;
  const PdfPage p = render_pdf_page(bytes, "scan.pdf", 1, screen);
  const PdfPage full = render_pdf_page(bytes, "scan.pdf", 1, generous());
  EXPECT_TRUE(p.words.empty());
  EXPECT_FALSE(p.screen_sized);
  EXPECT_EQ(p.dpi, full.dpi);
  EXPECT_EQ(p.grey.size(), full.grey.size());
  EXPECT_GT(std::max(p.grey.cols, p.grey.rows), 1000)
      << "the full budget, not the side asked for pages with a text layer";

  // The same scan with a one-line text layer is drawn at the side: the layer is what decides.
  const std::string captioned = test::image_only_pdf(jpeg, horse.cols, horse.rows, 72.0, "Scanned at the library");
  const PdfPage c =
      render_pdf_page(std::vector<std::uint8_t>(captioned.begin(), captioned.end()), "captioned.pdf", 1, screen);
  EXPECT_EQ(c.words.size(), 4u);
  EXPECT_TRUE(c.screen_sized);
  EXPECT_LE(std::max(c.grey.cols, c.grey.rows), 100);
}

TEST(PdfText, ParagraphPageBlocksGiveThePdftotextWords) {
  if (!have_tool("pdftotext")) GTEST_SKIP() << "pdftotext not installed";
  const auto bytes = read_file(kSpec);
  for (const int page : {3, 5}) {
    SCOPED_TRACE(page);
    const PdfPage p = render_pdf_page(bytes, "spec", page, generous());
    ASSERT_GT(p.words.size(), 100u);
    ASSERT_GT(p.blocks.size(), 2u);
    std::vector<std::string> ours;
    for (const TextBlock& b : p.blocks) {
      for (const std::string& w : split_words(b.text)) ours.push_back(w);
    }
    const std::vector<std::string> theirs = split_words(
        run("pdftotext -f " + std::to_string(page) + " -l " + std::to_string(page) + " '" + kSpec + "' - 2>/dev/null"));
    EXPECT_EQ(ours, theirs);
    // Every word's box holds ink, and the ink of the page is on words (this page has no pictures or rules).
    cv::Mat covered(p.grey.size(), CV_8UC1, cv::Scalar(0));
    for (const PdfWord& w : p.words) {
      EXPECT_GT(ink(p.grey, w.box_px), 0.02) << w.text;
      cv::rectangle(covered, cv::Rect(w.box_px) + cv::Size(2, 2) - cv::Point(1, 1), cv::Scalar(255), cv::FILLED);
    }
    const cv::Mat dark = p.grey < 128;
    const double on_words = cv::countNonZero(dark & covered), all = cv::countNonZero(dark);
    EXPECT_GT(on_words / all, 0.97);
  }
}

TEST(PdfText, RotatedPageWithCropBoxWordsLieOnTheirInk) {
  // 400 x 300 pt media box, crop box [50 20 400 300], /Rotate 90: shown 280 x 350 pt, three words.
  const auto bytes = read_file(kRotated);
  const PdfPage p = render_pdf_page(bytes, "rotated", 1, generous());
  EXPECT_DOUBLE_EQ(p.width_pt, 280.0);
  EXPECT_DOUBLE_EQ(p.height_pt, 350.0);
  EXPECT_GT(p.grey.rows, p.grey.cols);
  ASSERT_EQ(p.words.size(), 3u);
  cv::Mat covered(p.grey.size(), CV_8UC1, cv::Scalar(0));
  for (const PdfWord& w : p.words) {
    EXPECT_GT(ink(p.grey, w.box_px), 0.05) << w.text;
    // Rotated text: the box is taller than wide.
    EXPECT_GT(w.box_px.height, w.box_px.width) << w.text;
    cv::rectangle(covered, cv::Rect(w.box_px) + cv::Size(4, 4) - cv::Point(2, 2), cv::Scalar(255), cv::FILLED);
  }
  // The ink is inside the word boxes. Not all of it: poppler measures the boxes with Helvetica's metrics but
  // draws with the substitute font fontconfig finds (DejaVu Sans here, wider), so glyph edges spill over.
  const cv::Mat dark = p.grey < 128;
  EXPECT_GT(static_cast<double>(cv::countNonZero(dark & covered)) / cv::countNonZero(dark), 0.97);
  // Rotated 90 degrees clockwise: "Top" (top left of the unrotated page) is now at the top right.
  const auto top = std::find_if(p.words.begin(), p.words.end(), [](const PdfWord& w) { return w.text == "Top"; });
  ASSERT_NE(top, p.words.end());
  EXPECT_GT(top->box_px.x, 0.6 * p.grey.cols);
  EXPECT_LT(top->box_px.y, 0.4 * p.grey.rows);
}

// ---------------------------------------------------------------------------------------------------

TEST(PdfBadFiles, EmptyAndTextFilesAreNotPdf) {
  for (const std::string f : {"empty.pdf", "text_named.pdf"}) {
    const auto bytes = read_file(kData + "/bad/" + f);
    std::string what;
    EXPECT_EQ(error_kind([&] { probe_pdf(bytes, f, generous()); }, &what), PdfError::Kind::NotPdf);
    EXPECT_EQ(what.rfind("pdf '" + f + "': ", 0), 0u) << what;
    EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, f, 1, generous()); }), PdfError::Kind::NotPdf);
  }
  expect_good_render_still_works();
}

TEST(PdfBadFiles, TruncatedIsDamaged) {
  // The first half of the spec: no cross-reference table, no trailer. poppler 22.12 tries to reconstruct the
  // table, finds no catalog in the objects it has, and load_from_raw_data fails (pdfinfo: "Couldn't read
  // xref table"), so nothing of it renders.
  const auto bytes = read_file(kData + "/bad/truncated.pdf");
  std::string what;
  EXPECT_EQ(error_kind([&] { probe_pdf(bytes, "truncated.pdf", generous()); }, &what), PdfError::Kind::Damaged);
  EXPECT_EQ(what, "pdf 'truncated.pdf': poppler cannot read it (damaged or not a PDF)");
  EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, "truncated.pdf", 1, generous()); }), PdfError::Kind::Damaged);
  expect_good_render_still_works();
}

TEST(PdfBadFiles, LockedIsRefusedBeforeAnyPage) {
  const auto bytes = read_file(kData + "/bad/locked.pdf");
  std::string what;
  EXPECT_EQ(error_kind([&] { probe_pdf(bytes, "locked.pdf", generous()); }, &what), PdfError::Kind::Locked);
  EXPECT_EQ(what, "pdf 'locked.pdf': protected by a password");
  EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, "locked.pdf", 1, generous()); }), PdfError::Kind::Locked);
  expect_good_render_still_works();
}

TEST(PdfBadFiles, FiveThousandPagesAreCappedNotRefused) {
  const auto bytes = read_file(kData + "/bad/pages_5000.pdf");
  const PdfLimits limits = generous();  // max_pages 1000
  const PdfInfo info = probe_pdf(bytes, "pages_5000.pdf", limits);
  EXPECT_EQ(info.pages_in_file, 5000);
  EXPECT_EQ(info.pages, 1000);
  EXPECT_TRUE(info.capped);
  const PdfPage last = render_pdf_page(bytes, "pages_5000.pdf", 1000, limits);
  EXPECT_EQ(last.pages, 1000);
  ASSERT_EQ(last.words.size(), 1u);
  EXPECT_EQ(last.words[0].text, "Page");
  std::string what;
  EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, "pages_5000.pdf", 1001, limits); }, &what),
            PdfError::Kind::NoSuchPage);
  EXPECT_NE(what.find("first 1000 pages"), std::string::npos) << what;
  expect_good_render_still_works();
}

TEST(PdfBadFiles, LargestPdfPageRendersWithinTheBudgetAtLowDpi) {
  const auto bytes = read_file(kData + "/bad/page_14400pt.pdf");
  const PdfLimits limits = generous();
  const PdfPage p = render_pdf_page(bytes, "page_14400pt.pdf", 1, limits);
  EXPECT_EQ(p.width_pt, 14400.0);
  EXPECT_LE(static_cast<double>(p.grey.cols) * p.grey.rows, limits.max_page_pixels);
  EXPECT_NEAR(p.dpi, 10.0, 0.05);  // 72 * sqrt(4e6) / 14400
  // The ring (radius 5000 pt, 500 pt thick) is drawn: dark on its radius, white in the middle.
  const double k = p.dpi / 72.0;
  const cv::Point2d c(7200 * k, 7200 * k);
  EXPECT_LT(p.grey.at<std::uint8_t>(cv::Point(c + cv::Point2d(5000 * k, 0))), 64);
  EXPECT_EQ(p.grey.at<std::uint8_t>(cv::Point(c)), 255);

  PdfLimits tight = generous();
  tight.max_page_pixels = 10000;  // would need 0.5 dpi
  std::string what;
  EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, "page_14400pt.pdf", 1, tight); }, &what), PdfError::Kind::TooLarge);
  EXPECT_NE(what.find("14400 x 14400 pt"), std::string::npos) << what;
  EXPECT_NE(what.find("10000 pixels"), std::string::npos) << what;
  expect_good_render_still_works();
}

TEST(PdfBadFiles, PagesOutsideTheDocumentAreNoSuchPage) {
  const auto bytes = read_file(kHorse);
  EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, "horse", 0, generous()); }), PdfError::Kind::NoSuchPage);
  EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, "horse", -1, generous()); }), PdfError::Kind::NoSuchPage);
  std::string what;
  EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, "horse", 3, generous()); }, &what), PdfError::Kind::NoSuchPage);
  EXPECT_EQ(what, "pdf 'horse': page 3 does not exist (the document has 2 pages)");
  expect_good_render_still_works();
}

TEST(PdfBadFiles, FileOverTheSizeLimitIsTooLarge) {
  const auto bytes = read_file(kHorse);
  PdfLimits limits = generous();
  limits.max_file_bytes = 1000;
  EXPECT_EQ(error_kind([&] { probe_pdf(bytes, "horse", limits); }), PdfError::Kind::TooLarge);
}

TEST(PdfBadFiles, NamesArePrintedOnOneLine) {
  const auto bytes = read_file(kData + "/bad/text_named.pdf");
  std::string what;
  EXPECT_EQ(error_kind([&] { probe_pdf(bytes, "evil\nname\x1b[2J.pdf", generous()); }, &what), PdfError::Kind::NotPdf);
  EXPECT_EQ(what.rfind("pdf 'evil\\x0Aname\\x1B[2J.pdf': ", 0), 0u) << what;
}

TEST(PdfBadFiles, HeaderAfterJunkIsAcceptedButNotAfterTooMuch) {
  std::vector<std::uint8_t> b(1024, 'x');
  const std::string h = "%PDF-1.4";
  b.insert(b.end(), h.begin(), h.end());
  EXPECT_TRUE(looks_like_pdf(b));
  b.insert(b.begin(), 'x');
  EXPECT_FALSE(looks_like_pdf(b));
  EXPECT_FALSE(looks_like_pdf({}));
}

// ---------------------------------------------------------------------------------------------------

TEST(PdfWorker, CrashedWorkerIsWorkerCrashedNotTheCaller) {
  const auto bytes = read_file(kHorse);
  PdfLimits limits = generous();
  limits.fault = PdfFault::Crash;
  std::string what;
  EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, "x.pdf", 2, limits); }, &what), PdfError::Kind::WorkerCrashed);
  EXPECT_EQ(what, "pdf 'x.pdf': the reader stopped on page 2 (signal 11)");
  EXPECT_EQ(error_kind([&] { probe_pdf(bytes, "x.pdf", limits); }, &what), PdfError::Kind::WorkerCrashed);
  EXPECT_EQ(what, "pdf 'x.pdf': the reader stopped while opening the document (signal 11)");
  expect_good_render_still_works();
}

TEST(PdfWorker, HangingWorkerIsKilledAtTheWallClockLimit) {
  const auto bytes = read_file(kHorse);
  PdfLimits limits = generous();
  limits.fault = PdfFault::Hang;
  limits.worker_wall_s = 0.5;
  std::string what;
  EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, "x.pdf", 1, limits); }, &what), PdfError::Kind::Timeout);
  EXPECT_EQ(what, "pdf 'x.pdf': page 1 took longer than 0.5 s to draw");
  EXPECT_EQ(error_kind([&] { probe_pdf(bytes, "x.pdf", limits); }), PdfError::Kind::Timeout);
  expect_good_render_still_works();
}

TEST(PdfWorker, SpinningWorkerIsStoppedByItsCpuLimit) {
  const auto bytes = read_file(kHorse);
  PdfLimits limits = generous();
  limits.fault = PdfFault::Hang;
  limits.worker_cpu_s = 0.2;  // rounded up to 1 s
  limits.worker_wall_s = 60;  // not reached
  std::string what;
  EXPECT_EQ(error_kind([&] { render_pdf_page(bytes, "x.pdf", 1, limits); }, &what), PdfError::Kind::Timeout);
  EXPECT_EQ(what, "pdf 'x.pdf': page 1 used more than 1 s of processor time");
  expect_good_render_still_works();
}

// The memory limit (RLIMIT_AS, which AddressSanitizer builds do not set): tests/worker_limits.

// ---------------------------------------------------------------------------------------------------
// group_text_blocks on synthetic words: 10 px wide characters, given line height.

/// Words of `text` laid out from (x, y) with letters `h` * 0.5 wide and spaces `h` * 0.3 wide.
std::vector<PdfWord> line_of(const std::string& text, double x, double y, double h) {
  std::vector<PdfWord> out;
  for (const std::string& w : split_words(text)) {
    const double width = 0.5 * h * static_cast<double>(w.size());
    out.push_back(PdfWord{w, cv::Rect2d(x, y, width, h)});
    x += width + 0.3 * h;
  }
  return out;
}

void append(std::vector<PdfWord>& to, const std::vector<PdfWord>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

TEST(PdfTextBlocks, ParagraphsSeparatedByAGapAreTwoBlocks) {
  std::vector<PdfWord> words;
  append(words, line_of("the first paragraph", 100, 100, 20));
  append(words, line_of("goes on here", 100, 124, 20));
  append(words, line_of("and ends", 100, 148, 20));
  append(words, line_of("a second one", 100, 200, 20));  // gap 32 px > one line height
  append(words, line_of("follows", 100, 224, 20));
  const auto blocks = group_text_blocks(words);
  ASSERT_EQ(blocks.size(), 2u);
  EXPECT_EQ(blocks[0].text, "the first paragraph goes on here and ends");
  EXPECT_EQ(blocks[0].lines, 3);
  EXPECT_EQ(blocks[1].text, "a second one follows");
  EXPECT_EQ(blocks[1].lines, 2);
  EXPECT_DOUBLE_EQ(blocks[0].box_px.y, 100.0);
  EXPECT_DOUBLE_EQ(blocks[0].box_px.height, 68.0);
  EXPECT_DOUBLE_EQ(blocks[0].box_px.x, 100.0);
}

TEST(PdfTextBlocks, TwoColumnsAreNotMerged) {
  std::vector<PdfWord> words;
  for (int i = 0; i < 3; ++i) {
    append(words, line_of("left column line", 50, 100 + 24 * i, 20));
    append(words, line_of("right column line", 400, 100 + 24 * i, 20));  // gutter 190 px > 1.5 x 20
  }
  const auto blocks = group_text_blocks(words);
  ASSERT_EQ(blocks.size(), 2u);
  EXPECT_EQ(blocks[0].text, "left column line left column line left column line");
  EXPECT_EQ(blocks[1].text, "right column line right column line right column line");
  EXPECT_EQ(blocks[0].lines, 3);
  EXPECT_EQ(blocks[1].lines, 3);
}

TEST(PdfTextBlocks, LargerHeadingAboveAParagraphIsItsOwnBlock) {
  std::vector<PdfWord> words;
  append(words, line_of("A Heading", 100, 100, 36));
  append(words, line_of("body text starts", 100, 140, 18));  // gap 4 px, but 36 / 18 = 2 >= 1.5
  append(words, line_of("right below it", 100, 162, 18));
  const auto blocks = group_text_blocks(words);
  ASSERT_EQ(blocks.size(), 2u);
  EXPECT_EQ(blocks[0].text, "A Heading");
  EXPECT_EQ(blocks[1].text, "body text starts right below it");
}

TEST(PdfTextBlocks, NoSpaceAfterAWordJoinsItToTheNextOnTheLineOnly) {
  std::vector<PdfWord> words = line_of("see globs2 , magic", 100, 100, 20);
  append(words, line_of("and more", 100, 124, 20));
  words[1].space_after = false;  // "globs2" "," touching
  words[2].box_px.x = words[1].box_px.br().x;
  words[3].space_after = false;  // the line's last word: lines are still joined with a space
  words[4].space_after = false;  // flagged, but 6 px (0.3 line heights) away: still a space
  const auto blocks = group_text_blocks(words);
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_EQ(blocks[0].text, "see globs2, magic and more");
}

TEST(PdfTextBlocks, WordsOutOfOrderComeOutInReadingOrder) {
  std::vector<PdfWord> words;
  append(words, line_of("one two three four", 100, 100, 20));
  append(words, line_of("five six seven", 100, 123, 20));
  append(words, line_of("eight nine", 100, 146, 20));
  words[5].box_px.y += 2;  // a little baseline jitter
  std::mt19937 rng(7);
  std::shuffle(words.begin(), words.end(), rng);
  const auto blocks = group_text_blocks(words);
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_EQ(blocks[0].text, "one two three four five six seven eight nine");
  EXPECT_EQ(blocks[0].lines, 3);
  EXPECT_TRUE(group_text_blocks({}).empty());
}

}  // namespace
}  // namespace hk::vision
