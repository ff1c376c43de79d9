#include "visit/read_aloud.hpp"

#include <algorithm>

#include "audio/speech.hpp"
#include "vision/ocr.hpp"

namespace hk::app {

std::string name_unclear_words(std::string_view text, const audio::MessageCatalog& messages) {
  std::string out;
  out.reserve(text.size());
  const std::string_view mark = vision::kUnclearWord;
  std::size_t i = 0;
  while (i < text.size()) {
    if (text.compare(i, mark.size(), mark) != 0) {
      out += text[i++];
      continue;
    }
    // A run of marks, each a word of its own: counted, then named once.
    int run = 0;
    std::size_t j = i;
    while (text.compare(j, mark.size(), mark) == 0) {
      ++run;
      j += mark.size();
      std::size_t k = j;
      while (k < text.size() && text[k] == ' ') ++k;
      if (text.compare(k, mark.size(), mark) != 0) break;
      j = k;
    }
    out += messages.text(audio::MessageId::unclear_words, run);
    i = j;
  }
  return out;
}

ReadAloud::ReadAloud(const std::vector<std::string>& paragraphs) {
  for (const std::string& p : paragraphs) {
    std::vector<std::string> sentences = audio::speech_pieces(p);
    if (!sentences.empty()) paragraphs_.push_back(std::move(sentences));
  }
}

const std::string& ReadAloud::sentence(ReadingPlace at) const {
  return paragraphs_[static_cast<std::size_t>(at.paragraph)][static_cast<std::size_t>(at.sentence)];
}

bool ReadAloud::valid(ReadingPlace at) const {
  return at.paragraph >= 0 && at.paragraph < paragraphs() && at.sentence >= 0 && at.sentence < sentences(at.paragraph);
}

std::string ReadAloud::text_from(ReadingPlace at) const {
  std::string text;
  const std::vector<std::string>& p = paragraphs_[static_cast<std::size_t>(at.paragraph)];
  for (std::size_t s = static_cast<std::size_t>(at.sentence); s < p.size(); ++s) {
    if (!text.empty()) text += '\n';
    text += p[s];
  }
  return text;
}

void ReadAloud::started(ReadingPlace at, int lead_pieces) {
  place_ = at;
  started_ = at;
  lead_pieces_ = std::max(0, lead_pieces);
}

void ReadAloud::heard(int piece) {
  if (empty() || piece < lead_pieces_) return;
  const int last = sentences(started_.paragraph) - 1;
  place_ = {started_.paragraph, std::min(started_.sentence + piece - lead_pieces_, last)};
}

ReadAloud::Step ReadAloud::next_sentence() const {
  if (place_.sentence + 1 < sentences(place_.paragraph)) return {{place_.paragraph, place_.sentence + 1}};
  if (place_.paragraph + 1 < paragraphs()) return {{place_.paragraph + 1, 0}};
  return {place_, Edge::End};
}

ReadAloud::Step ReadAloud::previous_sentence() const {
  if (place_.sentence > 0) return {{place_.paragraph, place_.sentence - 1}};
  if (place_.paragraph > 0) return {{place_.paragraph - 1, sentences(place_.paragraph - 1) - 1}};
  return {{0, 0}, Edge::Start};
}

ReadAloud::Step ReadAloud::next_paragraph() const {
  if (place_.paragraph + 1 < paragraphs()) return {{place_.paragraph + 1, 0}};
  return {place_, Edge::End};
}

ReadAloud::Step ReadAloud::previous_paragraph() const {
  if (place_.paragraph > 0) return {{place_.paragraph - 1, 0}};
  return {{0, 0}, Edge::Start};
}

}  // namespace hk::app
