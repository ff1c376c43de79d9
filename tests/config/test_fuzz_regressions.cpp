// Inputs the fuzz harness fuzz/fuzz_config.cpp found breaking a property of parse_settings (scripts/fuzz.sh;
// kept in tests/data/fuzz/config/), fed through the same entry point: each must be refused with a
// ConfigError whose what() and key() are one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "config/load.hpp"

namespace hk::config {
namespace {

namespace fs = std::filesystem;

const fs::path kDir = fs::path(HK_TEST_DATA_DIR) / "fuzz" / "config";

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// No C0 control (newline, escape...), no DEL, no C1 control (UTF-8 C2 80..C2 9F).
bool one_line(const std::string& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto u = static_cast<unsigned char>(s[i]);
    if (u < 0x20 || u == 0x7F) return false;
    if (u == 0xC2 && i + 1 < s.size() && (static_cast<unsigned char>(s[i + 1]) & 0xE0) == 0x80) return false;
  }
  return true;
}

/// The ConfigError parsing `file` must throw (what(), key()).
std::pair<std::string, std::string> refusal(const fs::path& file) {
  try {
    (void)parse_settings(read_file(file), "stick/" + file.filename().string());
  } catch (const ConfigError& e) {
    return {e.what(), e.key()};
  }
  ADD_FAILURE() << file << " was accepted";
  return {};
}

TEST(ConfigFuzzRegressions, EveryKeptInputIsRefusedOnOneLine) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(kDir)) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty());
  for (const fs::path& p : files) {
    const auto [what, key] = refusal(p);
    EXPECT_TRUE(one_line(what)) << p << ": " << what;
    EXPECT_TRUE(one_line(key)) << p << ": " << key;
    EXPECT_EQ(what.rfind("config 'stick/" + p.filename().string() + "': ", 0), 0u) << what;
  }
}

TEST(ConfigFuzzRegressions, QuotedKeyOutsideAnyTableIsEscapedInKeyToo) {
  // "max\nforce\u001b[2J" = 1 at the top of the file: the message escaped the key, key() gave it raw.
  const auto [what, key] = refusal(kDir / "bare_quoted_key_with_control_chars.toml");
  EXPECT_EQ(key, "max\\x0Aforce\\x1B[2J");
  EXPECT_NE(what.find("unknown key 'max\\x0Aforce\\x1B[2J' outside any table"), std::string::npos) << what;
}

}  // namespace
}  // namespace hk::config
