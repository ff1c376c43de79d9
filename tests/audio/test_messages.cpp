// The message catalogues: English is the source, the shipped translations load from the build's MO files with
// every message, the build's check refuses a broken catalogue, and a bad file is refused in one line.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "audio/messages.hpp"
#include "hk/text.hpp"
#include "test_paths.hpp"

namespace hk::audio {
namespace {

namespace fs = std::filesystem;

const fs::path kPoDir = fs::path(HK_TEST_DATA_DIR) / ".." / ".." / "audio-cues" / "po";
const fs::path kEnglishSource = fs::path(HK_TEST_DATA_DIR) / ".." / ".." / "audio-cues" / "src" / "messages_en.cpp";
const std::vector<std::string> kShipped{"fr", "de", "es"};

std::string read_text(const fs::path& path) {
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

/// A fresh folder under the temp directory, removed at scope exit.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name) : path(fs::temp_directory_path() / ("hk_messages_" + name)) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

/// Runs `command` with sh; its exit status, its standard error in *err.
int run(const std::string& command, const fs::path& err_file, std::string* err) {
  const int rc = std::system((command + " 2> '" + err_file.string() + "'").c_str());
  *err = read_text(err_file);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(Messages, EnglishHasEveryMessageAndFillsPlaceholders) {
  const MessageCatalog& en = MessageCatalog::english();
  EXPECT_EQ(en.voice(), "en");
  EXPECT_EQ(en.language_name(), "English");
  for (int i = 0; i < kMessageCount; ++i) EXPECT_FALSE(en.raw(static_cast<MessageId>(i)).empty()) << i;
  EXPECT_EQ(message_key(MessageId::welcome), "welcome");
  EXPECT_EQ(message_key(MessageId::other_language), "other_language");
  EXPECT_EQ(en.text(MessageId::picture_loaded, 7, {{"picture", "2"}, {"pictures", "5"}}),
            "Picture 2 of 5. It has 7 shapes.");
  EXPECT_EQ(en.text(MessageId::picture_loaded, 1, {{"picture", "2"}, {"pictures", "5"}}),
            "Picture 2 of 5. It has one shape.");
  // An argument the text does not use changes nothing; a placeholder without an argument stays visible.
  EXPECT_EQ(en.text(MessageId::volume_up, {{"shapes", "3"}}), "Louder.");
  EXPECT_NE(en.text(MessageId::timeout_warning).find("{seconds}"), std::string::npos);
  // Words: a form's look with its size and colour; an unknown colour leaves no double space.
  EXPECT_EQ(en.word("look_round", 1, {{"size", "small"}, {"colour", "white"}}), "a small white round shape");
  EXPECT_EQ(en.word("look_square", 3, {{"size", "large"}, {"colour", ""}}), "3 large squares");
  EXPECT_EQ(en.word("no_such_word"), "");
}

TEST(Messages, EveryShippedLanguageLoadsWholeAndTranslated) {
  const MessageCatalog& en = MessageCatalog::english();
  const std::map<std::string, std::string> names{{"fr", "Français"}, {"de", "Deutsch"}, {"es", "Español"}};
  for (const std::string& lang : kShipped) {
    SCOPED_TRACE(lang);
    const MessageCatalog c = MessageCatalog::load(lang, default_locale_dir());
    EXPECT_EQ(c.language(), lang);
    EXPECT_EQ(c.voice(), lang);
    EXPECT_EQ(c.language_name(), names.at(lang));
    int same = 0;
    for (int i = 0; i < kMessageCount; ++i) {
      const auto id = static_cast<MessageId>(i);
      same += c.raw(id) == en.raw(id);
      EXPECT_EQ(c.text(id).find('\n'), std::string::npos) << message_key(id);
    }
    EXPECT_LE(same, 3) << "messages left in English (describe, a bare {name}., Text: are the same in some)";
    for (const auto& [name, form] : en.key_names()) EXPECT_EQ(c.key_names().count(name), 1u) << name;
  }
}

TEST(Messages, PluralFormsFollowEachCatalogue) {
  const MessageCatalog fr = MessageCatalog::load("fr", default_locale_dir());
  const MessageCatalog de = MessageCatalog::load("de", default_locale_dir());
  const MessageCatalog& en = MessageCatalog::english();
  // French counts 0 and 1 as one (Plural-Forms: n > 1); German and English only 1.
  EXPECT_EQ(fr.raw(MessageId::tour_remaining, 0), fr.raw(MessageId::tour_remaining, 1));
  EXPECT_NE(fr.raw(MessageId::tour_remaining, 2), fr.raw(MessageId::tour_remaining, 1));
  EXPECT_EQ(fr.raw(MessageId::tour_remaining, 2), fr.raw(MessageId::tour_remaining, 5));
  EXPECT_NE(de.raw(MessageId::tour_remaining, 0), de.raw(MessageId::tour_remaining, 1));
  EXPECT_EQ(de.raw(MessageId::tour_remaining, 0), de.raw(MessageId::tour_remaining, 5));
  EXPECT_EQ(en.text(MessageId::tour_remaining, 5), "5 shapes not yet touched.");
  EXPECT_EQ(en.text(MessageId::tour_remaining, 1), "One shape not yet touched.");
  EXPECT_NE(fr.text(MessageId::tour_remaining, 5).find('5'), std::string::npos);
}

/// The catalogue of `lang` from `po_text`, compiled by msgfmt (without --check, so a broken entry gets through
/// to the loader) into `dir`/LANG/LC_MESSAGES/haptic-kiosk.mo.
void compile(const std::string& po_text, const fs::path& dir, const std::string& lang) {
  const fs::path out = dir / lang / "LC_MESSAGES";
  fs::create_directories(out);
  std::ofstream(dir / (lang + ".po"), std::ios::binary) << po_text;
  std::string err;
  ASSERT_EQ(run("msgfmt -o '" + (out / "haptic-kiosk.mo").string() + "' '" + (dir / (lang + ".po")).string() + "'",
                dir / "err.txt", &err),
            0)
      << err;
}

void expect_refused(const std::string& lang, const fs::path& dir, const std::string& must_contain) {
  SCOPED_TRACE(lang);
  try {
    (void)MessageCatalog::load(lang, dir);
    ADD_FAILURE() << "loaded";
  } catch (const MessageError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("catalogue '" + lang + "'"), std::string::npos) << what;
    EXPECT_NE(what.find(must_contain), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
  }
}

TEST(Messages, BadCataloguesAreRefusedInOneLine) {
  const TempDir dir("bad");
  const std::string fr = read_text(kPoDir / "fr.po");
  // A translation with a placeholder its English text lacks (msgfmt without --check lets it through).
  compile(replaced(fr, "msgstr \"Plus fort.\"", "msgstr \"Plus fort {colour}.\""), dir.path, "fr");
  expect_refused("fr", dir.path, "volume_up uses {colour}");
  // A message left out.
  std::string missing = fr;
  const std::size_t at = missing.find("msgctxt \"volume_up\"");
  ASSERT_NE(at, std::string::npos);
  missing.erase(at, missing.find("\n\n", at) - at);
  compile(missing, dir.path, "de");
  expect_refused("de", dir.path, "volume_up is missing");
  // No catalogue, not an MO file, too big, not a language tag.
  expect_refused("it", dir.path, "no file");
  fs::create_directories(dir.path / "es" / "LC_MESSAGES");
  std::ofstream(dir.path / "es" / "LC_MESSAGES" / "haptic-kiosk.mo", std::ios::binary) << "msgid \"x\"\n";
  expect_refused("es", dir.path, "not a gettext MO file");
  fs::create_directories(dir.path / "pt" / "LC_MESSAGES");
  std::ofstream(dir.path / "pt" / "LC_MESSAGES" / "haptic-kiosk.mo", std::ios::binary)
      << std::string(kMaxCatalogueBytes + 1, '\0');
  expect_refused("pt", dir.path, "over the limit of 1048576 bytes");
  expect_refused("EN_us", dir.path, "not a BCP 47 language tag");
  // A regional tag falls back to its language's catalogue.
  EXPECT_EQ(MessageCatalog::load("fr-CA", default_locale_dir()).language_name(), "Français");
}

TEST(Messages, AnMoFileWithoutItsHeaderEntryIsRefusedInOneLine) {
  // Boost.Locale 1.74 reads entry 0 (the header) whatever the file's count says, and read past the end of one that
  // said 0 (a fuzz find, kept as fuzz/seeds/messages/no_header_entry.mo).
  std::ifstream in(default_locale_dir() / "fr" / "LC_MESSAGES" / "haptic-kiosk.mo", std::ios::binary);
  std::vector<char> mo((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(mo.size(), 28u);
  std::fill(mo.begin() + 8, mo.begin() + 12, '\0');  // no strings
  try {
    (void)MessageCatalog::from_mo("fr", mo, "headless.mo");
    ADD_FAILURE() << "a file without its header entry was read";
  } catch (const MessageError& e) {
    EXPECT_NE(std::string(e.what()).find("headless.mo"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no header entry"), std::string::npos) << e.what();
  }
}

TEST(Messages, TheBuildCheckFailsOnABrokenCatalogue) {
  // The build's own step (audio-cues/po/catalogues.sh build) on a copy of the catalogues, each broken in turn.
  const TempDir dir("check");
  const std::string script = (kPoDir / "catalogues.sh").string();
  const auto check = [&](const std::string& fr_text, std::string* err) {
    fs::remove_all(dir.path / "po");
    fs::create_directories(dir.path / "po");
    fs::copy_file(kPoDir / "haptic-kiosk.pot", dir.path / "po" / "haptic-kiosk.pot");
    std::ofstream(dir.path / "po" / "fr.po", std::ios::binary) << fr_text;
    return run("bash '" + script + "' build haptic-kiosk '" + (dir.path / "po").string() + "' '" +
                   (dir.path / "out").string() + "' '" + kEnglishSource.string() + "'",
               dir.path / "err.txt", err);
  };
  const std::string fr = read_text(kPoDir / "fr.po");
  std::string err;
  ASSERT_EQ(check(fr, &err), 0) << err;
  EXPECT_TRUE(fs::exists(dir.path / "out" / "fr" / "LC_MESSAGES" / "haptic-kiosk.mo"));
  // A placeholder that differs from the English text's.
  std::string bad = fr;
  const std::size_t entry = bad.find("msgstr", bad.find("msgctxt \"picture_empty\""));
  bad.replace(bad.find("{picture}", entry), 9, "{image}");
  EXPECT_EQ(check(bad, &err), 1);
  EXPECT_NE(err.find("fr.po does not compile"), std::string::npos) << err;
  // A message left untranslated.
  EXPECT_EQ(check(replaced(fr, "msgstr \"Plus fort.\"", "msgstr \"\""), &err), 1);
  EXPECT_NE(err.find("fr.po lacks messages"), std::string::npos) << err;
}

// --- Keys: messages name keys with placeholders filled with their spoken forms. ---

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
  const MessageCatalog fr = MessageCatalog::load("fr", default_locale_dir());
  const KeyArg keys[] = {{"previous_key", "LEFT"}};
  const std::string t = fr.text(MessageId::key_previous, {}, keys);
  ASSERT_FALSE(t.empty());
  EXPECT_EQ(t.rfind(hk::capitalised(fr.key_name("LEFT")), 0), 0u) << t;
  // English: "the Up arrow" after "Press" stays lower case; F1 has nothing to capitalise.
  const MessageCatalog& en = MessageCatalog::english();
  const KeyArg up[] = {{"help_key", "UP"}};
  EXPECT_NE(en.text(MessageId::welcome, {}, up).find("Press the Up arrow for help."), std::string::npos);
  EXPECT_EQ(hk::capitalised("écoutez"), "Écoutez");
  EXPECT_EQ(hk::capitalised("÷x"), "÷x");
}

TEST(MessageKeys, EnglishNamesKeysOnlyThroughPlaceholders) {
  const MessageCatalog& en = MessageCatalog::english();
  for (int i = 0; i < kMessageCount; ++i) {
    const std::string& t = en.raw(static_cast<MessageId>(i));
    SCOPED_TRACE(std::string(message_key(static_cast<MessageId>(i))) + ": " + t);
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
  // The help names every action's key (the camera's in the sentence added when there is a camera, the Copy key's
  // in the one added where copies are offered); the welcome the help key; the tutorial how to go on.
  for (std::string_view k : kKeyPlaceholders) {
    const MessageId where = k == "capture_key" ? MessageId::help_camera
                            : k == "copy_key"  ? MessageId::help_copy
                                               : MessageId::help;
    EXPECT_NE(en.raw(where).find("{" + std::string(k) + "}"), std::string::npos) << k;
  }
  EXPECT_NE(en.raw(MessageId::welcome).find("{help_key}"), std::string::npos);
  for (MessageId id : {MessageId::tutorial_start, MessageId::tutorial_circle, MessageId::tutorial_triangle,
                       MessageId::stick_inserted}) {
    EXPECT_NE(en.raw(id).find("{next_key}"), std::string::npos) << message_key(id);
  }
}

}  // namespace
}  // namespace hk::audio
