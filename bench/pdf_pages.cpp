// PDF pages in the forked poppler worker: for each shipped PDF in tests/data/documents, probe it
// and render each of its pages (at most 20 per document) with the default limits (4 MP budget, 300 dpi at
// most), one worker per page as the kiosk does. Per page: the worker's wall time (fork to reap, so it
// includes loading the document again), its peak resident memory (wait4's ru_maxrss, which includes the
// pages shared with this process at fork), pixels, dpi, words and text blocks.
// Usage: bench_pdf_pages [--documents DIR] [--out FILE.json] [--repeat N]   (prints a markdown table;
//        with --repeat, each page is rendered N times and the median wall time reported)
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "test_paths.hpp"
#include "vision/pdf.hpp"

namespace fs = std::filesystem;
using namespace hk::vision;

int main(int argc, char** argv) {
  std::string documents = std::string(HK_TEST_DATA_DIR) + "/documents", out_path;
  int repeat = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--documents" && i + 1 < argc) documents = argv[++i];
    if (a == "--out" && i + 1 < argc) out_path = argv[++i];
    if (a == "--repeat" && i + 1 < argc) repeat = std::max(1, std::stoi(argv[++i]));
  }
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(documents)) {
    if (e.path().extension() == ".pdf") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());

  const PdfLimits limits;
  constexpr int kMaxPagesPerDocument = 20;
  nlohmann::json docs = nlohmann::json::array();
  std::vector<double> all_ms;
  long max_rss = 0;
  std::printf(
      "| document | page | render ms | worker peak RSS KiB | pixels | dpi | words | blocks "
      "|\n|---|---|---|---|---|---|---|---|\n");
  for (const fs::path& path : files) {
    std::ifstream f(path, std::ios::binary);
    const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
    const std::string name = path.filename().string();
    nlohmann::json dj;
    dj["document"] = name;
    dj["bytes"] = bytes.size();
    try {
      const PdfInfo info = probe_pdf(bytes, name, limits);
      dj["pages"] = info.pages;
      dj["probe_ms"] = info.worker_ms;
      dj["probe_max_rss_kb"] = info.worker_max_rss_kb;
      nlohmann::json pages = nlohmann::json::array();
      for (int page = 1; page <= std::min(info.pages, kMaxPagesPerDocument); ++page) {
        std::vector<double> ms;
        PdfPage p;
        for (int r = 0; r < repeat; ++r) {
          p = render_pdf_page(bytes, name, page, limits);
          ms.push_back(p.worker_ms);
        }
        std::sort(ms.begin(), ms.end());
        const double med = ms[ms.size() / 2];
        all_ms.push_back(med);
        max_rss = std::max(max_rss, p.worker_max_rss_kb);
        const long pixels = static_cast<long>(p.grey.cols) * p.grey.rows;
        std::printf("| %s | %d | %.1f | %ld | %ld (%d x %d) | %.1f | %zu | %zu |\n", name.c_str(), page, med,
                    p.worker_max_rss_kb, pixels, p.grey.cols, p.grey.rows, p.dpi, p.words.size(), p.blocks.size());
        pages.push_back({{"page", page},
                         {"render_ms", med},
                         {"worker_max_rss_kb", p.worker_max_rss_kb},
                         {"width_px", p.grey.cols},
                         {"height_px", p.grey.rows},
                         {"pixels", pixels},
                         {"dpi", p.dpi},
                         {"width_pt", p.width_pt},
                         {"height_pt", p.height_pt},
                         {"words", p.words.size()},
                         {"blocks", p.blocks.size()}});
      }
      dj["rendered"] = pages;
    } catch (const PdfError& e) {
      dj["error"] = e.what();
      std::printf("| %s | - | %s |\n", name.c_str(), e.what());
    }
    docs.push_back(dj);
  }
  std::sort(all_ms.begin(), all_ms.end());
  if (!all_ms.empty()) {
    std::printf("\n%zu pages: render ms median %.1f, max %.1f; worker peak RSS max %ld KiB\n", all_ms.size(),
                all_ms[all_ms.size() / 2], all_ms.back(), max_rss);
  }
  nlohmann::json j;
  j["limits"] = {{"max_page_pixels", limits.max_page_pixels},
                 {"max_dpi", limits.max_dpi},
                 {"worker_wall_s", limits.worker_wall_s},
                 {"worker_cpu_s", limits.worker_cpu_s}};
  j["repeat"] = repeat;
#if defined(__SANITIZE_ADDRESS__)
  j["sanitized"] = true;
#else
  j["sanitized"] = false;
#endif
  j["documents"] = docs;
  if (!out_path.empty()) std::ofstream(out_path) << j.dump(1) << "\n";
  return 0;
}
