// The visitor's flow: reading a page's text aloud by sentence and paragraph, and Repeat (kiosk_flow.hpp,
// read_aloud.hpp).
#include <string>

#include "audio/speech.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {

using audio::MessageId;

// ---- reading a page's text by sentence and paragraph ---------------------------------------------------

bool KioskFlow::reading() const {
  return v_.reading_on && !v_.reading.empty() && fx_.speech.kept_texts() == v_.reading_kept;
}

void KioskFlow::follow_reading() {
  if (!reading()) return;
  const int piece = fx_.speech.heard_piece();
  if (piece >= 0) v_.reading.heard(piece);
}

std::string KioskFlow::other_language(const std::string& tag) const {
  const auto primary = [](const std::string& t) { return t.substr(0, t.find('-')); };
  return !tag.empty() && primary(tag) != primary(msg_.language()) ? tag : std::string();
}

std::string KioskFlow::language_notice() const {
  if (v_.reading_language.empty()) return {};
  std::string name = fx_.speech.language_name_of(v_.reading_language);
  if (name.empty()) name = v_.reading_language;
  return text(MessageId::other_language, {{"name", name}}) + " ";
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
    v_.reading_on = false;
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

std::string KioskFlow::paragraph_line(int p) const {
  if (v_.reading.paragraphs() < 2) return {};
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
