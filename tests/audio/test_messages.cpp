// The message catalogue: English compiled in, translations loaded and checked, bad files refused in one
// line naming the file and the key.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <functional>

#include "audio/messages.hpp"
#include "test_paths.hpp"

namespace hk::audio {
namespace {

const std::string kDir = std::string(HK_TEST_DATA_DIR) + "/messages/";

TEST(Messages, EnglishHasEveryMessageAndFillsPlaceholders) {
  const MessageCatalog& en = MessageCatalog::english();
  EXPECT_EQ(en.voice(), "en");
  for (int i = 0; i < kMessageCount; ++i)
    EXPECT_FALSE(en.raw(static_cast<MessageId>(i)).empty()) << kMessageKeys[static_cast<std::size_t>(i)];
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
  EXPECT_EQ(de.text(MessageId::picture_loaded, {{"picture", "1"}, {"pictures", "3"}, {"shapes", "4"}}),
            "Bild 1 von 3. Es hat 4 Formen.");
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

// --- Keys: messages name keys with placeholders filled from [key_names]. ---

std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// `text` with the first occurrence of `from` replaced by `to` (which must be there).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t i = text.find(from);
  EXPECT_NE(i, std::string::npos) << from;
  if (i != std::string::npos) text.replace(i, from.size(), to);
  return text;
}

/// Writes `text` to a file named `name` in the temp directory, removed at scope exit.
struct TempCatalog {
  std::filesystem::path path;
  TempCatalog(const std::string& name, const std::string& text) : path(std::filesystem::temp_directory_path() / name) {
    std::ofstream(path, std::ios::binary) << text;
  }
  ~TempCatalog() { std::filesystem::remove(path); }
};

/// Placeholders used in `s`.
std::vector<std::string> placeholders_in(const std::string& s) {
  std::vector<std::string> out;
  for (std::size_t i = s.find('{'); i != std::string::npos; i = s.find('{', i + 1)) {
    const std::size_t j = s.find('}', i);
    if (j == std::string::npos) break;
    out.push_back(s.substr(i + 1, j - i - 1));
  }
  return out;
}

TEST(MessageKeys, EnglishSpokenFormsReadAfterPress) {
  const MessageCatalog& en = MessageCatalog::english();
  EXPECT_EQ(en.key_name("F1"), "F1");
  EXPECT_EQ(en.key_name("UP"), "the Up arrow");
  EXPECT_EQ(en.key_name("PAGE_UP"), "Page Up");
  EXPECT_EQ(en.key_name("SPACE"), "the space bar");
  EXPECT_EQ(en.key_name("KP_5"), "keypad 5");
  EXPECT_EQ(en.key_name("KP_ADD"), "keypad plus");
  EXPECT_EQ(en.key_name("MINUS"), "the minus key");
  EXPECT_EQ(en.key_name("D"), "the D key");
  EXPECT_EQ(en.key_name("NO_SUCH_KEY"), "NO_SUCH_KEY") << "an unknown name is said as it is";
  EXPECT_EQ(en.key_names().size(), 75u);
  for (const auto& [name, form] : en.key_names()) {
    EXPECT_FALSE(form.empty()) << name;
    EXPECT_EQ(form.find('{'), std::string::npos) << name;
    EXPECT_EQ(form.find('_'), std::string::npos) << name << ": a spoken form, not the settings name";
  }
}

TEST(MessageKeys, KeyPlaceholdersAreFilledWithTheSpokenForm) {
  const MessageCatalog& en = MessageCatalog::english();
  const KeyArg keys[] = {{"help_key", "F1"}, {"next_key", "SPACE"}, {"previous_key", "BACKSPACE"}};
  EXPECT_EQ(en.text(MessageId::stick_inserted, {{"summary", "one document: a picture"}}, keys),
            "A USB stick with one document: a picture. Press the space bar to go through them.");
  EXPECT_EQ(en.text(MessageId::tutorial_circle, {}, keys),
            "A circle. Press {where_key} to hear where your hand is. Press the space bar for the next shape.");
  EXPECT_EQ(en.text(MessageId::key_previous, {}, keys), "The Backspace key: the picture before.")
      << "a key first in the text is capitalised";
  // Without the keys, the placeholder stays visible (a caller that forgot them is seen at once).
  EXPECT_NE(en.text(MessageId::welcome).find("{help_key}"), std::string::npos);
  // One pass: text put in is not searched for placeholders again.
  EXPECT_EQ(en.text(MessageId::stick_inserted, {{"summary", "{next_key} and {summary}"}}, keys),
            "A USB stick with {next_key} and {summary}. Press the space bar to go through them.");
  // An argument of the same name wins over a key (a message argument is the caller's explicit choice).
  EXPECT_EQ(en.text(MessageId::stick_inserted, {{"summary", "x"}, {"next_key", "Enter"}}, keys),
            "A USB stick with x. Press Enter to go through them.");
}

TEST(MessageKeys, AKeyThatStartsASentenceStartsWithACapital) {
  // A translation that puts keys first: "{help_key} gives help." at the start and after a full stop, not mid-sentence.
  std::string de = read_text(kDir + "de.toml");
  const std::string help_line =
      de.substr(de.find("\nhelp = "), de.find('\n', de.find("\nhelp = ") + 1) - de.find("\nhelp = "));
  de = replaced(de, help_line,
                "\nhelp = \"{help_key} gibt Hilfe. {next_key} bringt das nächste Bild!  {finer_key} mehr, oder "
                "{coarser_key}? {describe_key}.\"");
  const MessageCatalog c = MessageCatalog::parse(de, "keys-first.toml");
  const KeyArg keys[] = {
      {"help_key", "F1"}, {"next_key", "RIGHT"}, {"finer_key", "UP"}, {"coarser_key", "DOWN"}, {"describe_key", "D"}};
  EXPECT_EQ(c.text(MessageId::help, {}, keys),
            "Die Taste F1 gibt Hilfe. Die Pfeiltaste nach rechts bringt das nächste Bild!  Die Pfeiltaste nach oben "
            "mehr, oder "
            "die Pfeiltaste nach unten? Die Taste D.");
  // English: "the Up arrow" after "Press" stays lower case; F1 has nothing to capitalise.
  const MessageCatalog& en = MessageCatalog::english();
  const KeyArg up[] = {{"help_key", "UP"}};
  EXPECT_NE(en.text(MessageId::welcome, {}, up).find("Press the Up arrow for help."), std::string::npos);
}

TEST(MessageKeys, EnglishNamesKeysOnlyThroughPlaceholders) {
  const MessageCatalog& en = MessageCatalog::english();
  for (int i = 0; i < kMessageCount; ++i) {
    const std::string& t = en.raw(static_cast<MessageId>(i));
    SCOPED_TRACE(std::string(kMessageKeys[static_cast<std::size_t>(i)]) + ": " + t);
    for (const std::string& p : placeholders_in(t)) {
      if (p.size() > 4 && p.ends_with("_key")) {
        bool known = false;
        for (std::string_view k : kKeyPlaceholders) known = known || k == p;
        EXPECT_TRUE(known) << "{" << p << "} is not a key placeholder";
      }
    }
    // Every "Press" is followed by a key placeholder ("Press any key", "Press it twice" name none): no message
    // names a key itself.
    for (std::size_t at = t.find("Press "); at != std::string::npos; at = t.find("Press ", at + 1)) {
      if (t.compare(at + 6, 7, "any key") == 0 || t.compare(at + 6, 3, "it ") == 0) continue;
      EXPECT_EQ(t.compare(at + 6, 1, "{"), 0) << "at " << at;
    }
    for (const char* wrong : {"Plus and minus", "big key", "Arrow keys", "D key", "volume keys", "Next"}) {
      EXPECT_EQ(t.find(wrong), std::string::npos) << wrong;
    }
  }
  // The help names every action's key (the camera's in the sentence added when there is a camera); the welcome
  // the help key; the tutorial how to go on.
  for (std::string_view k : kKeyPlaceholders) {
    const MessageId where = k == "capture_key" ? MessageId::help_camera : MessageId::help;
    EXPECT_NE(en.raw(where).find("{" + std::string(k) + "}"), std::string::npos) << k;
  }
  EXPECT_NE(en.raw(MessageId::welcome).find("{help_key}"), std::string::npos);
  for (MessageId id : {MessageId::tutorial_start, MessageId::tutorial_circle, MessageId::tutorial_triangle,
                       MessageId::stick_inserted}) {
    EXPECT_NE(en.raw(id).find("{next_key}"), std::string::npos) << kMessageKeys[static_cast<std::size_t>(id)];
  }
}

TEST(MessageKeys, GermanHasEveryKeyNameOfEnglish) {
  const MessageCatalog de = MessageCatalog::load(kDir + "de.toml");
  const MessageCatalog& en = MessageCatalog::english();
  ASSERT_EQ(de.key_names().size(), en.key_names().size());
  for (const auto& [name, form] : en.key_names()) EXPECT_EQ(de.key_names().count(name), 1u) << name;
  EXPECT_EQ(de.key_name("SPACE"), "die Leertaste");
  const KeyArg keys[] = {{"help_key", "F1"}};
  EXPECT_NE(de.text(MessageId::welcome, {}, keys).find("Drücken Sie die Taste F1 für Hilfe."), std::string::npos);
}

/// Loads de.toml changed by `edit` from a file named `file`; expects a one-line MessageError naming it and
/// `must_contain`.
void expect_translation_refused(const std::string& file, const std::function<std::string(std::string)>& edit,
                                const std::string& must_contain) {
  SCOPED_TRACE(file);
  const TempCatalog t(file, edit(read_text(kDir + "de.toml")));
  try {
    MessageCatalog::load(t.path.string());
    ADD_FAILURE() << "loaded";
  } catch (const MessageError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file), std::string::npos) << what;
    EXPECT_NE(what.find(must_contain), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
  }
}

TEST(MessageKeys, TranslationsMustNameExactlyTheEnglishKeys) {
  expect_translation_refused(
      "hk_keys_missing.toml", [](std::string s) { return replaced(s, "UP = \"die Pfeiltaste nach oben\"\n", ""); },
      "key_names.UP is missing");
  expect_translation_refused(
      "hk_keys_unknown.toml", [](std::string s) { return s + "ESCAPE = \"die Escape-Taste\"\n"; },
      "key_names.ESCAPE is not a key name the English catalogue has");
  expect_translation_refused(
      "hk_keys_empty.toml", [](std::string s) { return replaced(s, "F1 = \"die Taste F1\"", "F1 = \"\""); },
      "key_names.F1 must be 1 to 100 bytes");
  expect_translation_refused(
      "hk_keys_not_string.toml",
      [](std::string s) { return replaced(s, "KP_5 = \"die Taste 5 im Ziffernblock\"", "KP_5 = 5"); },
      "key_names.KP_5 is not a string");
  expect_translation_refused(
      "hk_keys_no_table.toml", [](std::string s) { return s.substr(0, s.find("[key_names]")); },
      "has no [key_names] table");
  // A key placeholder is accepted where the English text has it, and refused where it has not.
  expect_translation_refused(
      "hk_keys_wrong_place.toml",
      [](std::string s) { return replaced(s, "volume_up = \"Lauter.\"", "volume_up = \"Lauter. {help_key}\""); },
      "messages.volume_up uses {help_key}");
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
