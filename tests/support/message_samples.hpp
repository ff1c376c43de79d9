#pragma once
/// @file message_samples.hpp
/// Each catalogue message as the kiosk would say it at its longest in ordinary use: the shipped keys, and
/// long but real values in its placeholders (two-digit numbers, a picture's title, a document's name, the
/// longest shape description describe_one_shape gives, the eight words of a block of text Where reads). For measuring
/// how long messages take to say (tests and bench_speech).

#include <span>
#include <string>

#include "audio/messages.hpp"

namespace hk::test {

/// The messages a visitor asks to hear whole, however long: help's second layer (every key), a picture's
/// description, a block of text read aloud.
inline bool asked_to_be_long(audio::MessageId id) {
  return id == audio::MessageId::help || id == audio::MessageId::describe || id == audio::MessageId::text_block;
}

/// `id` with every placeholder filled as described above and `keys` naming the keys.
inline std::string sample_message(const audio::MessageCatalog& m, audio::MessageId id,
                                  std::span<const audio::KeyArg> keys) {
  using audio::MessageId;
  const std::string place = m.text(MessageId::place_document, {{"page", "12"}, {"pages", "40"}});
  return m.text(
      id,
      {{"picture", "12"},
       {"pictures", "12"},
       {"shapes", "30"},
       {"title", "a horse, seen from the side"},
       {"level", "3"},
       {"seconds", "20"},
       {"count", "12"},
       {"description", id == MessageId::document_page || id == MessageId::document_picture
                           ? "It has 2 blocks of text and 3 figures."
                       : id == MessageId::where_near || id == MessageId::where_inside || id == MessageId::where_on_part
                           ? "a small light grey round shape"
                           : "a small white round shape with 2 small black round shapes inside it"},
       {"direction", "3 cm farther away, to your right"},
       {"summary", "3 documents: 2 pictures and a PDF of 12 pages"},
       {"reason", "the file is damaged"},
       {"name", "Annual report 2025"},
       {"page", "12"},
       {"pages", "40"},
       {"document", "2"},
       {"documents", "3"},
       {"text", "The quick brown fox jumps over the lazy dog"},
       {"place", place},
       {"shape", "12"},
       {"where", "in the far middle"},
       {"key", "The Q key"},
       {"block", "2"},
       {"blocks", "5"},
       {"folder", "A horse, seen from the side (tactile copy) 2"}},
      keys);
}

}  // namespace hk::test
