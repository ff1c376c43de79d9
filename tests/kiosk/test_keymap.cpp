// The keys the settings name are the keys that work: every name [keys] allows maps to
// one GLFW key, different names to different keys, each action to its configured key, and the operator's
// chord only with exactly its modifiers.
#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "config/keys.hpp"
#include "config/settings.hpp"
#include "kiosk/keymap.hpp"

namespace hk::app {
namespace {

TEST(Keymap, EveryAllowedKeyNameIsAKeyAndNoTwoNamesShareOne) {
  std::set<int> codes;
  for (std::string_view name : config::visitor_key_names()) {
    const int code = glfw_key(std::string(name));
    EXPECT_NE(code, GLFW_KEY_UNKNOWN) << name;
    EXPECT_TRUE(codes.insert(code).second) << name << " shares its key with another name";
  }
  // Independent spot checks against GLFW's own codes.
  EXPECT_EQ(glfw_key("F1"), GLFW_KEY_F1);
  EXPECT_EQ(glfw_key("F12"), GLFW_KEY_F12);
  EXPECT_EQ(glfw_key("PAGE_UP"), GLFW_KEY_PAGE_UP);
  EXPECT_EQ(glfw_key("KP_5"), GLFW_KEY_KP_5);
  EXPECT_EQ(glfw_key("Z"), GLFW_KEY_Z);
  EXPECT_EQ(glfw_key("O"), GLFW_KEY_O);
  EXPECT_EQ(glfw_key("ESCAPE"), GLFW_KEY_ESCAPE);
  EXPECT_EQ(glfw_key("F13"), GLFW_KEY_UNKNOWN);
  EXPECT_EQ(glfw_key("up"), GLFW_KEY_UNKNOWN);
}

TEST(Keymap, EachActionIsOnItsConfiguredKeyForEveryKeyName) {
  // Every name on every action (the other actions moved off it), as the operator could set them.
  const KioskKey actions[] = {KioskKey::Help,
                              KioskKey::Next,
                              KioskKey::Previous,
                              KioskKey::Describe,
                              KioskKey::Finer,
                              KioskKey::Coarser,
                              KioskKey::VolumeUp,
                              KioskKey::VolumeDown,
                              KioskKey::Tutorial,
                              KioskKey::Guide,
                              KioskKey::Capture,
                              KioskKey::Repeat,
                              KioskKey::Pause,
                              KioskKey::Where,
                              KioskKey::Finish,
                              KioskKey::NextSentence,
                              KioskKey::PreviousSentence,
                              KioskKey::NextParagraph,
                              KioskKey::PreviousParagraph,
                              KioskKey::Language,
                              KioskKey::Copy};
  static_assert(std::size(actions) == config::kKeyActionCount);
  for (int a = 0; a < static_cast<int>(config::kKeyActionCount); ++a) {
    for (std::string_view name : config::visitor_key_names()) {
      config::KeysSettings k;
      std::string* slot[] = {&k.help,
                             &k.next,
                             &k.previous,
                             &k.describe,
                             &k.finer,
                             &k.coarser,
                             &k.volume_up,
                             &k.volume_down,
                             &k.tutorial,
                             &k.guide,
                             &k.capture,
                             &k.repeat,
                             &k.pause,
                             &k.where,
                             &k.finish,
                             &k.next_sentence,
                             &k.previous_sentence,
                             &k.next_paragraph,
                             &k.previous_paragraph,
                             &k.language,
                             &k.copy};
      for (int b = 0; b < static_cast<int>(config::kKeyActionCount); ++b)
        if (b != a && *slot[b] == name) *slot[b] = *slot[a];  // swap: the set stays one key per action
      *slot[a] = std::string(name);
      const auto map = visitor_key_map(k);
      ASSERT_EQ(map.size(), config::kKeyActionCount) << name;
      const auto it = map.find(glfw_key(std::string(name)));
      ASSERT_NE(it, map.end()) << name;
      EXPECT_EQ(it->second, actions[a]) << name;
    }
  }
}

TEST(Keymap, TheChordNeedsExactlyItsModifiers) {
  const config::KeyChord c = *config::parse_chord("CTRL+ALT+O");
  EXPECT_TRUE(chord_pressed(c, GLFW_KEY_O, GLFW_MOD_CONTROL | GLFW_MOD_ALT));
  EXPECT_TRUE(chord_pressed(c, GLFW_KEY_O, GLFW_MOD_CONTROL | GLFW_MOD_ALT | GLFW_MOD_NUM_LOCK))
      << "Num Lock is not a modifier";
  EXPECT_FALSE(chord_pressed(c, GLFW_KEY_O, 0)) << "O alone is a key like any other";
  EXPECT_FALSE(chord_pressed(c, GLFW_KEY_O, GLFW_MOD_CONTROL));
  EXPECT_FALSE(chord_pressed(c, GLFW_KEY_O, GLFW_MOD_CONTROL | GLFW_MOD_ALT | GLFW_MOD_SHIFT));
  EXPECT_FALSE(chord_pressed(c, GLFW_KEY_P, GLFW_MOD_CONTROL | GLFW_MOD_ALT));
}

}  // namespace
}  // namespace hk::app

namespace hk::app {
namespace {

// A key that does nothing is spoken by its settings name's spoken form: the window finds that name from the
// key code, for every name the settings know, and for the operator's O, C and Escape.
TEST(Keymap, EveryKeyCodeFindsItsSettingsName) {
  for (std::string_view name : config::visitor_key_names()) EXPECT_EQ(key_name_of(glfw_key(std::string(name))), name);
  EXPECT_EQ(key_name_of(GLFW_KEY_O), "O");
  EXPECT_EQ(key_name_of(GLFW_KEY_C), "C");
  EXPECT_EQ(key_name_of(GLFW_KEY_ESCAPE), "ESCAPE");
  EXPECT_EQ(key_name_of(GLFW_KEY_PRINT_SCREEN), "") << "a key the settings do not name";
  EXPECT_EQ(key_name_of(GLFW_KEY_UNKNOWN), "");
}

}  // namespace
}  // namespace hk::app
