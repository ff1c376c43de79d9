#pragma once
// Running the haptic-kiosk executable from app tests (HK_KIOSK_EXE, HK_TEST_DATA_DIR come from
// tests/CMakeLists.txt): the test pictures, a fresh temporary folder, and one run with its stderr.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include "test_paths.hpp"

namespace hk::test {

/// The pictures of tests/data/images (.png and .jpg), sorted by path.
inline std::vector<std::filesystem::path> test_images() {
  std::vector<std::filesystem::path> v;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(HK_TEST_DATA_DIR) / "images")) {
    const auto ext = e.path().extension().string();
    if (ext == ".png" || ext == ".jpg") v.push_back(e.path());
  }
  std::sort(v.begin(), v.end());
  return v;
}

/// An empty folder in the temporary directory named after `name` and this process (removed first if there).
inline std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("hk_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// `p` in single quotes, for a shell command line.
inline std::string quoted(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

/// Runs `cmd` through the shell: its exit status, 128 when it did not exit.
inline int sh(const std::string& cmd) {
  const int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
}

/// The whole of file `p` ("" when it cannot be read).
inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// What a run of the executable gave: its exit status (128 when it did not exit) and its stderr.
struct ExeResult {
  int status = -1;
  std::string err;
};

/// Runs haptic-kiosk with `args` (stdout discarded), its stderr captured through `tmp`/stderr.txt.
inline ExeResult run_kiosk(const std::string& args, const std::filesystem::path& tmp) {
  const std::filesystem::path err = tmp / "stderr.txt";
  const std::string cmd = std::string(HK_KIOSK_EXE) + " " + args + " >/dev/null 2>" + err.string();
  ExeResult r;
  const int raw = std::system(cmd.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
  std::ifstream f(err);
  std::stringstream ss;
  ss << f.rdbuf();
  r.err = ss.str();
  return r;
}

}  // namespace hk::test
