// Keys the visitor is told about are the keys that work: for every key name the settings
// allow and every action, the kiosk configured that way names that key for that action in its welcome, its
// help, its tutorial and its USB stick announcement; the operator's change (set_keys) is heard at once.
#include <gtest/gtest.h>

#include <cctype>

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "audio/messages.hpp"
#include "config/keys.hpp"
#include "config/load.hpp"
#include "config/settings.hpp"
#include "every_effect.hpp"
#include "test_paths.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {
namespace {

/// Records what is said (the captions show the last of it); the device and library are trivial.
struct Speech final : hk::test::EveryEffect {
  std::vector<std::string> said;
  void say(const std::string& t) override { said.push_back(t); }
  void show_tutorial(TutorialShape) override {}
  int show_picture(int) override { return 3; }
  int picture_count() const override { return 2; }
  std::string describe() override { return "3 shapes."; }
  bool change_level(int) override { return true; }
  bool change_volume(int) override { return true; }
  void new_session() override {}
  void show_document(int, int) override {}
  void forget_stick() override {}
  /// The caption the window shows: the last text said.
  const std::string& caption() const { return said.back(); }
};

/// One [keys] action: its name, its field, and the words of the English help that follow its key.
struct Action {
  std::string_view name;
  std::string config::KeysSettings::*field;
  std::string_view help_before;  ///< what the English help says just before the key
  std::string_view help_after;   ///< ... and just after it
};

constexpr std::array<Action, config::kKeyActionCount> kActions{{
    {"help", &config::KeysSettings::help, "Hold ", " and press another key to learn what it does."},
    {"next", &config::KeysSettings::next, "Press ", " for the next picture"},
    {"previous", &config::KeysSettings::previous, "and ", " for the one before."},
    {"describe", &config::KeysSettings::describe, "and ", " to hear what the picture holds."},
    {"finer", &config::KeysSettings::finer, "Press ", " for more detail"},
    {"coarser", &config::KeysSettings::coarser, "and ", " for less."},
    {"volume_up", &config::KeysSettings::volume_up, "Press ", " for louder"},
    {"volume_down", &config::KeysSettings::volume_down, "and ", " for quieter."},
    {"tutorial", &config::KeysSettings::tutorial, "Press ", " to practise with the shapes again"},
    {"guide", &config::KeysSettings::guide, "Press ", " to be led to a shape you have not touched yet."},
    {"capture", &config::KeysSettings::capture, "Press ", " to feel a picture of your own under the camera."},
    {"repeat", &config::KeysSettings::repeat, "Press ", " to hear the last message again"},
    {"pause", &config::KeysSettings::pause, "and ", " to pause the speech and go on."},
    {"where", &config::KeysSettings::where, "Press ", " to hear what is under your hand"},
    {"finish", &config::KeysSettings::finish, "and ", " when you have finished."},
    {"next_sentence", &config::KeysSettings::next_sentence, "press ", " or "},
    {"previous_sentence", &config::KeysSettings::previous_sentence, "or ", " to move by sentence"},
    {"next_paragraph", &config::KeysSettings::next_paragraph, "and ", " or "},
    {"previous_paragraph", &config::KeysSettings::previous_paragraph, "or ", " by paragraph."},
    {"language", &config::KeysSettings::language, ", ", " for another language,"},
    {"copy", &config::KeysSettings::copy, "Press ", " twice for a copy of the picture"},
}};

/// Every key's help as a visitor hears it: Help pressed (twice when `fresh`: the first layer, then every key),
/// then Next through its groups to the last ("That is every key."); the groups' texts joined.
std::string whole_help(KioskFlow& flow, Speech& fx, double now_s, std::string_view last = "That is every key.") {
  flow.key(KioskKey::Help, now_s);
  flow.key(KioskKey::Help, now_s + 0.1);
  std::string all;
  for (int g = 0; g < 12; ++g) {
    all += fx.caption() + " ";
    if (fx.caption().find(last) != std::string::npos || !flow.view().in_help) break;
    flow.key(KioskKey::Next, now_s + 0.2 + 0.1 * g);
  }
  return all;
}

/// The shipped keys with `action` on `name`; an action that had `name` moves to a key no action uses, so the
/// set stays valid (each action on its own key).
config::KeysSettings keys_with(const Action& action, std::string_view name) {
  config::KeysSettings k;
  for (const Action& other : kActions) {
    if (other.name == action.name || k.*other.field != name) continue;
    for (std::string_view free : config::visitor_key_names()) {
      bool used = free == name;
      for (const Action& a : kActions) used = used || k.*a.field == free;
      if (!used) {
        k.*other.field = std::string(free);
        break;
      }
    }
  }
  k.*action.field = std::string(name);
  return k;
}

/// The words no message may say any more: they named keys that were never configured.
void expect_no_stale_key_words(const std::string& said) {
  EXPECT_EQ(said.find("Plus and minus"), std::string::npos) << said;
  EXPECT_EQ(said.find("big key"), std::string::npos) << said;
  EXPECT_EQ(said.find("Arrow keys"), std::string::npos) << said;
  EXPECT_EQ(said.find('{'), std::string::npos) << "a placeholder left unfilled: " << said;
}

TEST(SpokenKeys, EnglishAndGermanHaveASpokenFormForEveryKeyName) {
  const audio::MessageCatalog& en = audio::MessageCatalog::english();
  const audio::MessageCatalog de = audio::MessageCatalog::load("de", audio::default_locale_dir());
  const auto names = config::visitor_key_names();
  for (std::string_view name : names) {
    EXPECT_EQ(en.key_names().count(name), 1u) << name << " has no spoken form in English";
    EXPECT_EQ(de.key_names().count(name), 1u) << name << " has no spoken form in German";
  }
  EXPECT_EQ(en.key_names().size(), names.size()) << "English names a key the settings do not allow";
  // Different keys sound different, so a visitor can tell which one is meant.
  for (std::size_t i = 0; i < names.size(); ++i) {
    for (std::size_t j = i + 1; j < names.size(); ++j) {
      EXPECT_NE(en.key_name(names[i]), en.key_name(names[j])) << names[i] << " and " << names[j];
      EXPECT_NE(de.key_name(names[i]), de.key_name(names[j])) << names[i] << " and " << names[j];
    }
  }
}

// Every action (19) x every key name (75), each a kiosk configured so, woken, asked for help twice (the
// first layer names the two most useful keys, the second every key).
TEST(SpokenKeys, EveryActionOnEveryKeyIsNamedInTheWelcomeHelpAndTutorial) {
  const audio::MessageCatalog& en = audio::MessageCatalog::english();
  const audio::MessageCatalog de = audio::MessageCatalog::load("de", audio::default_locale_dir());
  int cases = 0;
  for (const Action& action : kActions) {
    for (std::string_view name : config::visitor_key_names()) {
      SCOPED_TRACE("keys." + std::string(action.name) + " = \"" + std::string(name) + "\"");
      config::Settings s;
      s.keys = keys_with(action, name);
      ASSERT_NO_THROW(config::validate(s)) << "the test's key set must be one the operator could save";
      const std::string form = en.key_name(name);

      Speech fx;
      KioskFlowParams p;
      p.keys = s.keys;
      p.camera = true;  // the help names the Capture key too
      p.copies = true;  // and the Copy key
      KioskFlow flow(fx, en, p);
      flow.key(KioskKey::Other, 0.0);  // wakes: the welcome and the first tutorial shape
      ASSERT_EQ(fx.said.size(), 1u);
      const std::string welcome = fx.said.back();
      expect_no_stale_key_words(welcome);
      EXPECT_NE(welcome.find("Press " + en.key_name(s.keys.help) + " for help."), std::string::npos) << welcome;
      if (action.name == "help") {
        EXPECT_NE(welcome.find(form), std::string::npos) << welcome;
      }

      flow.key(KioskKey::Help, 1.0);
      const std::string brief = fx.caption();
      flow.key(KioskKey::Where, 1.05);  // leaves the first layer: the next Help starts it again
      expect_no_stale_key_words(brief);
      std::string help_form = en.key_name(s.keys.help);  // it starts a sentence
      help_form[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(help_form[0])));
      EXPECT_NE(brief.find("Press " + en.key_name(s.keys.next) + " to go on, " + en.key_name(s.keys.where) +
                           " for what is here. " + help_form + " again gives every key."),
                std::string::npos)
          << brief;
      const std::string help = whole_help(flow, fx, 1.5);
      ASSERT_TRUE(flow.view().in_help) << "on the last group: Next goes on from here";
      expect_no_stale_key_words(help);
      const std::string phrase = std::string(action.help_before) + form + std::string(action.help_after);
      EXPECT_NE(help.find(phrase), std::string::npos) << "wanted \"" << phrase << "\" in: " << help;
      for (const Action& other : kActions) {  // and every other action with its own key
        const std::string o =
            std::string(other.help_before) + en.key_name(s.keys.*other.field) + std::string(other.help_after);
        EXPECT_NE(help.find(o), std::string::npos) << "wanted \"" << o << "\" in: " << help;
      }

      // The tutorial says how to go on, with the keys that go on.
      flow.key(KioskKey::Next, 2.0);
      EXPECT_NE(fx.caption().find("Press " + en.key_name(s.keys.next) + " for the next shape."), std::string::npos)
          << fx.caption();
      flow.key(KioskKey::Next, 3.0);
      EXPECT_NE(fx.caption().find("Press " + en.key_name(s.keys.next) + " for the first picture."), std::string::npos)
          << fx.caption();
      flow.key(KioskKey::Next, 4.0);
      ASSERT_EQ(flow.view().state, KioskState::Picture);
      // A USB stick: "Press <next> to go through them."
      flow.stick_inserted({{"cat.png", false, 1, ""}}, 5.0);
      DocumentResult r;
      r.ok = true;
      r.description = "It has 3 shapes.";
      flow.document_ready(r, 5.1);
      EXPECT_NE(fx.caption().find("Press " + en.key_name(s.keys.next) + " to go through them."), std::string::npos)
          << fx.caption();
      for (const std::string& t : fx.said) expect_no_stale_key_words(t);

      // The German kiosk names the same key in its own words.
      Speech fx_de;
      KioskFlow flow_de(fx_de, de, p);
      flow_de.key(KioskKey::Other, 0.0);
      const std::string& last_de = de.raw(audio::MessageId::help_last);
      const std::string help_de = whole_help(flow_de, fx_de, 1.0, last_de.substr(0, last_de.find('.') + 1));
      EXPECT_NE(help_de.find(de.key_name(name)), std::string::npos) << help_de;
      EXPECT_EQ(help_de.find('{'), std::string::npos) << help_de;
      ++cases;
    }
  }
  EXPECT_EQ(cases, static_cast<int>(config::kKeyActionCount * config::visitor_key_names().size()));
}

TEST(SpokenKeys, KeyArgsPairEachPlaceholderWithItsAction) {
  config::KeysSettings k;
  const auto names = config::visitor_key_names();
  for (std::size_t i = 0; i < kActions.size(); ++i) k.*kActions[i].field = std::string(names[i]);
  const auto args = key_args(k);
  ASSERT_EQ(args.size(), kActions.size());
  for (std::size_t i = 0; i < kActions.size(); ++i) {
    EXPECT_EQ(args[i].first, std::string(kActions[i].name) + "_key");
    EXPECT_EQ(args[i].second, names[i]);
  }
}

TEST(SpokenKeys, TheOperatorsChangeIsHeardAtOnce) {
  const audio::MessageCatalog& en = audio::MessageCatalog::english();
  Speech fx;
  KioskFlow flow(fx, en);  // the shipped keys
  flow.key(KioskKey::Other, 0.0);
  for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 1.0 + i);
  ASSERT_EQ(flow.view().state, KioskState::Picture);
  const std::string help = whole_help(flow, fx, 5.0);  // the second layer: every key
  EXPECT_NE(help.find("Press the Up arrow for more detail and the Down arrow for less."), std::string::npos) << help;

  config::KeysSettings k;
  k.finer = "KP_ADD";
  k.coarser = "KP_SUBTRACT";
  k.help = "SPACE";
  const std::size_t before = fx.said.size();
  flow.set_keys(k);
  EXPECT_EQ(fx.said.size(), before) << "changing the keys says nothing by itself";
  EXPECT_EQ(flow.keys(), k);
  EXPECT_EQ(flow.view().state, KioskState::Picture) << "and leaves the visitor where they are";
  const std::string changed = whole_help(flow, fx, 6.0);
  EXPECT_NE(changed.find("Press keypad plus for more detail and keypad minus for less."), std::string::npos) << changed;
  EXPECT_NE(changed.find("Hold the space bar and press another key to learn what it does."), std::string::npos)
      << changed;
  EXPECT_EQ(changed.find("Up arrow"), std::string::npos) << "the old key is not named any more: " << changed;

  // A stick inserted before the change and announced after it names the new next key.
  flow.stick_inserted({{"a.png", false, 1, ""}}, 7.0);
  k.next = "ENTER";
  flow.set_keys(k);
  DocumentResult r;
  r.ok = true;
  r.description = "It has 3 shapes.";
  flow.document_ready(r, 7.2);
  EXPECT_NE(fx.caption().find("Press the Enter key to go through them."), std::string::npos) << fx.caption();

  // The next visitor hears the new help key in the welcome.
  flow.tick(7.2 + 1000.0);
  ASSERT_EQ(flow.view().state, KioskState::Attract);
  flow.handle_moved(2000.0);
  EXPECT_NE(fx.caption().find("Press the space bar for help."), std::string::npos) << fx.caption();
  flow.key(KioskKey::Help, 2001.0);
  EXPECT_NE(fx.caption().find("Press the Enter key to go on"), std::string::npos) << fx.caption();
}

}  // namespace
}  // namespace hk::app
