// The visitor's flow: which language the visit is in (kiosk_flow.hpp): the Language key, the invitation in each
// offered language in turn, and a text in another language than the visitor's.
#include <string>

#include "hk/language.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {

using audio::MessageId;

void KioskFlow::language_key() {
  const int n = fx_.speech.language_count();
  if (n > 1) fx_.speech.set_language((fx_.speech.language() + 1) % n);
  say(MessageId::language_name);  // in itself: "Français"
}

void KioskFlow::invite() {
  // One language an invitation, in turn, from the default: each offers its own language's key.
  const int n = fx_.speech.language_count();
  if (n <= 1) {
    say_brief(MessageId::attract);
    return;
  }
  v_.invitation_language =
      v_.invitation_language < 0 ? fx_.speech.default_language() : (v_.invitation_language + 1) % n;
  fx_.speech.set_language(v_.invitation_language);
  fx_.speech.say_brief(text(MessageId::attract) + " " + text(MessageId::language_offer));
}

std::string KioskFlow::other_language(const std::string& tag) const {
  return !tag.empty() && hk::language_subtag(tag) != hk::language_subtag(msg_.language()) ? tag : std::string();
}

std::string KioskFlow::language_notice() const { return language_notice(v_.reading_language); }

std::string KioskFlow::language_notice(const std::string& tag) const {
  if (tag.empty()) return {};
  // The language's name in the visitor's ("In French:"), else in itself ("Français"), else its tag.
  std::string name = msg_.word("language_" + std::string(hk::language_subtag(tag)));
  if (name.empty()) name = fx_.speech.language_name_of(tag);
  if (name.empty()) name = tag;
  return text(MessageId::other_language, {{"name", name}}) + " ";
}

}  // namespace hk::app
