// Inputs the fuzz harness fuzz/fuzz_messages.cpp found breaking a property of MessageCatalog::parse
// (scripts/fuzz.sh; kept in tests/data/fuzz/messages/), fed through the same entry point: every one must be
// refused with a MessageError whose what() is one line naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "audio/messages.hpp"

namespace hk::audio {
namespace {

namespace fs = std::filesystem;

const fs::path kDir = fs::path(HK_TEST_DATA_DIR) / "fuzz" / "messages";

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

/// what() of the MessageError that parsing `file` must throw.
std::string refusal(const std::string& file) {
  try {
    (void)MessageCatalog::parse(read_file(kDir / file), "stick/" + file);
  } catch (const MessageError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " was accepted";
  return {};
}

TEST(MessagesFuzzRegressions, EveryKeptInputIsRefusedOnOneLine) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(kDir)) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty());
  for (const fs::path& p : files) {
    const std::string what = refusal(p.filename().string());
    EXPECT_TRUE(one_line(what)) << p << ": " << what;
    EXPECT_EQ(what.rfind("messages 'stick/" + p.filename().string() + "': ", 0), 0u) << what;
  }
}

TEST(MessagesFuzzRegressions, TomlErrorQuotingAControlCharacterIsEscaped) {
  // toml++ quotes the character it choked on as it is ("saw 'f\x02'"); the message escapes it.
  const std::string what = refusal("toml_error_quotes_control_char.toml");
  EXPECT_NE(what.find("not valid TOML"), std::string::npos) << what;
  EXPECT_NE(what.find("\\x02"), std::string::npos) << what;
}

TEST(MessagesFuzzRegressions, QuotedKeyWithNewlineIsEscaped) {
  // A quoted TOML key may hold any character: "welcome\n\u001b[2J" is not a message the kiosk has.
  const std::string what = refusal("quoted_key_with_newline.toml");
  EXPECT_NE(what.find("messages.welcome\\x0A\\x1B[2J is not a message the kiosk has"), std::string::npos) << what;
}

}  // namespace
}  // namespace hk::audio
