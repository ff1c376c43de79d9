// Inputs kept for the message catalogue's fuzz harness (fuzz/fuzz_messages.cpp, scripts/fuzz.sh; in
// tests/data/fuzz/messages/: catalogue files that once broke a property), fed through its entry point,
// MessageCatalog::from_mo: every one must be refused with a MessageError whose what() is one line naming the file.
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
    const std::string bytes = test::read_text(test::fuzz_dir("messages") / file);
    (void)MessageCatalog::from_mo("fr", std::vector<char>(bytes.begin(), bytes.end()), "stick/" + file);
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
    EXPECT_EQ(what.rfind("catalogue 'fr' (stick/" + p.filename().string() + "): ", 0), 0u) << what;
  }
}

}  // namespace
}  // namespace hk::audio
