// A page's text read with handles: the sentences the kiosk reads are the pieces the speaker says (so the piece
// heard is the sentence the visitor is at); the sentence and paragraph keys move from the sentence heard, across
// paragraphs, and say where the text starts and ends; Repeat says the sentence heard again; a long text says how
// long it is and which keys move through it; a page without text says so. Driven through the flow with a recorder
// that keeps what a speaker would, and the piece heard set by the test as a mixer would move it.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "audio/speech.hpp"
#include "every_effect.hpp"
#include "test_paths.hpp"
#include "vision/ocr.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/read_aloud.hpp"

namespace hk::app {
namespace {

using audio::MessageId;

const std::string kData = HK_TEST_DATA_DIR;

}  // namespace

void PrintTo(const ReadingPlace& p, std::ostream* os) {
  *os << "{paragraph " << p.paragraph << ", sentence " << p.sentence << "}";
}

namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Three paragraphs: two short ones round the 8 KB paragraph of tests/data/documents (long_paragraph.txt, the
/// text of long_paragraph.pdf).
std::vector<std::string> page_paragraphs() {
  return {"Opening hours. The museum opens at nine; it closes at five.",
          read_file(kData + "/documents/long_paragraph.txt"), "Thank you for reading. Come again soon!"};
}

struct Reader final : hk::test::EveryEffect {
  std::vector<std::string> said;
  std::vector<bool> brief;
  std::string kept;
  std::uint64_t kept_count = 0;
  int piece = -1;            // the piece of the last kept text being heard (the test moves it)
  bool brief_since = false;  // an acknowledgement was said after the last kept text (it cut that text off)
  PageText page;

  void say(const std::string& t) override {
    said.push_back(t);
    brief.push_back(false);
    kept = t;
    ++kept_count;
    piece = 0;
    brief_since = false;
    voices.push_back("");
  }
  void say_brief(const std::string& t) override {
    said.push_back(t);
    brief.push_back(true);
    piece = -1;
    brief_since = true;
  }
  bool repeat() override {
    if (kept.empty()) return false;
    say(std::string(kept));
    return true;
  }
  std::uint64_t kept_texts() const override { return kept_count; }
  std::vector<std::string> voices;  // the language of each text said with say_in, "" for say
  void say_in(const std::string& t, int, const std::string& language, int) override {
    say(t);
    voices.back() = language;
  }
  int heard_piece() const override { return piece; }
  bool heard_to_end() const override { return piece < 0 && !brief_since; }
  PageText page_text() override { return page; }
  void show_tutorial(TutorialShape) override {}
  int show_picture(int) override { return 2; }
  int picture_count() const override { return 3; }
  std::string describe() override { return "It has 3 blocks of text and no figures."; }
  bool change_level(int) override { return true; }
  bool change_volume(int) override { return true; }
  void new_session() override { kept.clear(); }
  void show_document(int, int) override {}
  void forget_stick() override {}
};

/// A flow woken and walked to the first picture, on a page of three paragraphs with the hand on `at_hand`.
struct Page {
  Reader fx;
  KioskFlow flow{fx, audio::MessageCatalog::english()};
  double now = 1.0;
  explicit Page(int at_hand) {
    flow.handle_moved(now);
    for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, now += 0.1);
    fx.page = {page_paragraphs(), at_hand, ""};
  }
  void key(KioskKey k) { flow.key(k, now += 0.1); }
  /// The mixer reaches piece `p` of the last text said; the flow follows at its next tick.
  void hear(int p) {
    fx.piece = p;
    flow.tick(now += 0.02);
  }
  std::string text(MessageId id, std::initializer_list<audio::MessageArg> args = {}) const {
    return flow.text(id, args);
  }
};

TEST(ReadAloud, SentencesAreThePiecesTheSpeakerSays) {
  const ReadAloud r(page_paragraphs());
  ASSERT_EQ(r.paragraphs(), 3);
  EXPECT_EQ(r.sentences(0), 3) << "\"Opening hours.\", then two: ';' ends a spoken piece too";
  EXPECT_EQ(r.sentence({0, 0}), "Opening hours.");
  EXPECT_GT(r.sentences(1), 50);
  for (int p = 0; p < r.paragraphs(); ++p) {
    for (int s = 0; s < r.sentences(p); s += 7) {
      // Said from any sentence, the speaker cuts the text into exactly the sentences that follow: the piece it
      // reports heard is a sentence of this reading.
      const std::vector<std::string> pieces = audio::speech_pieces(r.text_from({p, s}));
      ASSERT_EQ(static_cast<int>(pieces.size()), r.sentences(p) - s) << p << ", " << s;
      for (std::size_t i = 0; i < pieces.size(); ++i) EXPECT_EQ(pieces[i], r.sentence({p, s + static_cast<int>(i)}));
    }
  }
  EXPECT_EQ(ReadAloud(std::vector<std::string>{" ", "\n"}).paragraphs(), 0) << "paragraphs without words are left out";
}

TEST(ReadAloud, MovesCrossParagraphsAndStopAtTheEdges) {
  ReadAloud r(page_paragraphs());
  r.started({0, 0}, 1);
  r.heard(0);
  EXPECT_EQ(r.place(), (ReadingPlace{0, 0})) << "the lead's pieces keep the place at the start";
  r.heard(2);
  EXPECT_EQ(r.place(), (ReadingPlace{0, 1}));
  r.heard(9);
  EXPECT_EQ(r.place(), (ReadingPlace{0, 2})) << "past the paragraph's end: its last sentence";
  EXPECT_EQ(r.next_sentence().at, (ReadingPlace{1, 0}));
  EXPECT_EQ(r.previous_sentence().at, (ReadingPlace{0, 1}));
  EXPECT_EQ(r.next_paragraph().at, (ReadingPlace{1, 0}));
  EXPECT_EQ(r.previous_paragraph().edge, ReadAloud::Edge::Start);
  r.started({1, 0}, 0);
  EXPECT_EQ(r.previous_sentence().at, (ReadingPlace{0, 2})) << "back into the paragraph before, at its last sentence";
  r.started({2, 1}, 0);
  EXPECT_EQ(r.next_sentence().edge, ReadAloud::Edge::End);
  EXPECT_EQ(r.next_sentence().at, (ReadingPlace{2, 1})) << "at the end the place stays";
  EXPECT_EQ(r.next_paragraph().edge, ReadAloud::Edge::End);
  EXPECT_EQ(r.previous_paragraph().at, (ReadingPlace{1, 0}));
}

TEST(ReadAloud, DescribeReadsTheParagraphUnderTheHandAndTheKeysMoveFromTheSentenceHeard) {
  Page v(1);
  const ReadAloud r(page_paragraphs());
  v.key(KioskKey::Describe);
  const std::string& said = v.fx.said.back();
  // A long paragraph: its length and the keys that move through it, then the catalogue's "Text:", then the text.
  const std::string lead =
      "About 10 minutes of text. Press the K key to skip a sentence, the I key a paragraph. Text:\n";
  EXPECT_EQ(said.rfind(lead, 0), 0u) << said.substr(0, 200);
  EXPECT_EQ(said.substr(lead.size()), r.text_from({1, 0}));
  EXPECT_TRUE(v.flow.view().reading);
  const int lead_pieces = static_cast<int>(audio::speech_pieces(lead).size());
  ASSERT_EQ(lead_pieces, 3);
  v.hear(lead_pieces + 5);  // the visitor hears sentence 5
  EXPECT_EQ(v.flow.view().reading_place, (ReadingPlace{1, 5}));
  v.key(KioskKey::NextSentence);
  EXPECT_EQ(v.fx.said.back(), r.text_from({1, 6})) << "on from the next sentence, nothing before it";
  v.hear(2);
  EXPECT_EQ(v.flow.view().reading_place, (ReadingPlace{1, 8}));
  v.key(KioskKey::Repeat);
  EXPECT_EQ(v.fx.said.back(), r.text_from({1, 8})) << "Repeat: the sentence heard, again";
  v.key(KioskKey::PreviousSentence);
  EXPECT_EQ(v.fx.said.back(), r.text_from({1, 7}));
  v.key(KioskKey::NextParagraph);
  EXPECT_EQ(v.fx.said.back(),
            v.text(MessageId::reading_paragraph, {{"block", "3"}, {"blocks", "3"}}) + "\n" + r.text_from({2, 0}));
  v.hear(2);  // the second sentence of the last paragraph
  v.key(KioskKey::NextSentence);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::reading_end)) << "the end of the text";
  EXPECT_TRUE(v.fx.brief.back());
  v.key(KioskKey::Repeat);
  EXPECT_EQ(v.fx.said.back(), r.text_from({2, 1})) << "the place stayed at the last sentence";
  v.key(KioskKey::PreviousParagraph);
  v.key(KioskKey::PreviousParagraph);
  v.key(KioskKey::PreviousParagraph);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::reading_start) + " " +
                                  v.text(MessageId::reading_paragraph, {{"block", "1"}, {"blocks", "3"}}) + "\n" +
                                  r.text_from({0, 0}));
}

TEST(ReadAloud, AfterSomethingElseIsSaidTheKeysStartAgainFromTheHand) {
  Page v(2);
  const ReadAloud r(page_paragraphs());
  v.key(KioskKey::Describe);
  EXPECT_EQ(v.fx.said.back(), "Text:\n" + r.text_from({2, 0})) << "a short paragraph: no length said";
  v.key(KioskKey::Where);  // something else is said: the reading is over
  EXPECT_FALSE(v.flow.view().reading);
  v.key(KioskKey::Repeat);
  EXPECT_EQ(v.fx.said.back(), v.fx.said[v.fx.said.size() - 2]) << "Repeat says what was said last, whole";
  v.fx.page.at_hand = -1;  // the hand off the text
  v.key(KioskKey::NextSentence);
  EXPECT_EQ(v.fx.said.back(),
            v.text(MessageId::reading_paragraph, {{"block", "1"}, {"blocks", "3"}}) + "\n" + r.text_from({0, 0}))
      << "the page's first paragraph";
  EXPECT_TRUE(v.flow.view().reading);
}

TEST(ReadAloud, UnclearWordsAreNamedNotReadAsIfCertain) {
  const std::string u(vision::kUnclearWord);
  const audio::MessageCatalog& en = audio::MessageCatalog::english();
  EXPECT_EQ(name_unclear_words("The " + u + " opens at " + u + " " + u + " " + u + ", daily.", en),
            "The unclear word opens at 3 unclear words, daily.");
  EXPECT_EQ(name_unclear_words(u, en), "unclear word");
  EXPECT_EQ(name_unclear_words("Nothing unsure here.", en), "Nothing unsure here.");
  const audio::MessageCatalog de = audio::MessageCatalog::load("de", audio::default_locale_dir());
  EXPECT_EQ(name_unclear_words(u + " " + u + " Uhr", de), de.text(MessageId::unclear_words, 2) + " Uhr")
      << "in the visitor's language";
  EXPECT_NE(de.text(MessageId::unclear_words, 2), en.text(MessageId::unclear_words, 2));
}

TEST(ReadAloud, APictureWithoutTextSaysSo) {
  Page v(-1);
  v.fx.page = {};
  v.key(KioskKey::NextParagraph);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::reading_none));
  v.key(KioskKey::Describe);
  EXPECT_EQ(v.fx.said.back(), v.fx.describe()) << "Describe as ever: what the picture holds";
  EXPECT_FALSE(v.flow.view().reading);
}

TEST(ReadAloud, AReadingAskedForWhileTheTextIsReadStartsWithItsFirstBlockAndGoesOnAsBlocksCome) {
  Page v(-1);
  const std::vector<std::string> all = page_paragraphs();
  v.fx.page = {{}, -1, "", false};  // no block read yet
  v.key(KioskKey::NextSentence);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::reading_soon));
  const std::size_t asked = v.fx.said.size();
  v.hear(-1);  // heard; still nothing read
  EXPECT_EQ(v.fx.said.size(), asked) << "nothing to say until a block comes";
  v.fx.page = {{all[0]}, -1, "", false};  // the first block is read
  v.hear(-1);
  const std::string first = ReadAloud({all[0]}).text_from({0, 0});
  EXPECT_EQ(v.fx.said.back(), first) << "said at once, without a count of paragraphs not yet known";
  EXPECT_TRUE(v.flow.view().reading);
  v.hear(0);
  v.fx.page = {{all[0], all[1]}, -1, "", false};
  v.hear(0);
  EXPECT_EQ(v.fx.said.back(), first) << "the block being heard is not cut by the next one coming";
  v.fx.page = {all, -1, "", true};  // the whole text has been read
  v.hear(-1);                       // and the first block has been heard to its end
  EXPECT_EQ(v.fx.said.back(), ReadAloud(all).text_from({1, 0})) << "on with the blocks that came, from the next";
  EXPECT_TRUE(v.flow.view().reading);
  v.hear(3);
  v.hear(-1);  // the second paragraph heard to its end: the third follows, to the end of the page
  EXPECT_EQ(v.fx.said.back(), ReadAloud(all).text_from({2, 0}));
  const std::size_t read = v.fx.said.size();
  v.hear(-1);
  EXPECT_EQ(v.fx.said.size(), read) << "the end of the page: nothing more to add";
}

TEST(ReadAloud, AnAcknowledgementThatCutsAReadingOnEndsIt) {
  Page v(-1);
  const std::vector<std::string> all = page_paragraphs();
  v.fx.page = {{all[0]}, -1, "", false};
  v.key(KioskKey::NextSentence);  // the first block has been read: said at once
  v.fx.page = {all, -1, "", true};
  v.key(KioskKey::Finish);  // "Press the End key again ..." cuts it off
  ASSERT_TRUE(v.fx.brief.back());
  const std::size_t n = v.fx.said.size();
  v.hear(-1);
  v.hear(-1);
  EXPECT_EQ(v.fx.said.size(), n) << "the reading does not come back over what the visitor did";
}

TEST(ReadAloud, AWaitingReadingIsDroppedWhenTheVisitorMovesOnAndSaysSoWhenThePageHasNoText) {
  Page v(-1);
  v.fx.page = {{}, -1, "", false};
  v.key(KioskKey::NextParagraph);
  v.key(KioskKey::Where);  // something else asked for
  const std::size_t n = v.fx.said.size();
  v.fx.page = {{"Opening hours."}, -1, "", false};
  v.hear(-1);
  EXPECT_EQ(v.fx.said.size(), n) << "not read over what the visitor asked for since";
  v.fx.page = {{}, -1, "", false};
  v.key(KioskKey::NextParagraph);
  v.key(KioskKey::Finish);  // an acknowledgement ("Press the End key again ...") cuts the wait off too
  const std::size_t acknowledged = v.fx.said.size();
  v.fx.page = {{"Opening hours."}, -1, "", false};
  v.hear(-1);
  EXPECT_EQ(v.fx.said.size(), acknowledged) << "the first block is not read over the acknowledgement";
  EXPECT_TRUE(v.fx.brief.back());
  v.fx.page = {{}, -1, "", false};
  v.key(KioskKey::NextParagraph);
  v.fx.page = {{}, -1, "", true};  // read whole: no text on it
  v.hear(-1);
  EXPECT_EQ(v.fx.said.back(), v.text(MessageId::reading_none));
}

TEST(ReadAloud, AReadingOnKeepsTheVoiceItBeganInWhateverLaterBlocksSeemToBe) {
  Page v(-1);
  const std::vector<std::string> all = page_paragraphs();
  v.fx.page = {{}, -1, "", false};  // asked for before any block is read
  v.key(KioskKey::NextSentence);
  v.fx.page = {{all[0]}, -1, "de", false};  // OCR's guess from the first block: German
  v.hear(-1);
  ASSERT_EQ(v.fx.voices.back(), "de");
  v.fx.page = {all, -1, "en", true};  // from the whole page, another guess
  v.hear(-1);
  EXPECT_EQ(v.fx.said.back(), ReadAloud(all).text_from({1, 0}));
  EXPECT_EQ(v.fx.voices.back(), "de") << "one voice for the whole reading";
}

}  // namespace
}  // namespace hk::app
