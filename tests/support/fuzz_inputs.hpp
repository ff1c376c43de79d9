#pragma once
// The inputs the fuzz harnesses kept (tests/data/fuzz/<harness>/, see fuzz/ and scripts/fuzz.sh), and the
// one-line property their refusals must have: shared by tests/{vision,audio,config}/test_fuzz_regressions.cpp.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>
#include "test_paths.hpp"

namespace hk::test {

/// tests/data/fuzz/<harness>/.
inline std::filesystem::path fuzz_dir(const std::string& harness) {
  return std::filesystem::path(HK_TEST_DATA_DIR) / "fuzz" / harness;
}

/// The kept inputs of `harness`, sorted by name (empty when the folder is).
inline std::vector<std::filesystem::path> kept_inputs(const std::string& harness) {
  std::vector<std::filesystem::path> out;
  for (const auto& e : std::filesystem::directory_iterator(fuzz_dir(harness))) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

/// A file's bytes (empty when it cannot be read).
inline std::vector<std::uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// A file's bytes as text.
inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

/// No C0 control (newline, escape...), no DEL, no C1 control (UTF-8 C2 80..C2 9F).
inline bool is_one_line(std::string_view s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto u = static_cast<unsigned char>(s[i]);
    if (u < 0x20 || u == 0x7F) return false;
    if (u == 0xC2 && i + 1 < s.size() && (static_cast<unsigned char>(s[i + 1]) & 0xE0) == 0x80) return false;
  }
  return true;
}

}  // namespace hk::test
