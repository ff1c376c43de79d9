// The visitor in charge (ADA §707, EN 301 549 §5, EZ Access): Repeat, Pause, Where, Finish, help in two
// layers, a stray key naming itself, learning mode, no time pressure while speech is heard or a shape is
// touched, Volume that never cuts speech, the spoken invitation in Attract, and one guard that keeps the
// kiosk as it was when an action fails. Driven through the flow with a recorder that keeps what a speaker
// would: the last text kept for Repeat, whether speech is heard, whether it is paused.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "every_effect.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {
namespace {

using audio::MessageId;

struct Speaker final : hk::test::EveryEffect {
  std::vector<std::string> said;  // every text, in order
  std::vector<bool> brief;        // said[i] was an acknowledgement (Repeat passes it over)
  std::string kept;               // what Repeat says again
  bool heard = false;             // speech is being heard (the test sets it)
  bool paused = false;
  bool quiet = false;  // quiet hours
  int volume = 7, sessions = 0, shown_pictures = 0, keys_acting = 0;
  bool fail_next_picture = false;  // show_picture throws once (a picture that cannot be built)
  std::string here = "Your hand is on shape 2 of 4, a small closed shape, on the left. It is on the left.";

  void say(const std::string& t) override {
    said.push_back(t);
    brief.push_back(false);
    kept = t;
    heard = true;
    paused = false;
  }
  void say_brief(const std::string& t) override {
    said.push_back(t);
    brief.push_back(true);
    heard = true;
    paused = false;
  }
  bool repeat() override {
    if (kept.empty()) return false;
    say(std::string(kept));
    return true;
  }
  bool speaking() const override { return heard && !paused; }
  bool pause_speech() override {
    if (!heard || paused) return false;
    paused = true;
    return true;
  }
  bool resume_speech() override {
    if (!paused) return false;
    paused = false;
    return true;
  }
  bool quiet_hours() const override { return quiet; }
  void show_tutorial(TutorialShape) override {}
  int show_picture(int) override {
    if (fail_next_picture) {
      fail_next_picture = false;
      throw std::runtime_error("picture 'x.png': 70000 x 70000 pixels is over the limit of 40000000");
    }
    ++shown_pictures;
    return 4;
  }
  int picture_count() const override { return 3; }
  std::string describe() override { return "4 shapes. Nearest your hand, a small closed shape on the left."; }
  std::string where() override { return here; }
  bool automatic = false;  // the level follows hand speed (Finer and Coarser turn it off)
  bool change_level(int) override {
    automatic = false;
    return true;
  }
  bool auto_level() const override { return automatic; }
  bool change_volume(int d) override {
    if (volume + d < 1 || volume + d > 10) return false;
    volume += d;
    return true;
  }
  void new_session() override {
    ++sessions;
    volume = 7;
    kept.clear();
    heard = paused = false;
  }
  void show_document(int, int) override {}
  void forget_stick() override {}
  void key_pressed() override { ++keys_acting; }
};

const audio::MessageCatalog& en() { return audio::MessageCatalog::english(); }

/// A flow woken and walked to picture 1 (0-based 0), the speech of the walk heard to its end.
struct Visit {
  Speaker fx;
  KioskFlow flow{fx, en(), KioskFlowParams{120.0, 20.0, 0.5, 30.0}};
  Visit() {
    flow.handle_moved(1.0);
    for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 2.0);
    fx.heard = false;
  }
  std::string text(MessageId id, std::initializer_list<audio::MessageArg> args = {}) const {
    return flow.text(id, args);
  }
};

TEST(VisitorInCharge, RepeatSaysTheLastMessageAgainAndPassesOverAcknowledgements) {
  Visit v;
  ASSERT_EQ(v.flow.view().state, KioskState::Picture);
  v.flow.key(KioskKey::Describe, 3.0);
  const std::string description = v.fx.said.back();
  v.flow.key(KioskKey::Finer, 4.0);  // "More detail." is an acknowledgement
  v.fx.heard = false;
  v.flow.key(KioskKey::VolumeUp, 5.0);  // quiet: "Louder."
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::volume_up));
  v.flow.key(KioskKey::Repeat, 6.0);
  EXPECT_EQ(v.fx.said.back(), description) << "Repeat says the description again, not the acknowledgements after it";
  v.flow.key(KioskKey::Repeat, 7.0);
  EXPECT_EQ(v.fx.said.back(), description) << "and again";
}

TEST(VisitorInCharge, RepeatBeforeAnythingWasSaidSaysSo) {
  Speaker fx;
  KioskFlow flow(fx, en());
  flow.handle_moved(1.0);  // the welcome
  fx.new_session();        // forgotten, as the speaker forgets at a new visitor
  flow.key(KioskKey::Repeat, 2.0);
  EXPECT_EQ(fx.said.back(), flow.text(MessageId::nothing_to_repeat));
}

TEST(VisitorInCharge, PauseHoldsTheSpeechAndPauseAgainGoesOn) {
  Visit v;
  v.flow.key(KioskKey::Describe, 3.0);
  const std::size_t before = v.fx.said.size();
  v.flow.key(KioskKey::Pause, 4.0);
  EXPECT_TRUE(v.fx.paused);
  EXPECT_EQ(v.fx.said.size(), before) << "silence is the answer to Pause";
  v.flow.key(KioskKey::Pause, 5.0);
  EXPECT_FALSE(v.fx.paused) << "pressed again, it goes on";
  EXPECT_EQ(v.fx.said.size(), before) << "going on is not a new message";
  v.fx.heard = false;  // the description ended
  v.flow.key(KioskKey::Pause, 6.0);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::nothing_to_pause));
}

TEST(VisitorInCharge, VolumeNeverCutsSpeech) {
  Visit v;
  v.flow.key(KioskKey::Describe, 3.0);
  const std::size_t before = v.fx.said.size();
  v.flow.key(KioskKey::VolumeUp, 4.0);
  v.flow.key(KioskKey::VolumeDown, 4.5);
  v.flow.key(KioskKey::VolumeDown, 5.0);
  EXPECT_EQ(v.fx.said.size(), before) << "while speech is heard, Volume changes it without a word";
  EXPECT_EQ(v.fx.volume, 6);
  EXPECT_EQ(v.fx.keys_acting, 4) << "Volume does not stop a tour either (3 Next and Describe did)";
}

TEST(VisitorInCharge, WhereSaysWhatIsUnderTheHand) {
  Visit v;
  v.flow.key(KioskKey::Where, 3.0);
  EXPECT_EQ(v.fx.said.back(), v.fx.here);
  v.fx.here.clear();  // nothing to say of the hand: where the visitor is
  v.flow.key(KioskKey::Where, 4.0);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::place_picture, {{"picture", "1"}, {"pictures", "3"}}));
}

TEST(VisitorInCharge, FinishPressedTwiceEndsTheVisit) {
  Visit v;
  v.flow.key(KioskKey::Next, 3.0);
  ASSERT_EQ(v.flow.view().picture, 1);
  v.flow.key(KioskKey::Finish, 4.0);
  EXPECT_EQ(v.flow.view().state, KioskState::Picture) << "one press only asks";
  EXPECT_EQ(v.fx.said.back(), "Press the End key again to finish your visit.");
  EXPECT_EQ(v.fx.sessions, 0);
  v.flow.key(KioskKey::Finish, 4.0 + KioskFlow::kFinishConfirm_s - 0.1);
  EXPECT_EQ(v.flow.view().state, KioskState::Attract);
  EXPECT_EQ(v.fx.sessions, 1) << "the operator's defaults again";
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::goodbye));
  // The next visitor starts from the beginning.
  v.flow.key(KioskKey::Next, 10.0);
  EXPECT_EQ(v.flow.view().state, KioskState::Tutorial);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::welcome));
  v.flow.key(KioskKey::Repeat, 11.0);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::welcome)) << "Repeat never reaches the last visitor's words";
}

TEST(VisitorInCharge, OneFinishByAccidentLosesNothing) {
  Visit v;
  v.flow.key(KioskKey::Next, 3.0);
  // Too late for a second press: it asks again.
  v.flow.key(KioskKey::Finish, 4.0);
  v.flow.key(KioskKey::Finish, 4.0 + KioskFlow::kFinishConfirm_s + 0.5);
  EXPECT_EQ(v.flow.view().state, KioskState::Picture);
  EXPECT_EQ(v.fx.said.back(), "Press the End key again to finish your visit.");
  // Another key in between: the next Finish asks again.
  v.flow.key(KioskKey::Where, 10.5);
  v.flow.key(KioskKey::Finish, 11.0);
  EXPECT_EQ(v.flow.view().state, KioskState::Picture);
  EXPECT_EQ(v.flow.view().picture, 1) << "the picture is still the one felt";
  EXPECT_EQ(v.fx.sessions, 0);
  // Volume (next to it on the keypad) neither finishes nor cancels the question.
  v.flow.key(KioskKey::VolumeDown, 11.5);
  v.flow.key(KioskKey::Finish, 12.0);
  EXPECT_EQ(v.flow.view().state, KioskState::Attract);
}

TEST(VisitorInCharge, FinerOrCoarserSaysOnceThatAutomaticDetailIsOffAndWhatBringsItBack) {
  Visit v;
  v.fx.automatic = true;
  v.flow.key(KioskKey::Finer, 3.0);
  EXPECT_EQ(v.fx.said.back(),
            "More detail. Automatic detail is off until you press the Right arrow or the Left arrow for another "
            "picture.");
  v.flow.key(KioskKey::Coarser, 4.0);
  EXPECT_EQ(v.fx.said.back(), "Less detail.") << "said once, while it is off";
}

TEST(VisitorInCharge, HelpComesInTwoLayers) {
  Visit v;
  v.flow.key(KioskKey::Help, 3.0);
  const std::string first = v.fx.said.back();
  EXPECT_EQ(first, v.text(MessageId::help_brief,
                          {{"place", v.text(MessageId::place_picture, {{"picture", "1"}, {"pictures", "3"}})}}));
  EXPECT_EQ(first.rfind("Picture 1 of 3. ", 0), 0u) << "where the visitor is: " << first;
  EXPECT_NE(first.find("the Right arrow"), std::string::npos) << first;
  EXPECT_NE(first.find("the W key"), std::string::npos) << "the two most useful keys: " << first;
  v.flow.key(KioskKey::Help, 4.0);
  // The same key again: every key, two sentences at a time, each key with where it lies on the keypad.
  const std::string group1 = v.fx.said.back();
  EXPECT_EQ(group1,
            "Move the handle slowly to feel the outlines. Press the Right arrow for the next picture and the Left "
            "arrow for the one "
            "before. The Right arrow is the right one of the four arrow keys, at the bottom right of the keyboard. The "
            "Left arrow is "
            "the left one of the four arrow keys, at the bottom right of the keyboard. Press the Right arrow for more "
            "help, the Left "
            "arrow to go back.");
  EXPECT_TRUE(v.flow.view().in_help);
  std::string every = group1;
  for (int g = 0; g < 10 && v.fx.said.back().find("That is every key.") == std::string::npos; ++g) {
    v.flow.key(KioskKey::Next, 4.1 + 0.1 * g);
    every += " " + v.fx.said.back();
  }
  EXPECT_EQ(v.flow.view().picture, 0) << "Next stepped through the help, not the pictures";
  for (const char* key : {"the W key", "the D key", "the R key", "the P key", "the Up arrow", "the Down arrow",
                          "Page Up", "Page Down", "the G key", "the T key", "the End key", "F1"}) {
    EXPECT_NE(every.find(key), std::string::npos) << key << " in: " << every;
  }
  EXPECT_NE(every.find("The End key is in the block of six keys above the arrow keys, the middle of its bottom row."),
            std::string::npos);
  v.flow.key(KioskKey::Previous, 5.5);
  EXPECT_EQ(v.flow.view().picture, 0) << "Previous goes back within the help";
  EXPECT_EQ(v.fx.said.back().rfind("Press the Up arrow for more detail", 0), std::string::npos);
  v.flow.key(KioskKey::Next, 5.6);  // back on the last group
  v.flow.key(KioskKey::Next, 5.7);  // past it: Next moves on again
  EXPECT_FALSE(v.flow.view().in_help);
  EXPECT_EQ(v.flow.view().picture, 1);
  v.flow.key(KioskKey::Previous, 5.8);
  EXPECT_EQ(v.flow.view().picture, 0);
  v.flow.key(KioskKey::Help, 5.9);
  v.flow.key(KioskKey::Help, 5.95);
  v.flow.key(KioskKey::Where, 5.97);  // any other key leaves the help
  EXPECT_FALSE(v.flow.view().in_help);
  v.flow.key(KioskKey::Help, 6.0);
  v.flow.key(KioskKey::Help, 6.05);
  v.flow.key(KioskKey::Help, 6.1);
  EXPECT_EQ(v.fx.said.back(), first) << "and again the first layer";
  v.flow.key(KioskKey::Next, 6.3);
  v.flow.key(KioskKey::Help, 7.0);
  EXPECT_EQ(v.fx.said.back().rfind("Picture 2 of 3.", 0), 0u)
      << "another key in between: the first layer, where the visitor is now";
}

TEST(VisitorInCharge, AStrayKeySaysItsNameNotTheWholeHelp) {
  Visit v;
  v.flow.key(KioskKey::Other, 3.0, "Q");
  EXPECT_EQ(v.fx.said.back(), "The Q key does nothing here. Press F1 for help.");
  v.flow.key(KioskKey::Other, 4.0, "O");  // no longer the operator's: a key like any other
  EXPECT_EQ(v.fx.said.back(), "That key does nothing here. Press F1 for help.")
      << "a key the catalogue has no spoken name for";
  EXPECT_EQ(v.flow.view().picture, 0);
}

TEST(VisitorInCharge, HoldingHelpNamesAKeyWithoutActing) {
  Visit v;
  v.flow.key(KioskKey::Help, 3.0);
  v.flow.help_held(true);
  const int acting = v.fx.keys_acting;
  v.flow.key(KioskKey::Next, 3.2);
  EXPECT_EQ(v.fx.said.back(),
            "The Right arrow: the next picture. The Right arrow is the right one of the four arrow keys, at the "
            "bottom right of the keyboard.");
  EXPECT_EQ(v.flow.view().picture, 0) << "named, not done";
  v.flow.key(KioskKey::Finish, 3.4);
  EXPECT_EQ(v.fx.said.back(),
            "The End key: finish, and leave the kiosk for the next visitor. The End key is in the block of six keys "
            "above the arrow keys, the middle of its bottom row.")
      << "named, what it does, and where it lies";
  EXPECT_EQ(v.flow.view().state, KioskState::Picture);
  v.flow.key(KioskKey::Other, 3.6, "Z");
  EXPECT_EQ(v.fx.said.back(), "The Z key does nothing here. Press F1 for help.");
  EXPECT_EQ(v.fx.keys_acting, acting) << "no key acted while Help was held";
  v.flow.help_held(false);
  v.flow.key(KioskKey::Next, 4.0);
  EXPECT_EQ(v.flow.view().picture, 1) << "let go: keys act again";
}

TEST(VisitorInCharge, TheTimeOutNeverCutsATextBeingRead) {
  Visit v;
  v.flow.key(KioskKey::Describe, 3.0);  // a long text: heard for 300 s
  for (double t = 3.0; t <= 303.0; t += 0.5) v.flow.tick(t);
  EXPECT_EQ(v.flow.view().state, KioskState::Picture) << "speech heard is activity";
  EXPECT_FALSE(v.flow.view().warned);
  v.fx.heard = false;  // the text ends at 303 s
  for (double t = 303.5; t < 303.0 + 100.0; t += 0.5) v.flow.tick(t);
  EXPECT_FALSE(v.flow.view().warned) << "the 120 s start when the reading ends";
  v.flow.tick(303.0 + 101.0);
  EXPECT_TRUE(v.flow.view().warned);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::timeout_warning, {{"seconds", "19"}}));
  EXPECT_NE(v.fx.said.back().find("Press any key for more time."), std::string::npos);
  EXPECT_NE(v.fx.said.back().find("this visit ends"), std::string::npos) << "what is at stake";
  // Said again 10 s later, with the seconds left then; the warning's own speech does not count: with nothing
  // done the visit ends.
  const std::size_t before = v.fx.said.size();
  for (double t = 404.5; t < 414.0; t += 0.5) v.flow.tick(t);
  EXPECT_EQ(v.fx.said.size(), before) << "nothing more within the 10 s";
  v.flow.tick(414.0);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::timeout_warning, {{"seconds", "9"}}));
  for (double t = 414.5; t <= 424.0; t += 0.5) v.flow.tick(t);
  EXPECT_EQ(v.flow.view().state, KioskState::Attract);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::goodbye));
}

TEST(VisitorInCharge, PausedSpeechAndTouchingAShape) {
  Visit v;
  v.flow.key(KioskKey::Describe, 3.0);
  v.flow.key(KioskKey::Pause, 4.0);  // paused: nobody is listening to it
  for (double t = 4.0; t < 104.0; t += 0.5) v.flow.tick(t);
  EXPECT_FALSE(v.flow.view().warned);
  v.flow.tick(104.5);
  EXPECT_TRUE(v.flow.view().warned) << "a paused text holds no one's session";
  // Sliding along a shape is activity (the window layer reports contact with motion): a hand feeling an
  // outline without moving 5 mm is there.
  for (double t = 105.0; t < 400.0; t += 0.5) {
    v.flow.touching(t);
    v.flow.tick(t);
  }
  EXPECT_EQ(v.flow.view().state, KioskState::Picture);
  EXPECT_FALSE(v.flow.view().warned);
}

TEST(VisitorInCharge, AnyKeyAfterTheWarningGivesMoreTime) {
  Visit v;
  v.flow.tick(103.0);  // 100 s idle since the walk: warned
  ASSERT_TRUE(v.flow.view().warned);
  v.flow.key(KioskKey::Repeat, 105.0);
  EXPECT_FALSE(v.flow.view().warned);
  v.fx.heard = false;  // what Repeat said is over at once
  for (double t = 105.0; t < 205.0; t += 1.0) v.flow.tick(t);
  EXPECT_EQ(v.flow.view().state, KioskState::Picture);
}

TEST(VisitorInCharge, AttractInvitesEveryIntervalButNotInQuietHours) {
  Speaker fx;
  KioskFlow flow(fx, en(), KioskFlowParams{120.0, 20.0, 0.5, 30.0});
  for (double t = 0.0; t < 30.0; t += 0.5) flow.tick(t);
  EXPECT_TRUE(fx.said.empty());
  flow.tick(30.0);
  ASSERT_EQ(fx.said.size(), 1u);
  EXPECT_EQ(fx.said[0], flow.text(MessageId::attract));
  for (double t = 30.5; t <= 90.0; t += 0.5) flow.tick(t);
  EXPECT_EQ(fx.said.size(), 3u) << "at 30, 60 and 90 s";
  fx.quiet = true;
  for (double t = 90.5; t < 200.0; t += 0.5) flow.tick(t);
  EXPECT_EQ(fx.said.size(), 3u) << "none in quiet hours";
  EXPECT_EQ(flow.view().state, KioskState::Attract) << "an invitation is not a visitor";
  KioskFlow off(fx, en(), KioskFlowParams{120.0, 20.0, 0.5, 0.0});
  fx.quiet = false;
  for (double t = 0.0; t < 200.0; t += 0.5) off.tick(t);
  EXPECT_EQ(fx.said.size(), 3u) << "attract_every_s = 0: never";
}

// The tutorial teaches: touching the square (once the welcome is heard) says that its wall can be pushed
// through, once; Finer and Coarser on a practice shape say why they do nothing there.
TEST(VisitorInCharge, TheTutorialTeachesPushingThroughAndSaysWhyLevelsDoNothing) {
  Speaker fx;
  KioskFlow flow(fx, en(), KioskFlowParams{120.0, 20.0, 0.5, 30.0});
  flow.handle_moved(1.0);
  ASSERT_EQ(flow.view().state, KioskState::Tutorial);
  const std::size_t welcome = fx.said.size();
  flow.touching(1.5);
  EXPECT_EQ(fx.said.size(), welcome) << "never over the welcome";
  fx.heard = false;  // the welcome is over
  flow.touching(2.0);
  EXPECT_EQ(fx.said.back(), "That is the square's wall. Push hard on it to pass through.");
  fx.heard = false;
  flow.touching(3.0);
  EXPECT_EQ(fx.said.size(), welcome + 1) << "said once";
  flow.key(KioskKey::Finer, 4.0);
  EXPECT_EQ(fx.said.back(),
            "A practice shape has one level of detail. The Up arrow and the Down arrow work on the pictures.");
  flow.key(KioskKey::Coarser, 5.0);
  EXPECT_EQ(fx.said.back(),
            "A practice shape has one level of detail. The Up arrow and the Down arrow work on the pictures.");
  flow.key(KioskKey::Next, 6.0);
  fx.heard = false;
  flow.touching(7.0);
  EXPECT_EQ(fx.said.back().rfind("A circle.", 0), 0u) << "only on the square";
}

TEST(VisitorInCharge, TheWelcomeIsShortAndPutsAShapeUnderTheHand) {
  Speaker fx;
  KioskFlow flow(fx, en());
  flow.key(KioskKey::Describe, 1.0);
  ASSERT_EQ(fx.said.size(), 1u);
  EXPECT_EQ(fx.said[0],
            "Welcome. Feel the square with the handle. Press the Right arrow to move on. Press F1 for help.");
  EXPECT_EQ(flow.view().state, KioskState::Tutorial);
}

TEST(VisitorInCharge, AFailedActionLeavesTheKioskAsItWasWithOneSorryLine) {
  Visit v;
  v.flow.key(KioskKey::Next, 3.0);
  ASSERT_EQ(v.flow.view().picture, 1);
  v.fx.fail_next_picture = true;
  v.flow.key(KioskKey::Next, 4.0);
  EXPECT_EQ(v.flow.view().picture, 1) << "the picture felt before stays, and the flow knows it";
  EXPECT_EQ(v.flow.view().state, KioskState::Picture);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::sorry));
  EXPECT_EQ(v.flow.view().failures, 1);
  v.flow.key(KioskKey::Next, 5.0);
  EXPECT_EQ(v.flow.view().picture, 2) << "and goes on from there";
}

}  // namespace
}  // namespace hk::app
