#pragma once
/// @file display_switches.hpp
/// The operator's display switches (the panel's checkboxes): high contrast and the overlay of the collision
/// tree's boxes. A change is said and logged once ("High contrast on."), so a person at the kiosk who cannot
/// see the screen knows the staff changed it. Window thread only.

#include "audio/system.hpp"
#include "visit/voice.hpp"

namespace hk::app {

/// High contrast and the overlay. Not thread-safe: the window thread.
class DisplaySwitches {
 public:
  /// Both switches as the kiosk starts (`high_contrast` is also every new visitor's).
  DisplaySwitches(bool high_contrast, bool overlay)
      : start_contrast_(high_contrast),
        high_contrast_(high_contrast),
        overlay_(overlay),
        said_contrast_(high_contrast),
        said_overlay_(overlay) {}

  /// The switches, for the panel's checkboxes to set.
  bool& high_contrast() { return high_contrast_; }
  bool& overlay() { return overlay_; }
  /// Window thread, every frame: says (say_brief) and logs a change of either switch.
  void poll(Voice& voice, const audio::MessageCatalog& messages);
  /// A new visitor: high contrast as the kiosk started, without a word.
  void new_visitor() { high_contrast_ = said_contrast_ = start_contrast_; }

 private:
  bool start_contrast_;
  bool high_contrast_, overlay_;
  bool said_contrast_, said_overlay_;  // the switches as last said
};

}  // namespace hk::app
