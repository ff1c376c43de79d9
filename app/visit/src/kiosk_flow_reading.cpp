// The visitor's flow: Describe, reading a page's text aloud by sentence and paragraph, and Repeat (kiosk_flow.hpp,
// read_aloud.hpp).
#include <algorithm>
#include <cmath>
#include <string>

#include "audio/speech.hpp"
#include "visit/answers.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {

using audio::MessageId;

// ---- Describe: the block of text under the hand read, else what the picture holds ------------------------

void KioskFlow::describe_key() {
  std::string before;
  // A visitor's own document is about to be heard by everyone near the kiosk: said once a visit, first.
  if (v_.source == KioskSource::Stick && v_.doc >= 0 && !v_.read_aloud_said) {
    v_.read_aloud_said = true;
    before = text(MessageId::read_aloud_warning) + " ";
  }
  // The hand on a block of text: that paragraph is read, by sentence (the reading keys move within the page).
  PageText page = fx_.stage.page_text();
  v_.reading = ReadAloud(page.paragraphs);
  v_.reading_language = other_language(page.language);
  v_.reading_complete = page.complete;
  v_.reading_reads_on = false;
  v_.reading_on = false;
  if (page.at_hand >= 0 && page.at_hand < v_.reading.paragraphs()) {
    const ReadingPlace at{page.at_hand, 0};
    // The catalogue's words before the text ("Text:"), as the block's text would be said with text_block.
    const std::string& block = msg_.raw(MessageId::text_block);
    const std::string lead =
        msg_.expand(std::string_view(block).substr(0, block.find("{text}")), {}, key_args(p_.keys));
    read_from(at, before + long_text_line(v_.reading.text_from(at)) + language_notice() + lead);
    return;
  }
  const std::string description = fx_.stage.describe();
  const std::string said = text(MessageId::describe, {{"description", description}});
  // What staff wrote only in another language: said in that language's voice after a notice in the visitor's.
  const PictureNotes notes = fx_.stage.shown_notes();
  const std::string foreign = other_language(notes.language);
  std::string written = notes_words(notes);
  if (!foreign.empty() && !written.empty() && said.rfind(written, 0) == 0) {
    std::string lead = before + long_text_line(description) + language_notice(foreign);
    while (!lead.empty() && lead.back() == ' ') lead.pop_back();
    const std::string rest = said.substr(written.size());
    while (!written.empty() && written.back() == ' ') written.pop_back();
    // Line breaks end pieces: the notes are pieces of their own, whatever their last character.
    const int from = static_cast<int>(audio::speech_pieces(lead).size());
    const int until = from + static_cast<int>(audio::speech_pieces(written).size());
    fx_.speech.say_in(lead + "\n" + written + "\n" + rest, from, foreign, until);
    return;
  }
  fx_.speech.say(before + long_text_line(description) + said);
}

std::string KioskFlow::long_text_line(const std::string& said) const {
  // A long text says how long it is before it starts (words at the voice's rate), and how to move through it.
  const double seconds = spoken_seconds(said);
  if (seconds <= kLongText_s) return {};
  const int minutes = static_cast<int>(std::lround(seconds / 60.0));
  return counted(MessageId::long_text_minutes, std::max(1, minutes)) + " ";
}

double spoken_seconds(std::string_view text) {
  int words = 0;
  bool in_word = false;
  for (const char c : text) {
    const bool space = std::isspace(static_cast<unsigned char>(c)) != 0;
    words += !space && !in_word;
    in_word = !space;
  }
  return 60.0 * words / kWordsPerMinute;
}

// ---- reading a page's text by sentence and paragraph ---------------------------------------------------

bool KioskFlow::reading() const {
  return v_.reading_on && !v_.reading.empty() && fx_.speech.kept_texts() == v_.reading_kept;
}

void KioskFlow::follow_reading() {
  if (!reading()) return;
  const int piece = fx_.speech.heard_piece();
  if (piece >= 0) v_.reading.heard(piece);
}

void KioskFlow::read_from(ReadingPlace at, const std::string& before) {
  // The lead is said in the same text, so the pieces heard count from its start; a line break ends it, so it
  // is cut as its own pieces whatever its last character.
  std::string said = before;
  while (!said.empty() && said.back() == ' ') said.pop_back();
  const int lead = static_cast<int>(audio::speech_pieces(said).size());
  if (!said.empty()) said += '\n';
  said += v_.reading.text_from(at);
  if (v_.reading_language.empty())
    fx_.speech.say(said);
  else
    fx_.speech.say_in(said, lead, v_.reading_language);
  v_.reading.started(at, lead);
  v_.reading_on = true;
  v_.reading_kept = fx_.speech.kept_texts();
}

void KioskFlow::reading_key(KioskKey k) {
  follow_reading();
  if (!reading()) {
    // Nothing being read: the page's text from the paragraph under the hand (else its first), if it has any.
    const PageText page = fx_.stage.page_text();
    v_.reading = ReadAloud(page.paragraphs);
    v_.reading_language = other_language(page.language);
    v_.reading_complete = page.complete;
    v_.reading_on = false;
    // A page still being read is read on to its end, each block as it comes; its first words said when they are.
    v_.reading_reads_on = !page.complete;
    if (v_.reading.empty() && !page.complete) {
      say(MessageId::reading_soon);
      v_.reading_waits = true;
      v_.reading_waits_kept = fx_.speech.kept_texts();
      return;
    }
    if (v_.reading.empty()) {
      say_brief(MessageId::reading_none);
      return;
    }
    const int p = page.at_hand >= 0 && page.at_hand < v_.reading.paragraphs() ? page.at_hand : 0;
    read_from({p, 0}, language_notice() + paragraph_line(p));
    return;
  }
  const bool by_paragraph = k == KioskKey::NextParagraph || k == KioskKey::PreviousParagraph;
  const ReadAloud::Step step = k == KioskKey::NextSentence       ? v_.reading.next_sentence()
                               : k == KioskKey::PreviousSentence ? v_.reading.previous_sentence()
                               : k == KioskKey::NextParagraph    ? v_.reading.next_paragraph()
                                                                 : v_.reading.previous_paragraph();
  if (step.edge == ReadAloud::Edge::End) {
    say_brief(MessageId::reading_end);  // the reading stays where it is: Repeat and the keys go on from there
    return;
  }
  std::string before = step.edge == ReadAloud::Edge::Start ? text(MessageId::reading_start) + " " : std::string();
  if (by_paragraph || step.at.paragraph != v_.reading.place().paragraph) before += paragraph_line(step.at.paragraph);
  read_from(step.at, before);
}

void KioskFlow::read_more() {
  // Anything said since "I will read it as soon as ..." (a kept text, or an acknowledgement that cut it off): the
  // visitor has moved on, and the reading asked for is not said over it.
  if (v_.reading_waits && (fx_.speech.kept_texts() != v_.reading_waits_kept ||
                           (fx_.speech.heard_piece() < 0 && !fx_.speech.heard_to_end())))
    v_.reading_waits = false;
  const bool heard = reading() && v_.reading_reads_on && fx_.speech.heard_to_end();
  if (!v_.reading_waits && !heard) return;
  const PageText page = fx_.stage.page_text();
  const int next = v_.reading_waits ? 0 : v_.reading.place().paragraph + 1;  // after the paragraph heard to its end
  if (next >= static_cast<int>(page.paragraphs.size())) {
    if (!page.complete) return;                                // more is still being read
    if (v_.reading_waits) say_brief(MessageId::reading_none);  // read whole, and no text on it
    v_.reading_waits = false;
    v_.reading_reads_on = false;  // the end of the page
    return;
  }
  const bool first = v_.reading_waits;
  v_.reading_waits = false;
  v_.reading = ReadAloud(page.paragraphs);
  // One voice for the whole reading: the language the page had when the reading began (OCR's guess from more
  // blocks may differ, and a page read half in one voice and half in another is worse than either).
  if (first) v_.reading_language = other_language(page.language);
  v_.reading_complete = page.complete;
  read_from({next, 0}, first ? language_notice() : std::string());
}

std::string KioskFlow::paragraph_line(int p) const {
  if (v_.reading.paragraphs() < 2 || !v_.reading_complete) return {};
  return text(MessageId::reading_paragraph,
              {{"block", std::to_string(p + 1)}, {"blocks", std::to_string(v_.reading.paragraphs())}});
}

void KioskFlow::repeat_key() {
  // Reading a text: the sentence being heard, and on from there; else the last thing said, from its start.
  follow_reading();
  if (reading()) {
    read_from(v_.reading.place(), {});
    return;
  }
  if (!fx_.speech.repeat()) say_brief(MessageId::nothing_to_repeat);
}

}  // namespace hk::app
