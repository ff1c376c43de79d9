// Inputs the fuzz harness fuzz/fuzz_messages.cpp found breaking a property of MessageCatalog::parse
// (scripts/fuzz.sh; kept in tests/data/fuzz/messages/), fed through the same entry point: every one must be
// refused with a MessageError whose what() is one line naming the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "audio/messages.hpp"
#include "fuzz_inputs.hpp"

namespace hk::audio {
namespace {

namespace fs = std::filesystem;
using test::is_one_line;
using test::kept_inputs;

/// what() of the MessageError that parsing `file` must throw.
std::string refusal(const std::string& file) {
  try {
    (void)MessageCatalog::parse(test::read_text(test::fuzz_dir("messages") / file), "stick/" + file);
  } catch (const MessageError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " was accepted";
  return {};
}

TEST(MessagesFuzzRegressions, EveryKeptInputIsRefusedOnOneLine) {
  const std::vector<fs::path> files = kept_inputs("messages");
  ASSERT_FALSE(files.empty());
  for (const fs::path& p : files) {
    const std::string what = refusal(p.filename().string());
    EXPECT_TRUE(is_one_line(what)) << p << ": " << what;
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
