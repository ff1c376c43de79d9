#pragma once
/// @file read_aloud.hpp
/// A page's text read aloud with handles: the visitor moves by sentence and by paragraph, and Repeat says the
/// sentence being heard again, instead of a block of minutes starting over from its top.
///
/// A paragraph is one block of text of the page (vision: one of Tesseract's paragraphs, or a block of a PDF's
/// text layer), in reading order; a sentence is one piece the speaker says it in (audio::speech_pieces), so
/// the piece the speaker reports as heard (audio::Speaker::piece_heard) is the sentence the visitor is at.
/// Pure logic, no speech: the flow says text_from(), tells started() what it said before it, and reports
/// heard() as the speech goes on.

#include <string>
#include <string_view>
#include <vector>

#include "audio/messages.hpp"

namespace hk::app {

/// A block's text as it is said: each run of unclear words (vision::kUnclearWord, words the text reader was
/// not sure of) named in the catalogue's words, "unclear word" or "3 unclear words", never read as if certain.
std::string name_unclear_words(std::string_view text, const audio::MessageCatalog& messages);

/// A place in the text: paragraph and sentence within it, both counted from 0.
struct ReadingPlace {
  int paragraph = 0;
  int sentence = 0;
  bool operator==(const ReadingPlace&) const = default;
};

/// The text of one page, cut for reading, and where the visitor is in it.
class ReadAloud {
 public:
  /// No text: empty().
  ReadAloud() = default;
  /// `paragraphs` in reading order; each is cut into its spoken sentences. A paragraph with no words is left out.
  explicit ReadAloud(const std::vector<std::string>& paragraphs);

  bool empty() const { return paragraphs_.empty(); }
  int paragraphs() const { return static_cast<int>(paragraphs_.size()); }
  /// Sentences of paragraph `p` (0 ≤ p < paragraphs()).
  int sentences(int p) const { return static_cast<int>(paragraphs_[static_cast<std::size_t>(p)].size()); }
  /// The sentence `at` names (valid place).
  const std::string& sentence(ReadingPlace at) const;
  /// Where the visitor is: the sentence heard last (or the place reading started from).
  ReadingPlace place() const { return place_; }

  /// What to say to read from `at` to the end of its paragraph: its sentences joined by line breaks, so the
  /// speaker cuts it into exactly those pieces. `at` must be valid (valid()).
  std::string text_from(ReadingPlace at) const;
  /// Reading started at `at`, said after `lead_pieces` pieces of something else in the same text (a "Paragraph
  /// 2 of 5." before it): the place is `at`, and heard() counts pieces from there.
  void started(ReadingPlace at, int lead_pieces);
  /// Piece `piece` (from 0) of the text said since started() is being heard: the place follows it (pieces of
  /// the lead keep it at the start; past the paragraph's end it stays at the last sentence).
  void heard(int piece);
  /// Whether `at` names a sentence of this text.
  bool valid(ReadingPlace at) const;

  /// What a move hits: nothing, the start of the text, or its end.
  enum class Edge { None, Start, End };
  /// Where a move goes, and the edge it hit (at the start: the first sentence; at the end: the place stays).
  struct Step {
    ReadingPlace at;
    Edge edge = Edge::None;
  };
  /// The sentence after the place, on into the next paragraph.
  Step next_sentence() const;
  /// The sentence before the place, back into the paragraph before.
  Step previous_sentence() const;
  /// The first sentence of the next paragraph.
  Step next_paragraph() const;
  /// The first sentence of the paragraph before (of this one, at the start of the text).
  Step previous_paragraph() const;

 private:
  std::vector<std::vector<std::string>> paragraphs_;  // sentences of each paragraph
  ReadingPlace place_{};
  ReadingPlace started_{};
  int lead_pieces_ = 0;
};

}  // namespace hk::app
