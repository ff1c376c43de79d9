// Reading text from pictures: for scans of pages of the shipped PDF (made as a scanner or phone makes them,
// tests/support/scans.hpp: 150 and 300 dpi, turned ±1.5°, noise, JPEG 80) and for every test picture, the
// OCR worker's time and peak memory, the word recall against pdftotext of the same page, and the text
// blocks found where there is no text (false blocks). One Markdown table on stdout.
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

#include "image_scene.hpp"
#include "scans.hpp"

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
  hk::config::Settings s;
  s.vision.ocr = "auto";
  std::printf("| picture | pixels | OCR ran | words | recall | blocks | mean confidence | OCR ms | worker peak MiB | scene ms |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  auto row = [](const std::string& name, const cv::Size& size, const hk::app::ImageScene& is, double recall, double scene_ms) {
    std::printf("| %s | %dx%d | %s | %d | %s | %zu | %.2f | %.0f | %.0f | %.0f |\n", name.c_str(), size.width, size.height,
                is.ocr.ran ? "yes" : "no", is.ocr.words, recall < 0 ? "–" : (std::to_string(static_cast<int>(recall * 100 + 0.5)) + " %").c_str(),
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
  fs::remove_all(dir);
  return 0;
}
