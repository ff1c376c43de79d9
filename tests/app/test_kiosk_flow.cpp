// The visitor's walk through the kiosk, driven by scripted keys and handle motion, checked by what the
// kiosk says (attract → tutorial → picture → next picture → time-out → attract), and the
// spoken description of a picture.
#include <gtest/gtest.h>

#include <string>
#include <tuple>
#include <vector>

#include "audio/speech.hpp"
#include "every_effect.hpp"
#include "test_polylines.hpp"
#include "visit/answers.hpp"
#include "visit/describe.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {
namespace {

struct Recorder final : hk::test::EveryEffect {
  std::vector<std::string> said;
  std::vector<std::string> shown;
  int level = 1, volume = 7, sessions = 0;
  void say(const std::string& t) override { said.push_back(t); }
  void show_tutorial(TutorialShape s) override { shown.push_back("tutorial " + std::to_string(static_cast<int>(s))); }
  int show_picture(int i) override {
    shown.push_back("picture " + std::to_string(i));
    return i == 1 ? 1 : 4;
  }
  int picture_count() const override { return 3; }
  std::string describe() override { return "4 shapes. A large closed shape in the middle."; }
  bool change_level(int d) override {
    if (level + d < 0 || level + d > 3) return false;
    level += d;
    return true;
  }
  bool change_volume(int d) override {
    if (volume + d < 1 || volume + d > 10) return false;
    volume += d;
    return true;
  }
  void new_session() override {
    ++sessions;
    level = 1;
    volume = 7;
  }
  std::vector<std::pair<int, int>> requested;  // show_document calls (document, page)
  int forgotten = 0;
  void show_document(int d, int p) override {
    requested.emplace_back(d, p);
    shown.push_back("document " + std::to_string(d) + " page " + std::to_string(p));
  }
  void forget_stick() override { ++forgotten; }
  PictureNotes notes;  // what shown_notes() gives
  PictureNotes shown_notes() const override { return notes; }
};

DocumentResult ready(int d, int p, std::string description = "It has 2 blocks of text and one figure.") {
  DocumentResult r;
  r.document = d;
  r.page = p;
  r.ok = true;
  r.description = std::move(description);
  return r;
}

TEST(KioskFlow, AttractTutorialPicturesTimeoutAndBack) {
  Recorder fx;
  const auto& en = audio::MessageCatalog::english();
  KioskFlow flow(fx, en, {120.0, 20.0});
  flow.tick(10.0);
  EXPECT_EQ(flow.view().state, KioskState::Attract);
  EXPECT_TRUE(fx.said.empty()) << "attract is silent until someone comes";

  flow.handle_moved(11.0);
  EXPECT_EQ(flow.view().state, KioskState::Tutorial);
  ASSERT_EQ(fx.said.size(), 1u);
  EXPECT_EQ(fx.said.back().rfind("Welcome.", 0), 0u);
  EXPECT_NE(fx.said.back().find("Feel the square with the handle. Press the Right arrow to move on."),
            std::string::npos)
      << "the welcome names the key that moves on";
  EXPECT_NE(fx.said.back().find("Press F1 for help."), std::string::npos) << "the shipped help key";
  EXPECT_EQ(fx.shown.back(), "tutorial 0");

  flow.key(KioskKey::Next, 20.0);
  EXPECT_EQ(fx.said.back(),
            "A circle. Press the W key to hear where your hand is. Press the Right arrow for the next shape.")
      << "the circle practises Where";
  EXPECT_EQ(fx.said.back(), flow.text(audio::MessageId::tutorial_circle));
  EXPECT_EQ(fx.shown.back(), "tutorial 1");
  flow.key(KioskKey::Next, 30.0);
  EXPECT_EQ(fx.said.back(),
            "A triangle. Press the G key to be led round it. Press the Right arrow for the first picture.");
  flow.key(KioskKey::Next, 40.0);
  EXPECT_EQ(flow.view().state, KioskState::Picture);
  EXPECT_EQ(
      fx.said.back(),
      "Well done. Press the D key to hear about a picture, the R key to hear it again. Here is the first picture. "
      "Picture 1 of 3. It has 4 shapes.");
  EXPECT_EQ(fx.shown.back(), "picture 0");

  flow.key(KioskKey::Next, 50.0);
  EXPECT_EQ(fx.said.back(), "Picture 2 of 3. It has one shape.");
  flow.key(KioskKey::Previous, 51.0);
  flow.key(KioskKey::Previous, 52.0);
  EXPECT_EQ(fx.said.back(), "Picture 3 of 3. It has 4 shapes.") << "previous wraps round";
  flow.key(KioskKey::Describe, 53.0);
  EXPECT_EQ(fx.said.back(), "4 shapes. A large closed shape in the middle.");
  flow.key(KioskKey::Help, 53.5);
  flow.key(KioskKey::Help, 53.6);  // the second layer: every key, two sentences at a time, Next for more
  std::string every = fx.said.back();
  for (int g = 0; g < 6 && flow.view().in_help && fx.said.back().find("That is every key.") == std::string::npos; ++g) {
    flow.key(KioskKey::Next, 53.7 + 0.01 * g);
    every += " " + fx.said.back();
  }
  for (const char* sentence :
       {"Move the handle slowly to feel the outlines.",
        "Press the Right arrow for the next picture and the Left arrow for the one before.",
        "Press the W key to hear what is under your hand, and the D key to hear what the picture holds.",
        "Press the R key to hear the last message again, and the P key to pause the speech and go on.",
        "Press the Up arrow for more detail and the Down arrow for less.",
        "Press Page Up for louder and Page Down for quieter.",
        "Press the G key to be led to a shape you have not touched yet.",
        "Press the T key to practise with the shapes again, the L key for another language, and the End key when you "
        "have finished.",
        "Hold F1 and press another key to learn what it does."}) {
    EXPECT_NE(every.find(sentence), std::string::npos) << "the help names the shipped keys: " << sentence;
  }
  flow.key(KioskKey::Where, 53.9);  // leaves the help
  flow.key(KioskKey::Finer, 54.0);
  EXPECT_EQ(fx.said.back(), "More detail.");
  flow.key(KioskKey::Finer, 55.0);
  EXPECT_EQ(fx.said.back(), "This is the finest detail.");
  flow.key(KioskKey::VolumeUp, 56.0);
  EXPECT_EQ(fx.said.back(), "Louder.");
  EXPECT_EQ(fx.volume, 8);

  // Quiet for 100 s: the warning, 20 s before the end. A key extends the time.
  const std::size_t before = fx.said.size();
  flow.tick(155.0);
  EXPECT_EQ(fx.said.size(), before) << "no warning before timeout - warning";
  flow.tick(156.0);
  ASSERT_EQ(fx.said.size(), before + 1);
  EXPECT_NE(fx.said.back().find("In 20 seconds"), std::string::npos) << fx.said.back();
  flow.tick(157.0);
  EXPECT_EQ(fx.said.size(), before + 1) << "warned once";
  flow.handle_moved(160.0);
  flow.tick(200.0);
  EXPECT_EQ(flow.view().state, KioskState::Picture) << "the motion extended the session";
  flow.tick(280.0);
  EXPECT_EQ(flow.view().state, KioskState::Attract);
  EXPECT_EQ(fx.said.back(), en.raw(audio::MessageId::goodbye));
  EXPECT_EQ(fx.sessions, 1);
  EXPECT_EQ(fx.volume, 7) << "the operator's default again";

  // The next visitor starts with the tutorial again.
  flow.key(KioskKey::Other, 300.0);
  EXPECT_EQ(flow.view().state, KioskState::Tutorial);
}

TEST(KioskFlow, EveryKeyIsAnsweredInSpeech) {
  Recorder fx;
  KioskFlow flow(fx, audio::MessageCatalog::english());
  flow.key(KioskKey::Other, 0.0);  // wake
  double t = 1.0;
  for (KioskState want : {KioskState::Tutorial, KioskState::Picture}) {
    if (want == KioskState::Picture) {
      for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, t++);
    }
    ASSERT_EQ(flow.view().state, want);
    for (KioskKey k : {KioskKey::Help, KioskKey::Describe, KioskKey::Finer, KioskKey::Coarser, KioskKey::VolumeUp,
                       KioskKey::VolumeDown, KioskKey::Other}) {
      const std::size_t n = fx.said.size();
      flow.key(k, t++);
      EXPECT_EQ(fx.said.size(), n + 1) << "key " << static_cast<int>(k) << " in state " << static_cast<int>(want);
    }
  }
}

// A PDF with a title of its own is named by it, in what is said and when a page fails.
TEST(KioskFlow, APdfIsNamedByItsOwnTitle) {
  Recorder fx;
  KioskFlow flow(fx, audio::MessageCatalog::english(), {120.0, 20.0});
  flow.stick_inserted({{"ring.pdf", true, 2, "A ring, drawn for the hand"}}, 1.0);
  flow.document_ready(ready(0, 1, "It has one figure."), 1.1);
  EXPECT_NE(fx.said.back().find("Page 1 of 2 of A ring, drawn for the hand. It has one figure."), std::string::npos)
      << fx.said.back();
  EXPECT_EQ(fx.said.back().find("ring.pdf"), std::string::npos) << fx.said.back();
  flow.key(KioskKey::Next, 2.0);
  DocumentResult bad;
  bad.document = 0;
  bad.page = 2;
  bad.reason = "it took longer than 5 s to draw";
  flow.document_ready(bad, 2.1);
  EXPECT_EQ(fx.said.back().rfind("Page 2 of A ring, drawn for the hand cannot be read", 0), 0u) << fx.said.back();
}

// A stick inserted, browsed, a page that cannot be read, a load superseded, the stick
// taken out mid-load and inserted again, and a new visitor who does not inherit it.
TEST(KioskFlow, UsbStickInsertBrowseRemoveInsertAgain) {
  Recorder fx;
  const auto& en = audio::MessageCatalog::english();
  KioskFlow flow(fx, en, {120.0, 20.0});
  const std::vector<StickEntry> stick{
      {"cat.png", false, 1, ""}, {"report.pdf", true, 3, ""}, {"dog.jpg", false, 1, ""}};

  flow.stick_inserted(stick, 1.0);
  EXPECT_EQ(flow.view().state, KioskState::Picture) << "a stick wakes the kiosk";
  EXPECT_EQ(flow.view().source, KioskSource::Stick);
  ASSERT_EQ(fx.requested.size(), 1u);
  EXPECT_EQ(fx.requested.back(), std::make_pair(0, 1)) << "the first page is loaded at once";
  EXPECT_TRUE(fx.said.empty()) << "the summary waits for the first page, so one announcement says both";
  flow.tick(1.4);
  EXPECT_TRUE(fx.said.empty()) << "no loading cue within 0.5 s";
  flow.tick(1.6);
  ASSERT_EQ(fx.said.size(), 1u);
  EXPECT_EQ(fx.said.back(), "Loading.");
  flow.tick(1.7);
  EXPECT_EQ(fx.said.size(), 1u) << "said once per load";
  flow.document_ready(ready(0, 1, "It has 4 shapes."), 2.0);
  EXPECT_EQ(fx.said.back(),
            "A USB stick with 3 documents: 2 pictures and a PDF of 3 pages. Press the Right arrow to go through them. "
            "Document 1 of 3, cat. It has 4 shapes.");
  EXPECT_EQ(flow.view().document, 0);

  flow.key(KioskKey::Next, 3.0);
  EXPECT_EQ(fx.requested.back(), std::make_pair(1, 1));
  flow.document_ready(ready(1, 1), 3.1);
  EXPECT_EQ(fx.said.back(), "Page 1 of 3 of report. It has 2 blocks of text and one figure.");
  flow.key(KioskKey::Next, 4.0);
  EXPECT_EQ(fx.requested.back(), std::make_pair(1, 2)) << "Next walks the pages of a PDF";
  // A page the worker cannot draw: reported, the page felt before stays.
  DocumentResult bad;
  bad.document = 1;
  bad.page = 2;
  bad.reason = "the reader stopped on page 2 (signal 11)";
  flow.document_ready(bad, 4.2);
  EXPECT_EQ(fx.said.back(), "Page 2 of report cannot be read. You still feel the picture before.");
  EXPECT_EQ(flow.view().document, 1);
  EXPECT_EQ(flow.view().page, 1) << "the page shown is still page 1";
  // Next moves on from the unreadable page; a second press while loading moves on from the first; the
  // first's late result is ignored.
  flow.key(KioskKey::Next, 5.0);
  EXPECT_EQ(fx.requested.back(), std::make_pair(1, 3)) << "past the unreadable page";
  flow.key(KioskKey::Next, 5.1);
  EXPECT_EQ(fx.requested.back(), std::make_pair(2, 1)) << "page 3 is the last: on to the next document";
  const std::size_t said = fx.said.size();
  flow.document_ready(ready(1, 3), 5.2);
  EXPECT_EQ(fx.said.size(), said) << "a superseded load says nothing";
  flow.document_ready(ready(2, 1, "It has one shape."), 5.3);
  EXPECT_EQ(fx.said.back(), "Document 3 of 3, dog. It has one shape.");
  flow.key(KioskKey::Next, 6.0);
  EXPECT_EQ(fx.requested.back(), std::make_pair(0, 1)) << "wraps round to the first document";
  flow.key(KioskKey::Previous, 6.1);
  EXPECT_EQ(fx.requested.back(), std::make_pair(2, 1)) << "previous from the one awaited";
  flow.key(KioskKey::Previous, 6.2);
  EXPECT_EQ(fx.requested.back(), std::make_pair(1, 3)) << "previous goes to the last page of a PDF";

  // Taken out mid-load: back to the library picture, and the late result is ignored.
  flow.stick_removed(7.0);
  EXPECT_EQ(flow.view().source, KioskSource::Library);
  EXPECT_EQ(fx.said.back(),
            "The USB stick was taken out. Back to the picture library. Picture 1 of 3. It has 4 shapes.");
  EXPECT_EQ(fx.shown.back(), "picture 0");
  flow.document_ready(ready(1, 3), 7.5);
  EXPECT_EQ(fx.shown.back(), "picture 0");
  flow.key(KioskKey::Next, 8.0);
  EXPECT_EQ(fx.shown.back(), "picture 1") << "Next walks the library again";

  // Inserted again: a fresh listing from its first page.
  flow.stick_inserted({{"only.pdf", true, 1, ""}}, 9.0);
  EXPECT_EQ(fx.requested.back(), std::make_pair(0, 1));
  flow.document_ready(ready(0, 1, "It has no text and one figure."), 9.1);
  EXPECT_EQ(fx.said.back(),
            "A USB stick with one document: a PDF of one page. Press the Right arrow to go through them. Page 1 of 1 "
            "of only. It has no text and one figure.");

  // The visitor leaves; the next one does not get the stick.
  flow.tick(9.1 + 120.0);
  EXPECT_EQ(flow.view().state, KioskState::Attract);
  EXPECT_EQ(fx.forgotten, 1);
  EXPECT_EQ(flow.view().source, KioskSource::Library);
  flow.key(KioskKey::Other, 300.0);
  EXPECT_EQ(flow.view().state, KioskState::Tutorial);
}

// A stick put in while the kiosk waits, its first file unreadable: nothing was felt before, so nothing
// "still" is; a PDF over the page cap is counted as it is and said to be readable in part; a 254-byte file
// name is said shortened, without its extension.
TEST(KioskFlow, StickNamesPageCountsAndNothingFeltBefore) {
  Recorder fx;
  KioskFlow flow(fx, audio::MessageCatalog::english(), {120.0, 20.0});
  const std::string long_name =
      std::string("minutes_of_the_annual_general_meeting_of_the_society_") + std::string(197, 'x') + ".pdf";
  ASSERT_EQ(long_name.size(), 254u);
  flow.stick_inserted({{"bad_crc.png", false, 1, ""}, {"atlas.pdf", true, 1000, "", 5000}, {long_name, true, 2, ""}},
                      1.0);
  DocumentResult bad;
  bad.document = 0;
  bad.page = 1;
  bad.reason = "it is damaged";
  flow.document_ready(bad, 1.1);
  EXPECT_EQ(fx.said.back(),
            "A USB stick with 3 documents: a picture and 2 PDFs of 5002 pages in all (the first 1000 pages of each can "
            "be read). "
            "Press the Right arrow to go through them. bad crc cannot be read.")
      << "no picture was felt before";
  flow.key(KioskKey::Next, 2.0);
  flow.document_ready(ready(1, 1), 2.1);
  EXPECT_EQ(fx.said.back(), "Page 1 of 5000 of atlas. It has 2 blocks of text and one figure.");
  flow.key(KioskKey::Previous, 3.0);
  EXPECT_EQ(fx.requested.back(), std::make_pair(0, 1));
  flow.key(KioskKey::Previous, 3.1);
  EXPECT_EQ(fx.requested.back(), std::make_pair(2, 2)) << "the third document's last page";
  flow.document_ready(ready(2, 2), 3.2);
  EXPECT_EQ(
      fx.said.back(),
      "Page 2 of 2 of minutes of the annual general meeting of the society. It has 2 blocks of text and one figure.");
  flow.key(KioskKey::Next, 4.0);
  EXPECT_EQ(fx.requested.back(), std::make_pair(0, 1));
  flow.document_ready(bad, 4.1);
  EXPECT_EQ(fx.said.back(), "bad crc cannot be read. You still feel the picture before.") << "now there was one";
}

// What cannot be read is one short line after what the stick holds, counted; never file by file.
TEST(KioskFlow, UnreadableFilesOfAStickAreOneCountedLine) {
  Recorder fx;
  KioskFlow flow(fx, audio::MessageCatalog::english(), {120.0, 20.0});
  flow.stick_inserted({{"cat.png", false, 1, ""}}, 1.0, 2);
  flow.document_ready(ready(0, 1, "It has 4 shapes."), 1.1);
  EXPECT_EQ(
      fx.said.back(),
      "A USB stick with one document: a picture. Press the Right arrow to go through them. 2 files cannot be read. "
      "Document 1 of 1, cat. It has 4 shapes.");
  flow.stick_removed(2.0);
  flow.stick_inserted({}, 3.0, 1);
  EXPECT_EQ(fx.said.back(), "I found no pictures and no PDF documents on this USB stick. One file cannot be read.");
  flow.stick_inserted({{"cat.png", false, 1, ""}}, 4.0);
  flow.document_ready(ready(0, 1, "It has 4 shapes."), 4.1);
  EXPECT_EQ(fx.said.back().find("cannot be read"), std::string::npos) << fx.said.back();
}

// An empty stick put in during the tutorial leaves the visitor on the practice shape: Help says so, and Next
// goes on with the tutorial, not to a picture.
TEST(KioskFlow, AnEmptyStickDuringTheTutorialLeavesTheTutorialAsItWas) {
  Recorder fx;
  KioskFlow flow(fx, audio::MessageCatalog::english(), {120.0, 20.0});
  flow.key(KioskKey::Other, 0.0);
  ASSERT_EQ(flow.view().state, KioskState::Tutorial);
  flow.stick_inserted({}, 1.0, 0);
  EXPECT_EQ(fx.said.back(), "I found no pictures and no PDF documents on this USB stick.");
  EXPECT_EQ(flow.view().state, KioskState::Tutorial);
  flow.key(KioskKey::Help, 2.0);
  EXPECT_EQ(fx.said.back().rfind("Practising with a shape.", 0), 0u) << fx.said.back();
  flow.key(KioskKey::Next, 3.0);
  EXPECT_EQ(fx.shown.back(), "tutorial 1") << "Next goes on to the circle";
  // In Attract, an empty stick wakes the kiosk into the tutorial, as any visitor's first act does.
  Recorder fx2;
  KioskFlow waiting(fx2, audio::MessageCatalog::english(), {120.0, 20.0});
  waiting.stick_inserted({}, 1.0, 0);
  EXPECT_EQ(waiting.view().state, KioskState::Tutorial);
  EXPECT_EQ(fx2.shown.back(), "tutorial 0");
  EXPECT_EQ(fx2.said.back(),
            "I found no pictures and no PDF documents on this USB stick. Welcome. Feel the square with the handle. "
            "Press the Right arrow to move on. Press F1 for help.");
  // A stick that cannot be read at all, likewise.
  Recorder fx3;
  KioskFlow refused(fx3, audio::MessageCatalog::english(), {120.0, 20.0});
  refused.stick_refused("its filesystem (btrfs) is not one the kiosk reads", 1.0);
  EXPECT_EQ(refused.view().state, KioskState::Tutorial);
  EXPECT_EQ(fx3.said.back(),
            "I cannot read this USB stick. its filesystem (btrfs) is not one the kiosk reads. Welcome. Feel the square "
            "with the handle. Press the Right arrow to move on. Press F1 for help.");
}

TEST(KioskFlow, SpokenNamesAreShortWholeWordsAndWholeCharacters) {
  EXPECT_EQ(spoken_name("holiday-photo_2025.JPG", true), "holiday photo 2025");
  EXPECT_EQ(spoken_name("notes.v2.pdf", true), "notes.v2");
  EXPECT_EQ(spoken_name(std::string(80, 'a'), false).size(), kSpokenNameBytes);
  // 45 two-byte letters after one one-byte letter: cut at a character, never inside one.
  std::string umlauts = "a";
  for (int i = 0; i < 45; ++i) umlauts += "\xc3\xa4";
  const std::string cut = spoken_name(umlauts, false);
  EXPECT_EQ(cut.size(), kSpokenNameBytes - 1);
  EXPECT_EQ(cut.size() % 2, 1u);
  EXPECT_EQ(spoken_name("A ring, drawn for the hand", false), "A ring, drawn for the hand");
}

TEST(KioskFlow, SpokenSecondsCountWordsAtTheVoicesRate) {
  std::string text;
  for (int i = 0; i < 330; ++i) text += "word\t \n";
  EXPECT_DOUBLE_EQ(spoken_seconds(text), 120.0);  // 330 words at 165 a minute
  EXPECT_DOUBLE_EQ(spoken_seconds("  "), 0.0);
  EXPECT_DOUBLE_EQ(spoken_seconds("one"), 60.0 / 165.0);
}

TEST(KioskFlow, EmptyAndRefusedSticksAreSaidAndChangeNothing) {
  Recorder fx;
  KioskFlow flow(fx, audio::MessageCatalog::english(), {120.0, 20.0});
  flow.key(KioskKey::Other, 0.0);
  for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 1.0);
  ASSERT_EQ(flow.view().state, KioskState::Picture);
  flow.stick_inserted({}, 2.0);
  EXPECT_EQ(fx.said.back(), "I found no pictures and no PDF documents on this USB stick.");
  EXPECT_EQ(flow.view().source, KioskSource::Library);
  EXPECT_TRUE(fx.requested.empty());
  flow.stick_refused("its filesystem (btrfs) is not one the kiosk reads", 3.0);
  EXPECT_EQ(fx.said.back(), "I cannot read this USB stick. its filesystem (btrfs) is not one the kiosk reads");
  flow.key(KioskKey::Next, 4.0);
  EXPECT_EQ(fx.shown.back(), "picture 1") << "the library is still what Next walks";
}

TEST(KioskFlow, APictureWithATitleIsAnnouncedByIt) {
  Recorder fx;
  fx.notes.title = "a horse, seen from the side";
  KioskFlow flow(fx, audio::MessageCatalog::english(), {120.0, 20.0});
  flow.handle_moved(1.0);
  for (int k = 0; k < 3; ++k) flow.key(KioskKey::Next, 2.0 + k);  // square, circle, triangle, then pictures
  EXPECT_EQ(fx.shown.back(), "picture 0");
  EXPECT_EQ(
      fx.said.back(),
      "Well done. Press the D key to hear about a picture, the R key to hear it again. Here is the first picture. "
      "Picture 1 of 3: a horse, seen from the side. It has 4 shapes.");
  flow.key(KioskKey::Next, 10.0);
  EXPECT_EQ(fx.said.back(), "Picture 2 of 3: a horse, seen from the side. It has one shape.");
  fx.notes = {};
  flow.key(KioskKey::Next, 11.0);
  EXPECT_EQ(fx.said.back(), "Picture 3 of 3. It has 4 shapes.") << "no title: as before";
}

TEST(Describe, PagesCountTextBlocksAndFigures) {
  EXPECT_EQ(describe_page(2, 1), "It has 2 blocks of text and one figure.");
  EXPECT_EQ(describe_page(1, 0), "It has one block of text and no figures.");
  EXPECT_EQ(describe_page(0, 3), "It has no text and 3 figures.");
  EXPECT_EQ(describe_shapes(0), "I found no shapes in it.");
  EXPECT_EQ(describe_shapes(1), "It has one shape.");
  EXPECT_EQ(describe_shapes(5), "It has 5 shapes.");
}

using test::rect;

TEST(Describe, FiguresAreGroupsOfTouchingCurves) {
  // A drawing of three strokes that touch (one figure), a separate box (a second), a stroke 1 mm from the
  // box (within the 2 mm margin: the same figure), a dot far away (a third).
  const std::vector<Polyline> curves{rect({-0.03, 0}, {0.01, 0.01}),
                                     rect({-0.02, 0}, {0.01, 0.002}, false),
                                     rect({-0.01, 0.005}, {0.002, 0.01}, false),
                                     rect({0.03, 0}, {0.005, 0.005}),
                                     rect({0.0365, 0}, {0.0005, 0.004}, false),
                                     rect({0.06, -0.04}, {0.001, 0.001})};
  EXPECT_EQ(count_figures(curves), 3);
  EXPECT_EQ(count_figures(curves, 0.0), 4) << "without the margin the stroke beside the box stands alone";
  EXPECT_EQ(count_figures({}), 0);
}

}  // namespace
}  // namespace hk::app

namespace hk::app {
namespace {
using audio::MessageId;

/// A visit as heard in one language: the flow's catalogue is `current`, which set_language swaps, as the audio
/// system does; each picture has the shapes of kShapes, and Describe says a drawn scene in the visit's language.
struct LanguageRecorder final : hk::test::EveryEffect {
  std::vector<audio::MessageCatalog> catalogues;
  audio::MessageCatalog current = audio::MessageCatalog::english();
  int in_use = 0;
  std::vector<std::string> said;
  static constexpr int kShapes[] = {0, 1, 2, 5};
  void say(const std::string& t) override { said.push_back(t); }
  void show_tutorial(TutorialShape) override {}
  int show_picture(int i) override { return kShapes[i]; }
  int picture_count() const override { return 4; }
  std::string describe() override {
    Polyline square{{{-0.02, -0.02}, {0.02, -0.02}, {0.02, 0.02}, {-0.02, 0.02}}, true};
    Polyline dot{{{0.05, 0.03}, {0.056, 0.03}, {0.056, 0.036}, {0.05, 0.036}}, true};
    return notes_words(notes) + describe_scene({square, dot}, {}, {0.08, 0.06}, 3, std::nullopt, nullptr, current);
  }
  PictureNotes notes;  // what staff wrote of the picture shown, in notes.language
  PictureNotes shown_notes() const override { return notes; }
  bool change_level(int) override { return true; }
  bool change_volume(int) override { return true; }
  void new_session() override {}
  void show_document(int, int) override {}
  void forget_stick() override {}
  int language_count() const override { return static_cast<int>(catalogues.size()); }
  int language() const override { return in_use; }
  int default_language() const override { return 0; }
  void set_language(int i) override {
    in_use = i;
    current = catalogues[static_cast<std::size_t>(i)];
  }
  PageText page;  // what page_text() gives
  PageText page_text() override { return page; }
  /// say_in calls: text, from piece, language, until piece.
  std::vector<std::tuple<std::string, int, std::string, int>> said_in;
  void say_in(const std::string& text, int from_piece, const std::string& language, int until_piece) override {
    said.push_back(text);
    said_in.emplace_back(text, from_piece, language, until_piece);
  }
  std::string language_name_of(const std::string& tag) const override {
    for (const auto& c : catalogues)
      if (c.language() == tag.substr(0, tag.find('-'))) return c.language_name();
    return {};
  }
};

TEST(KioskFlow, AVisitInEachLanguageIsSaidWhollyInIt) {
  const std::vector<std::string> codes{"en", "fr", "de", "es"};
  for (std::size_t lang = 1; lang < codes.size(); ++lang) {
    SCOPED_TRACE(codes[lang]);
    LanguageRecorder fx;
    for (const std::string& c : codes)
      fx.catalogues.push_back(audio::MessageCatalog::load(c, audio::default_locale_dir()));
    const audio::MessageCatalog& m = fx.catalogues[lang];
    KioskFlowParams p;
    p.attract_every_s = 10.0;
    KioskFlow flow(fx, fx.current, p);
    // The invitation comes in each language in turn, from the default; each offers its own.
    for (std::size_t i = 0; i <= lang; ++i) flow.tick(10.0 * static_cast<double>(i + 1));
    ASSERT_EQ(fx.said.size(), lang + 1);
    EXPECT_NE(fx.said.back().find(m.text(MessageId::language_offer, {}, key_args(p.keys))), std::string::npos)
        << fx.said.back();
    // The Language key answers it: the visit is in that language, from the welcome to the goodbye.
    fx.said.clear();
    flow.key(KioskKey::Language, 100.0);
    EXPECT_EQ(fx.said.back(), m.text(MessageId::welcome, {}, key_args(p.keys)));
    flow.key(KioskKey::Help, 101.0);
    for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 102.0 + i);  // the tutorial, then picture 1: no shapes
    EXPECT_NE(fx.said.back().find(m.text(MessageId::picture_empty, {{"picture", "1"}, {"pictures", "4"}})),
              std::string::npos);
    for (int n = 1; n < 4; ++n) {  // 1, 2 and 5 shapes, each in its plural form
      flow.key(KioskKey::Next, 110.0 + n);
      EXPECT_EQ(fx.said.back(), m.text(MessageId::picture_loaded, LanguageRecorder::kShapes[n],
                                       {{"picture", std::to_string(n + 1)}, {"pictures", "4"}}));
    }
    flow.key(KioskKey::Describe, 120.0);
    EXPECT_NE(fx.said.back().find(m.word("scene_count", 2)), std::string::npos) << fx.said.back();
    flow.key(KioskKey::Finish, 130.0);
    flow.key(KioskKey::Finish, 130.5);
    EXPECT_EQ(fx.said.back(), m.text(MessageId::goodbye));
    EXPECT_EQ(fx.in_use, 0) << "the next visit starts in the default language";
    // Not one English line or phrase: the English texts of the words said are nowhere in it.
    for (const std::string& line : fx.said) {
      for (const char* english : {"Press", " the ", "shape", "Picture", "Welcome", "Goodbye", "picture"})
        EXPECT_EQ(line.find(english), std::string::npos) << english << " in: " << line;
    }
  }
}

TEST(KioskFlow, ADocumentsTextInAnotherLanguageIsSaidInItsVoiceAfterANotice) {
  LanguageRecorder fx;
  for (const char* c : {"en", "de"})
    fx.catalogues.push_back(audio::MessageCatalog::load(c, audio::default_locale_dir()));
  fx.page = {{"Der Brunnen steht auf dem Markt. Er ist alt."}, 0, "de-DE"};
  KioskFlowParams p;
  KioskFlow flow(fx, fx.current, p);
  flow.key(KioskKey::Other, 0.0);
  for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 1.0 + i);  // to the first picture
  flow.key(KioskKey::Describe, 5.0);                              // the hand on the block of text: it is read
  ASSERT_EQ(fx.said_in.size(), 1u);
  const auto& [text, from_piece, language, until_piece] = fx.said_in[0];
  EXPECT_EQ(language, "de-DE");
  EXPECT_EQ(until_piece, -1) << "to the end";
  const std::vector<std::string> pieces = audio::speech_pieces(text);
  ASSERT_LT(static_cast<std::size_t>(from_piece), pieces.size());
  EXPECT_EQ(pieces[static_cast<std::size_t>(from_piece)], "Der Brunnen steht auf dem Markt.")
      << "the visitor's words before it, the document's from here";
  EXPECT_NE(text.find("In German:"), std::string::npos) << text;  // its name in the visitor's language
  // A page in the visitor's own language is said as ever.
  fx.page.language = "en-GB";
  flow.key(KioskKey::Where, 7.0);
  flow.key(KioskKey::Describe, 8.0);
  EXPECT_EQ(fx.said_in.size(), 1u);
  EXPECT_NE(fx.said.back().find("Der Brunnen"), std::string::npos) << fx.said.back();
}

TEST(KioskFlow, WhatStaffWroteOnlyInAnotherLanguageIsSaidInItsVoiceBetweenTheVisitorsWords) {
  LanguageRecorder fx;
  for (const char* c : {"en", "fr"})
    fx.catalogues.push_back(audio::MessageCatalog::load(c, audio::default_locale_dir()));
  fx.notes.title = "A horse";
  fx.notes.description = "A horse standing, its head to the left.";
  fx.notes.language = "en";  // the sidecar has no [fr] table
  KioskFlowParams p;
  KioskFlow flow(fx, fx.current, p);
  flow.key(KioskKey::Other, 0.0);
  flow.key(KioskKey::Language, 0.5);  // Français
  ASSERT_EQ(fx.current.language(), "fr");
  for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 1.0 + i);
  flow.key(KioskKey::Describe, 5.0);
  ASSERT_EQ(fx.said_in.size(), 1u) << fx.said.back();
  const auto& [text, from_piece, language, until_piece] = fx.said_in[0];
  EXPECT_EQ(language, "en");
  const std::vector<std::string> pieces = audio::speech_pieces(text);
  ASSERT_LT(static_cast<std::size_t>(until_piece), pieces.size());
  ASSERT_EQ(until_piece - from_piece, 1) << text;  // the description, which opens with the title
  EXPECT_EQ(pieces[static_cast<std::size_t>(from_piece)], "A horse standing, its head to the left.");
  EXPECT_EQ(pieces[static_cast<std::size_t>(from_piece) - 1],
            fx.current.text(MessageId::other_language, {{"name", fx.current.word("language_en")}}))
      << "the notice, in the visitor's language, just before";
  EXPECT_NE(pieces[static_cast<std::size_t>(until_piece)].find("forme"), std::string::npos)
      << "the rest in French, in the French voice: " << text;
  // Notes in the visitor's own language are said as ever.
  fx.notes.language = "fr";
  flow.key(KioskKey::Where, 7.0);
  flow.key(KioskKey::Describe, 8.0);
  EXPECT_EQ(fx.said_in.size(), 1u);
}

}  // namespace
}  // namespace hk::app
