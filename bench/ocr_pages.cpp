// Reading text from pictures: for scans of pages of the shipped PDF (made as a scanner or phone makes them,
// tests/support/scans.hpp: 150 and 300 dpi, turned ±1.5°, noise, JPEG 80) and for every test picture, the
// OCR worker's time and peak memory, the word recall against pdftotext of the same page, and the text
// blocks found where there is no text (false blocks); then, as the kiosk shows a page (TextTiming::later, the
// text read by ImageScene::with_text as the TextReader does), when it is felt, when its first block of text is
// read (TextRun::on_block: what a visitor's reading starts with), when its whole text is available, and
// the curves felt inside the text blocks before and after; and a camera capture (the page photographed in a
// 3264 x 2448 frame, found and rectified at that resolution) read the same way. Markdown tables on stdout.
//
// Usage: bench_ocr_pages [--pages 3,5]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "pictures/image_scene.hpp"
#include "scans.hpp"
#include "synthetic_photo.hpp"
#include "test_paths.hpp"
#include "vision/page.hpp"

namespace fs = std::filesystem;

namespace {

/// The pictures of tests/data/images (.png and .jpg), sorted by path.
std::vector<fs::path> test_images() {
  std::vector<fs::path> v;
  for (const auto& e : fs::directory_iterator(fs::path(HK_TEST_DATA_DIR) / "images"))
    if (e.path().extension() == ".png" || e.path().extension() == ".jpg") v.push_back(e.path());
  std::sort(v.begin(), v.end());
  return v;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string text_of(const hk::app::ImageScene& is) {
  std::string text;
  for (const auto& b : is.text_blocks) text += b.text + "\n";
  return text;
}

/// Curves of `is` whose bounding box's centre lies in one of `blocks` (what a hand feels of the text).
int curves_in(const hk::app::ImageScene& is, const std::vector<hk::app::TextBlockM>& blocks) {
  int n = 0;
  for (const hk::Polyline& p : is.polylines) {
    hk::Vec2 lo = p.points_m[0], hi = p.points_m[0];
    for (hk::Vec2 q : p.points_m) {
      lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
      hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
    }
    const hk::Vec2 c = 0.5 * (lo + hi);
    n += std::any_of(blocks.begin(), blocks.end(), [&](const hk::app::TextBlockM& b) { return b.contains(c); });
  }
  return n;
}

/// One row of the "page shown" table: the page built as the kiosk builds it (text later), then its text.
void shown_row(const std::string& name, const std::vector<std::uint8_t>& jpeg, const std::vector<std::string>& truth,
               const hk::config::Settings& s) {
  hk::config::Settings off = s;
  off.vision.ocr = "off";
  const hk::app::ImageScene felt_off = hk::app::build_image_scene_from_bytes(jpeg, name, off);
  const auto t0 = std::chrono::steady_clock::now();
  hk::app::ImageScene quick = hk::app::build_image_scene_from_bytes(jpeg, name, s, hk::app::TextTiming::later);
  const double felt_ms = ms_since(t0);
  if (!quick.with_text) {
    std::printf("| %s | %.0f | – | – | – | – | – | – |\n", name.c_str(), felt_ms);
    return;
  }
  double first_ms = -1;  // the first block read, as the TextReader hands it to the reading
  hk::app::TextRun run;
  run.on_block = [&](const std::string&, const std::string&) {
    if (first_ms < 0) first_ms = ms_since(t0);
  };
  const hk::app::ImageScene read = quick.with_text(run);
  const double text_ms = ms_since(t0);
  std::printf("| %s | %.0f | %.0f | %.0f | %d %% | %d | %d | %d |\n", name.c_str(), felt_ms, first_ms, text_ms,
              static_cast<int>(100 * hk::test::word_recall(truth, hk::test::words_of(text_of(read))) + 0.5),
              curves_in(felt_off, read.text_blocks), curves_in(quick, read.text_blocks),
              curves_in(read, read.text_blocks));
}

/// The camera row: page `page` drawn at 300 dpi, photographed in a 3264 x 2448 frame (turned 3°, keystone,
/// uneven light, noise), found and rectified at the frame's resolution, then built and read.
void camera_row(const fs::path& pdf, int page, const fs::path& dir, const std::vector<std::string>& truth,
                const hk::config::Settings& s) {
  const std::vector<std::uint8_t> jpeg = hk::test::scan_jpeg(pdf, page, 300, 0.0, dir);
  const cv::Mat picture = cv::imdecode(jpeg, cv::IMREAD_COLOR);
  hk::test::PhotoConditions c;
  c.rotation_deg = 3;
  c.perspective = 0.05;
  c.uneven_light = true;
  c.noise_sigma = 3;
  c.fill = 0.9;
  const hk::test::SyntheticPhoto photo = hk::test::synthetic_photo(picture, cv::Size(3264, 2448), c);
  const auto t0 = std::chrono::steady_clock::now();
  const hk::vision::PageDetection d = hk::vision::find_page(photo.frame);
  if (!d.found) {
    std::printf("| camera capture of page %d | 3264x2448 | page not found | | | | |\n", page);
    return;
  }
  const cv::Mat rectified = hk::vision::rectify_page(photo.frame, d.corners_px);
  const double rectify_ms = ms_since(t0);
  const hk::app::ImageScene is = hk::app::build_image_scene_from_picture(rectified, "camera capture", s);
  std::printf("| camera capture of page %d | 3264x2448 → %dx%d | %.0f | %.0f | %d %% | %.0f | %.0f |\n", page,
              rectified.cols, rectified.rows, rectify_ms, is.ocr.ms,
              static_cast<int>(100 * hk::test::word_recall(truth, hk::test::words_of(text_of(is))) + 0.5),
              is.ocr.worker_max_rss_kb / 1024.0, ms_since(t0));
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> pages{3, 5};
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) != "--pages") continue;
    pages.clear();
    std::stringstream ss(argv[i + 1]);
    for (std::string p; std::getline(ss, p, ',');) pages.push_back(std::stoi(p));
  }
  const fs::path data = HK_TEST_DATA_DIR;
  const fs::path pdf = data / "documents" / "shared-mime-info-spec.pdf";
  const fs::path dir = fs::temp_directory_path() / ("hk_bench_ocr_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const hk::config::Settings s;  // shipped: [vision] ocr "auto"
  std::printf(
      "| picture | pixels | OCR ran | words | recall | blocks | mean confidence | OCR ms | worker peak MiB | scene ms "
      "|\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  auto row = [](const std::string& name, const cv::Size& size, const hk::app::ImageScene& is, double recall,
                double scene_ms) {
    std::printf("| %s | %dx%d | %s | %d | %s | %zu | %.2f | %.0f | %.0f | %.0f |\n", name.c_str(), size.width,
                size.height, is.ocr.ran ? "yes" : "no", is.ocr.words,
                recall < 0 ? "–" : (std::to_string(static_cast<int>(recall * 100 + 0.5)) + " %").c_str(),
                is.text_blocks.size(), is.ocr.mean_confidence, is.ocr.ms, is.ocr.worker_max_rss_kb / 1024.0, scene_ms);
  };
  if (hk::test::have_poppler_utils()) {
    for (int page : pages) {
      const std::vector<std::string> truth = hk::test::words_of(hk::test::pdftotext_page(pdf, page, dir));
      for (int dpi : {150, 300}) {
        const std::vector<std::uint8_t> jpeg = hk::test::scan_jpeg(pdf, page, dpi, dpi == 150 ? 1.5 : -1.5, dir);
        const cv::Mat grey = cv::imdecode(jpeg, cv::IMREAD_GRAYSCALE);
        const auto t0 = std::chrono::steady_clock::now();
        const hk::app::ImageScene is = hk::app::build_image_scene_from_bytes(jpeg, "scan.jpg", s);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::string text;
        for (const auto& b : is.text_blocks) text += b.text + "\n";
        row("scan of page " + std::to_string(page) + " at " + std::to_string(dpi) + " dpi", grey.size(), is,
            hk::test::word_recall(truth, hk::test::words_of(text)), ms);
      }
    }
  }
  for (const fs::path& p : test_images()) {
    const cv::Mat bgr = cv::imread(p.string(), cv::IMREAD_COLOR);
    const auto t0 = std::chrono::steady_clock::now();
    const hk::app::ImageScene is = hk::app::build_image_scene(p.string(), s);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    row(p.filename().string(), bgr.size(), is, -1, ms);
  }
  if (hk::test::have_poppler_utils()) {
    std::printf(
        "\nA page shown at the kiosk: felt after (the scene with its printed lines kept out), its first block of "
        "text read after (what the reading can start with), its whole text after, recall, and curves felt inside the "
        "text blocks with OCR off / before the text / after it.\n\n");
    std::printf(
        "| picture | felt after ms | first block after ms | whole text after ms | recall | curves in text, OCR off | "
        "before the text | after |\n");
    std::printf("|---|---|---|---|---|---|---|---|\n");
    for (int page : pages) {
      const std::vector<std::string> truth = hk::test::words_of(hk::test::pdftotext_page(pdf, page, dir));
      for (int dpi : {150, 300}) {
        shown_row("scan of page " + std::to_string(page) + " at " + std::to_string(dpi) + " dpi",
                  hk::test::scan_jpeg(pdf, page, dpi, dpi == 150 ? 1.5 : -1.5, dir), truth, s);
      }
    }
    std::printf("\nA camera capture: the page found and rectified at the frame's resolution, then read.\n\n");
    std::printf("| capture | pixels | find + rectify ms | OCR ms | recall | worker peak MiB | total ms |\n");
    std::printf("|---|---|---|---|---|---|---|\n");
    for (int page : pages) camera_row(pdf, page, dir, hk::test::words_of(hk::test::pdftotext_page(pdf, page, dir)), s);
  }
  fs::remove_all(dir);
  return 0;
}
