// The message catalogue: English compiled in, translations loaded and checked, bad files refused in one
// line naming the file and the key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "audio/messages.hpp"

namespace hk::audio {
namespace {

const std::string kDir = std::string(HK_TEST_DATA_DIR) + "/messages/";

TEST(Messages, EnglishHasEveryMessageAndFillsPlaceholders) {
  const MessageCatalog& en = MessageCatalog::english();
  EXPECT_EQ(en.voice(), "en");
  for (int i = 0; i < kMessageCount; ++i) EXPECT_FALSE(en.raw(static_cast<MessageId>(i)).empty()) << kMessageKeys[static_cast<std::size_t>(i)];
  EXPECT_EQ(en.text(MessageId::picture_loaded, {{"picture", "2"}, {"pictures", "5"}, {"shapes", "7"}}),
            "Picture 2 of 5. It has 7 shapes.");
  // An argument the text does not use changes nothing; a placeholder without an argument stays visible.
  EXPECT_EQ(en.text(MessageId::volume_up, {{"shapes", "3"}}), "Louder.");
  EXPECT_NE(en.text(MessageId::timeout_warning).find("{seconds}"), std::string::npos);
}

TEST(Messages, GermanTranslationLoads) {
  const MessageCatalog de = MessageCatalog::load(kDir + "de.toml");
  EXPECT_EQ(de.voice(), "de");
  EXPECT_EQ(de.language(), "Deutsch");
  EXPECT_EQ(de.text(MessageId::picture_loaded, {{"picture", "1"}, {"pictures", "3"}, {"shapes", "4"}}), "Bild 1 von 3. Es hat 4 Formen.");
}

void expect_refused(const std::string& file, const std::string& must_contain) {
  SCOPED_TRACE(file);
  try {
    MessageCatalog::load(kDir + file);
    ADD_FAILURE() << "loaded";
  } catch (const MessageError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file), std::string::npos) << what;
    EXPECT_NE(what.find(must_contain), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
  }
}

TEST(Messages, BadTranslationsAreRefusedInOneLine) {
  expect_refused("missing_key.toml", "messages.help is missing");
  expect_refused("unknown_key.toml", "messages.colour is not a message");
  expect_refused("bad_placeholder.toml", "messages.picture_loaded uses {colour}");
  expect_refused("empty_text.toml", "messages.volume_up must be 1 to 1000 bytes");
  expect_refused("not_toml.toml", "not valid TOML");
  expect_refused("no_voice.toml", "voice");
  expect_refused("binary.toml", "not valid TOML");
  expect_refused("does_not_exist.toml", "cannot read");
}

TEST(Messages, OversizedFileIsRefusedBeforeParsing) {
  const auto path = std::filesystem::temp_directory_path() / "hk_messages_huge.toml";
  {
    std::ofstream f(path);
    f << "voice = \"en\"\n# " << std::string(300 * 1024, 'x') << "\n";
  }
  try {
    MessageCatalog::load(path.string());
    ADD_FAILURE() << "loaded";
  } catch (const MessageError& e) {
    EXPECT_NE(std::string(e.what()).find("over the limit of 262144 bytes"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace hk::audio
