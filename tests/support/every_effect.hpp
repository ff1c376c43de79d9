#pragma once
// A stand-in for every part of the kiosk the visitor's flow asks of (kiosk_effects.hpp): tests derive their
// recorders from it and hand it to a KioskFlow, which takes it for each effect.

#include "visit/kiosk_effects.hpp"

namespace hk::test {

/// Every effect interface in one object; a test overrides what it records.
struct EveryEffect : app::SpeechEffects,
                     app::StageEffects,
                     app::LibraryEffects,
                     app::StickEffects,
                     app::CameraEffects,
                     app::TourEffects,
                     app::SessionEffects {};

}  // namespace hk::test
