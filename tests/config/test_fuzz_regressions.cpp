// Inputs the fuzz harness fuzz/fuzz_config.cpp found breaking a property of parse_settings (scripts/fuzz.sh;
// kept in tests/data/fuzz/config/), fed through the same entry point: each must be refused with a
// ConfigError whose what() and key() are one line.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "config/load.hpp"
#include "fuzz_inputs.hpp"

namespace hk::config {
namespace {

namespace fs = std::filesystem;
using test::is_one_line;
using test::kept_inputs;

/// The ConfigError parsing `file` must throw (what(), key()).
std::pair<std::string, std::string> refusal(const fs::path& file) {
  try {
    (void)parse_settings(test::read_text(file), "stick/" + file.filename().string());
  } catch (const ConfigError& e) {
    return {e.what(), e.key()};
  }
  ADD_FAILURE() << file << " was accepted";
  return {};
}

TEST(ConfigFuzzRegressions, EveryKeptInputIsRefusedOnOneLine) {
  const std::vector<fs::path> files = kept_inputs("config");
  ASSERT_FALSE(files.empty());
  for (const fs::path& p : files) {
    const auto [what, key] = refusal(p);
    EXPECT_TRUE(is_one_line(what)) << p << ": " << what;
    EXPECT_TRUE(is_one_line(key)) << p << ": " << key;
    EXPECT_EQ(what.rfind("config 'stick/" + p.filename().string() + "': ", 0), 0u) << what;
  }
}

TEST(ConfigFuzzRegressions, QuotedKeyOutsideAnyTableIsEscapedInKeyToo) {
  // "max\nforce\u001b[2J" = 1 at the top of the file: the message escaped the key, key() gave it raw.
  const auto [what, key] = refusal(test::fuzz_dir("config") / "bare_quoted_key_with_control_chars.toml");
  EXPECT_EQ(key, "max\\x0Aforce\\x1B[2J");
  EXPECT_NE(what.find("unknown key 'max\\x0Aforce\\x1B[2J' outside any table"), std::string::npos) << what;
}

}  // namespace
}  // namespace hk::config
