// The operator's display switches (display_switches.hpp).
#include "visit/display_switches.hpp"

namespace hk::app {

void DisplaySwitches::poll(Voice& voice, const audio::MessageCatalog& m) {
  if (high_contrast_ != said_contrast_) {
    said_contrast_ = high_contrast_;
    voice.say_brief(m.text(high_contrast_ ? audio::MessageId::high_contrast_on : audio::MessageId::high_contrast_off));
  }
  if (overlay_ != said_overlay_) {
    said_overlay_ = overlay_;
    voice.say_brief(m.text(overlay_ ? audio::MessageId::overlay_on : audio::MessageId::overlay_off));
  }
}

}  // namespace hk::app
