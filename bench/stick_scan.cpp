// Stick scan speed: how long scan_stick takes over a stick of 10 000 files in 100
// folders — six in ten tiny files with a picture's or a PDF's first bytes, the rest text, empty files
// and macOS "._" files — built in a fresh folder under /tmp and removed afterwards. Timed with the page
// cache warm (the first, cold walk is reported on its own), several repeats: min / median / max.
// Two cases: the whole walk (limits raised so nothing stops it), and the kiosk's default limits (which
// stop it at the 500th document, or the 10 000th entry).
// Usage: bench_stick_scan [--files N] [--folders N] [--repeats N] [--out FILE.json]   (prints one JSON line)
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "vision/stick_scan.hpp"

namespace fs = std::filesystem;
using hk::vision::ScanLimits;
using hk::vision::StickScan;

namespace {

/// The contents of file i: a mix of document magic bytes and things the scan refuses.
std::string file_bytes(int i) {
  switch (i % 10) {
    case 0:
    case 1:
    case 2:
    case 9:
      return std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16);
    case 3:
      return std::string("\xFF\xD8\xFF\xE0\0\x10JFIF\0", 11);
    case 4:
      return "%PDF-1.4\n%\xE2\xE3\xCF\xD3\n";
    case 5:
    case 8:
      return "a note, not a picture\n";
    default:
      return "";  // 6: empty; 7: an AppleDouble "._" file (name decides)
  }
}

std::string file_name(int i) {
  static const char* ext[] = {".png", ".png", ".png", ".jpg", ".pdf", ".txt", ".pdf", ".png", ".doc", ".png"};
  return (i % 10 == 7 ? "._IMG_" : "IMG_") + std::to_string(i) + ext[i % 10];
}

struct Timing {
  double min_ms = 0, median_ms = 0, max_ms = 0, cold_ms = 0;
  StickScan last;
};

Timing time_scans(const std::string& root, const ScanLimits& limits, int repeats) {
  Timing t;
  std::vector<double> ms;
  for (int r = 0; r <= repeats; ++r) {
    StickScan s = hk::vision::scan_stick(root, limits);
    if (r == 0) {
      t.cold_ms = 1e3 * s.seconds;  // the first walk after building: inodes cached, but not yet by this walk
    } else {
      ms.push_back(1e3 * s.seconds);
    }
    t.last = std::move(s);
  }
  std::sort(ms.begin(), ms.end());
  t.min_ms = ms.front();
  t.max_ms = ms.back();
  t.median_ms = ms[ms.size() / 2];
  return t;
}

nlohmann::json to_json(const Timing& t) {
  return {{"min_ms", t.min_ms},
          {"median_ms", t.median_ms},
          {"max_ms", t.max_ms},
          {"first_ms", t.cold_ms},
          {"entries_scanned", t.last.entries_scanned},
          {"documents", t.last.documents.size()},
          {"refused", t.last.refused.size()},
          {"complete", t.last.complete},
          {"stopped_by", t.last.stopped_by},
          {"median_us_per_entry",
           t.last.entries_scanned ? 1e3 * t.median_ms / static_cast<double>(t.last.entries_scanned) : 0.0}};
}

}  // namespace

int main(int argc, char** argv) {
  int files = 10000, folders = 100, repeats = 11;
  std::string out_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--files" && i + 1 < argc)
      files = std::atoi(argv[++i]);
    else if (a == "--folders" && i + 1 < argc)
      folders = std::atoi(argv[++i]);
    else if (a == "--repeats" && i + 1 < argc)
      repeats = std::atoi(argv[++i]);
    else if (a == "--out" && i + 1 < argc)
      out_path = argv[++i];
    else {
      std::fprintf(stderr, "usage: %s [--files N] [--folders N] [--repeats N] [--out FILE.json]\n", argv[0]);
      return 2;
    }
  }
  if (files < 1 || folders < 1 || repeats < 1) {
    std::fprintf(stderr, "bench_stick_scan: --files, --folders and --repeats must be positive\n");
    return 2;
  }
  char tmpl[] = "/tmp/hk_stick_bench_XXXXXX";
  if (::mkdtemp(tmpl) == nullptr) {
    std::perror("bench_stick_scan: mkdtemp");
    return 1;
  }
  const std::string root = tmpl;
  for (int f = 0; f < folders; ++f) fs::create_directories(root + "/DCIM/" + std::to_string(100 + f) + "CANON");
  for (int i = 0; i < files; ++i) {
    const std::string p = root + "/DCIM/" + std::to_string(100 + i % folders) + "CANON/" + file_name(i);
    const std::string b = file_bytes(i);
    const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0 || ::write(fd, b.data(), b.size()) != static_cast<ssize_t>(b.size())) {
      std::perror("bench_stick_scan: writing the tree");
      fs::remove_all(root);
      return 1;
    }
    ::close(fd);
  }

  ScanLimits whole;
  whole.max_entries = 10L * (files + folders + 1);
  whole.max_documents = files + 1;
  whole.max_seconds = 600.0;
  nlohmann::json j;
  try {
    const Timing full = time_scans(root, whole, repeats);
    const Timing deflt = time_scans(root, ScanLimits{}, repeats);
    j = {{"bench", "stick_scan"},       {"files", files},
         {"folders", folders},          {"repeats", repeats},
         {"whole_walk", to_json(full)}, {"default_limits", to_json(deflt)}};
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_stick_scan: %s\n", e.what());
    fs::remove_all(root);
    return 1;
  }
  fs::remove_all(root);
  const std::string line = j.dump();
  std::printf("%s\n", line.c_str());
  if (!out_path.empty()) {
    std::ofstream out(out_path);
    out << line << "\n";
    if (!out) {
      std::fprintf(stderr, "bench_stick_scan: cannot write %s\n", out_path.c_str());
      return 1;
    }
  }
  return 0;
}
