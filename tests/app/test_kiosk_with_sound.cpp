// The kiosk as a visitor meets it: with a sound device (ALSA's null PCM, so the speaker and the audio
// callback exist as at a real kiosk), under Xvfb, driven by a script. Describe with the hand on a PDF page
// whose one paragraph is over 8 000 bytes: the kiosk keeps running (it used to exit on a text over 4 000
// bytes), the whole paragraph is given to the speaker, and its pieces are spoken in order from its start.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "audio/speech.hpp"
#include "kiosk_exe.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace {

using hk::test::read_text;
using hk::test::sh;

const fs::path kData = HK_TEST_DATA_DIR;

/// The bytes of `text` but its white space.
std::string letters_of(const std::string& text) {
  std::string out;
  for (char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) out += c;
  return out;
}

/// The text after `marker` on every line of `log` that has it, in order.
std::vector<std::string> lines_after(const std::string& log, const std::string& marker) {
  std::vector<std::string> out;
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);) {
    const auto at = line.find(marker);
    if (at != std::string::npos) out.push_back(line.substr(at + marker.size()));
  }
  return out;
}

/// A HOME whose ~/.asoundrc makes ALSA's default PCM the null device: sound "plays" at the real rate and
/// goes nowhere. The kiosk's PortAudio output opens it as it would a sound card.
fs::path null_sound_home(const fs::path& dir) {
  const fs::path home = dir / "home";
  fs::create_directories(home);
  std::ofstream(home / ".asoundrc") << "pcm.!default { type null }\nctl.!default { type hw card 0 }\n";
  return home;
}

TEST(KioskWithSound, DescribeReadsAnEightKilobyteParagraphWholeAndTheKioskRunsOn) {
  if (sh("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = hk::test::fresh_dir("kiosk_sound");
  fs::create_directories(dir / "stick");
  fs::copy_file(kData / "documents" / "long_paragraph.pdf", dir / "stick" / "manual.pdf");
  const std::string paragraph = read_text(kData / "documents" / "long_paragraph.txt");
  ASSERT_GT(paragraph.size(), 8000u);
  // The stick's page comes up by itself; the hand goes to the middle of the page (on the paragraph), then
  // Describe. 12 s of kiosk time in all.
  std::ofstream(dir / "script.txt") << "1 wait\n2 cursor 0 0\n120 key describe\n";
  const fs::path home = null_sound_home(dir);
  const std::string cmd = "ASAN_OPTIONS=detect_leaks=0 SPDLOG_LEVEL=debug HOME=" + hk::test::quoted(home) +
                          " timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' " + std::string(HK_KIOSK_EXE) +
                          " --library " + hk::test::quoted(kData / "images") + " --stick " +
                          hk::test::quoted(dir / "stick") + " --script " + hk::test::quoted(dir / "script.txt") +
                          " --screenshot " + hk::test::quoted(dir / "end.png") + " --frames 720 >" +
                          hk::test::quoted(dir / "log.txt") + " 2>&1";
  ASSERT_EQ(sh(cmd), 0) << "the kiosk ended: " << read_text(dir / "log.txt").substr(0, 4000);
  const std::string log = read_text(dir / "log.txt");
  EXPECT_EQ(log.find("audio: no output device"), std::string::npos)
      << "the null PCM is a sound device: " << log.substr(0, 2000);
  EXPECT_TRUE(fs::exists(dir / "end.png")) << "it ran to its last frame";
  // Describe gave the speaker the whole block, every word in order.
  const std::vector<std::string> said = lines_after(log, "say: ");
  const std::string want = "Text: " + paragraph.substr(0, paragraph.find_last_not_of("\n") + 1);
  // Before it: that people nearby hear the visitor's document, and how long the text is.
  std::string line;
  for (const std::string& s : said) {
    const std::string l = letters_of(s), w = letters_of(want);
    if (l.size() >= w.size() && l.compare(l.size() - w.size(), w.size(), w) == 0) line = s;
  }
  ASSERT_FALSE(line.empty()) << "no 'say:' line holds the whole paragraph; said " << said.size() << " lines";
  EXPECT_EQ(line.rfind(
                "People nearby can hear your document. Press the P key to pause it, or the End key to stop. About ", 0),
            0u)
      << line.substr(0, 200);
  EXPECT_NE(line.find("minute"), std::string::npos) << line.substr(0, 200);
  // The pieces handed to the sound device so far follow the paragraph from its start, in order (the rest
  // would take minutes to play: the unit tests read a long text through to its end).
  std::string spoken;
  bool reading = false;
  for (const std::string& piece : lines_after(log, "speech: piece: ")) {
    if (piece.rfind("Text:", 0) == 0) {
      reading = true;
      spoken.clear();
    }
    if (reading) spoken += piece;
  }
  ASSERT_TRUE(reading) << "the reading never started";
  const std::string heard = letters_of(spoken), whole_text = letters_of(want);
  EXPECT_GT(heard.size(), 300u) << "more than its first sentence was handed on";
  EXPECT_EQ(whole_text.rfind(heard, 0), 0u) << "the pieces spoken are the paragraph's start, in order";
  fs::remove_all(dir);
}

/// The sentence of `sentences` from which `said` reads to the end (white space aside); −1 when it is no such text.
int reads_from(const std::vector<std::string>& sentences, const std::string& said) {
  const std::string heard = letters_of(said);
  std::string tail;
  for (int k = static_cast<int>(sentences.size()) - 1; k >= 0; --k) {
    tail = letters_of(sentences[static_cast<std::size_t>(k)]) + tail;
    if (tail == heard) return k;
  }
  return -1;
}

// The sentence keys on the same paragraph, heard as a visitor hears them (the null sound device plays at the
// real rate): each press reads on from the sentence being heard, never from the top; Previous goes one back,
// Repeat says the sentence heard again, and a page of one paragraph has no next one.
TEST(KioskWithSound, TheSentenceKeysMoveThroughALongParagraphFromTheSentenceHeard) {
  if (sh("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = hk::test::fresh_dir("kiosk_sentences");
  fs::create_directories(dir / "stick");
  fs::copy_file(kData / "documents" / "long_paragraph.pdf", dir / "stick" / "manual.pdf");
  const std::vector<std::string> sentences =
      hk::audio::speech_pieces(read_text(kData / "documents" / "long_paragraph.txt"));
  ASSERT_GT(sentences.size(), 20u);
  // Describe at 2 s; the text itself starts after the warning and the length (~10 s); then the keys.
  std::ofstream(dir / "script.txt")
      << "1 wait\n2 cursor 0 0\n120 key describe\n900 key next_sentence\n1000 key next_sentence\n"
         "1060 key previous_sentence\n1120 key repeat\n1180 key next_paragraph\n";
  const fs::path home = null_sound_home(dir);
  const std::string cmd = "ASAN_OPTIONS=detect_leaks=0 HOME=" + hk::test::quoted(home) +
                          " timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' " + std::string(HK_KIOSK_EXE) +
                          " --library " + hk::test::quoted(kData / "images") + " --stick " +
                          hk::test::quoted(dir / "stick") + " --script " + hk::test::quoted(dir / "script.txt") +
                          " --screenshot " + hk::test::quoted(dir / "end.png") + " --frames 1200 >" +
                          hk::test::quoted(dir / "log.txt") + " 2>&1";
  ASSERT_EQ(sh(cmd), 0) << read_text(dir / "log.txt").substr(0, 4000);
  const std::vector<std::string> said = lines_after(read_text(dir / "log.txt"), "say: ");
  ASSERT_GE(said.size(), 5u);
  const std::vector<std::string> last(said.end() - 5, said.end());
  const int a = reads_from(sentences, last[0]), b = reads_from(sentences, last[1]), c = reads_from(sentences, last[2]),
            d = reads_from(sentences, last[3]);
  EXPECT_GE(a, 1) << "the first press reads on from a sentence after the first: " << last[0].substr(0, 120);
  EXPECT_GT(b, a) << "the second press goes on past the first: " << last[1].substr(0, 120);
  EXPECT_GE(c, b - 1) << "Previous goes back one from the sentence heard: " << last[2].substr(0, 120);
  EXPECT_LT(c, b + 1) << last[2].substr(0, 120);
  EXPECT_GE(d, c) << "Repeat says the sentence heard, not the top: " << last[3].substr(0, 120);
  EXPECT_LE(d, c + 1) << last[3].substr(0, 120);
  EXPECT_EQ(last[4], "That is the end of the text. Press the J key to go back.") << "one paragraph: no next one";
  fs::remove_all(dir);
}

}  // namespace

namespace {

// A scripted visit heard through its spoken lines: chords a visitor may press by accident (Ctrl+Q, Alt+F4) are
// answered like any key that does nothing; Finish pressed once only asks, pressed again too late asks again,
// and pressed twice within 5 s ends the visit.
TEST(KioskWithSound, ChordsAreAnsweredAndFinishAsksOnce) {
  if (sh("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = hk::test::fresh_dir("kiosk_finish");
  std::ofstream(dir / "script.txt")
      << "1 wait\n10 press CTRL+Q\n40 press ALT+F4\n70 key finish\n500 key finish\n530 key finish\n";
  const fs::path home = null_sound_home(dir);
  const std::string cmd = "ASAN_OPTIONS=detect_leaks=0 HOME=" + hk::test::quoted(home) +
                          " timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' " + std::string(HK_KIOSK_EXE) +
                          " --library " + hk::test::quoted(kData / "images") + " --show " +
                          hk::test::quoted(kData / "images" / "horse.png") + " --script " +
                          hk::test::quoted(dir / "script.txt") + " --screenshot " + hk::test::quoted(dir / "end.png") +
                          " --frames 600 >" + hk::test::quoted(dir / "log.txt") + " 2>&1";
  ASSERT_EQ(sh(cmd), 0) << read_text(dir / "log.txt").substr(0, 4000);
  std::vector<std::string> said = lines_after(read_text(dir / "log.txt"), "say: ");
  const auto first =
      std::find_if(said.begin(), said.end(), [](const std::string& s) { return s.rfind("That key", 0) == 0; });
  ASSERT_NE(first, said.end()) << "Ctrl+Q was answered";
  const std::vector<std::string> want{
      "That key does nothing here. Press F1 for help.", "That key does nothing here. Press F1 for help.",
      "Press the End key again to finish your visit.", "Press the End key again to finish your visit.",
      "Thank you for visiting. Goodbye."};
  const std::vector<std::string> got(first, said.end());
  EXPECT_EQ(got, want);
  fs::remove_all(dir);
}

}  // namespace
