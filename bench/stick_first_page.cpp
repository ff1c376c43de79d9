// Stick inserted -> first page felt: the kiosk's own StickService on a
// folder standing in for a mounted stick. For each shipped document (and a picture), a stick holding just
// it is inserted; the clock runs from insert_folder() to the moment its first page's scene is built and
// ready to publish (scan + page counting in the PDF worker + drawing the page in the worker + edges +
// multiresolution + trees), which is when the kiosk says the summary and the force fades in. Mount time is
// not included (a loop mount here takes a few ms; a real stick's is its hardware's).
// Usage: bench_stick_first_page [--repeats N] [--out FILE.json]
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include <spdlog/spdlog.h>

#include "pictures/stick_service.hpp"
#include "test_paths.hpp"

using namespace hk;
using namespace hk::app;
namespace fs = std::filesystem;

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

template <class Poll>
auto wait_for(Poll poll) {
  for (;;) {
    auto got = poll();
    if (!got.empty()) return got;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_path;
  int repeats = 5;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--out") out_path = argv[i + 1];
    if (std::string(argv[i]) == "--repeats") repeats = std::max(1, std::atoi(argv[i + 1]));
  }
  spdlog::set_level(spdlog::level::warn);  // the service's info lines would land in the table
  const fs::path data = HK_TEST_DATA_DIR;
  const std::vector<fs::path> docs{data / "documents" / "horse_and_page.pdf",
                                   data / "documents" / "shared-mime-info-spec.pdf", data / "images" / "fruits.jpg"};
  const fs::path tmp = fs::temp_directory_path() / ("hk_bench_stick_" + std::to_string(::getpid()));
  config::Settings s;
  nlohmann::json rows = nlohmann::json::array();
  std::printf(
      "| document | pages | inserted -> first page felt, median [ms] | min [ms] | of which scan + page count [ms] "
      "|\n|---|---|---|---|---|\n");
  for (const fs::path& doc : docs) {
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    fs::copy_file(doc, tmp / doc.filename());
    std::vector<double> total, scan;
    int pages = 0;
    for (int r = 0; r < repeats; ++r) {
      StickService svc(s, nullptr, (tmp / "mnt").string());
      const auto t0 = std::chrono::steady_clock::now();
      svc.insert_folder(tmp.string());
      const std::vector<StickNews> news = wait_for([&] { return svc.poll_news(); });
      if (news.empty() || news[0].documents.empty()) {
        std::fprintf(stderr, "bench_stick_first_page: %s: not listed\n", doc.c_str());
        return 1;
      }
      scan.push_back(ms_since(t0));
      pages = news[0].documents[0].pages;
      svc.load(news[0].stick, 0, 1);
      const std::vector<LoadedDocument> got = wait_for([&] { return svc.poll_loaded(); });
      if (!got[0].scene) {
        std::fprintf(stderr, "bench_stick_first_page: %s: %s\n", doc.c_str(), got[0].reason.c_str());
        return 1;
      }
      total.push_back(ms_since(t0));
    }
    std::sort(total.begin(), total.end());
    std::sort(scan.begin(), scan.end());
    const double med = total[total.size() / 2];
    std::printf("| %s | %d | %.0f | %.0f | %.0f |\n", doc.filename().c_str(), pages, med, total.front(),
                scan[scan.size() / 2]);
    rows.push_back({{"document", doc.filename().string()},
                    {"pages", pages},
                    {"first_page_ms_median", med},
                    {"first_page_ms_min", total.front()},
                    {"scan_ms_median", scan[scan.size() / 2]},
                    {"repeats", repeats}});
  }
  fs::remove_all(tmp);
  if (!out_path.empty()) std::ofstream(out_path) << nlohmann::json{{"stick_first_page", rows}}.dump(2) << "\n";
  return 0;
}
