#pragma once
/// @file hud.hpp
/// The ImGui windows over the scene that are not the operator's panel: the captions (what the kiosk says,
/// large, for a companion who sees and for visitors with some sight) and, with the operator overlay on,
/// one line of servo status in the corner.

#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"

namespace hk::app {

/// Inside an ImGui frame: the caption band at the bottom of a `fw` x `fh` screen.
void draw_captions(KioskRuntime& runtime, const KioskFlow& flow, int fw, int fh);

/// Inside an ImGui frame: the overlay's status lines (state, level, contact, servo timing, sound).
void draw_overlay_status(KioskRuntime& runtime, const KioskFlow& flow);

}  // namespace hk::app
