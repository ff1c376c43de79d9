// Every message a visitor did not ask to be long is at most 8 s of speech at the default rate (165 words a
// minute, espeak-ng's English voice), measured by synthesising it as the kiosk does, with the shipped keys
// and long but real values in its placeholders. Exempt: what the visitor asked to hear whole — help's
// second layer (every key), a picture's description and a block of text read aloud.
#include <gtest/gtest.h>

#include <string>

#include "audio/messages.hpp"
#include "audio/speech.hpp"
#include "message_samples.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {
namespace {

TEST(MessageLengths, EveryMessageButThoseAskedForIsAtMostEightSeconds) {
  const audio::MessageCatalog& en = audio::MessageCatalog::english();
  const config::KeysSettings keys;
  const auto key_names = key_args(keys);
  int measured = 0;
  for (int i = 0; i < audio::kMessageCount; ++i) {
    const auto id = static_cast<audio::MessageId>(i);
    if (test::asked_to_be_long(id)) continue;
    const std::string text = test::sample_message(en, id, key_names);
    const double seconds = static_cast<double>(audio::synthesize_speech(text, {}).size()) / audio::kSampleRateHz;
    EXPECT_LE(seconds, 8.0) << audio::message_key(static_cast<audio::MessageId>(i)) << ": " << text;
    EXPECT_GT(seconds, 0.3) << audio::message_key(static_cast<audio::MessageId>(i)) << " is spoken at all";
    ++measured;
  }
  EXPECT_EQ(measured, audio::kMessageCount - 3);
}

TEST(MessageLengths, TheFirstWordsAVisitorHearsAreShort) {
  // Walking up: the welcome is the first speech before any action; the help's first layer is the answer
  // to the first key a lost visitor presses. Both well under the 8 s.
  const audio::MessageCatalog& en = audio::MessageCatalog::english();
  const config::KeysSettings keys;  // key_args views its strings
  const auto key_names = key_args(keys);
  for (const audio::MessageId id :
       {audio::MessageId::welcome, audio::MessageId::help_brief, audio::MessageId::attract}) {
    const std::string text = test::sample_message(en, id, key_names);
    EXPECT_LE(static_cast<double>(audio::synthesize_speech(text, {}).size()) / audio::kSampleRateHz, 7.0) << text;
  }
}

}  // namespace
}  // namespace hk::app
