#pragma once
/// @file camera_desk.hpp
/// The camera as the visitor uses it: the Capture key starts a capture on the camera's worker
/// (CaptureService), its news (advice to say, a picture taken, a failure or a time-out) handed to the flow,
/// and a picture taken put on the stage with the Shutter earcon. It answers the visitor's flow's CameraEffects
/// (kiosk_effects.hpp). Window thread only.

#include <string>

#include "audio/system.hpp"
#include "config/settings.hpp"
#include "pictures/capture_service.hpp"
#include "pictures/picture_shelf.hpp"
#include "visit/kiosk_effects.hpp"
#include "visit/stage.hpp"
#include "visit/voice.hpp"

namespace hk::app {

class KioskFlow;

/// The camera on the stage. Not thread-safe: the window thread (the capture's worker is its own).
class CameraDesk final : public CameraEffects {
 public:
  /// `camera`: the camera chosen (choose_camera), or none; `looked_for`: whether one was looked for ([camera]
  /// source "auto" probed, or a source named), so that announce() says when none was found. `stage`,
  /// `shelf`, `voice` and `audio` outlive the desk.
  CameraDesk(const config::Settings& settings, CameraChoice camera, bool looked_for, Stage& stage, PictureShelf& shelf,
             Voice& voice, audio::AudioSystem& audio);

  /// Starts a capture on the camera's worker (CaptureService::start); false without a camera. A library
  /// picture still being built is not wanted any more.
  bool start_capture() override;
  /// Stops the capture under way.
  void cancel_capture() override { capture_.cancel(); }

  /// Whether there is a camera to capture from.
  bool available() const { return capture_.available(); }
  /// Says which camera there is: "There is a camera: press … to feel a picture of your own." or "No
  /// camera was found." (nothing when [camera] source is "none", or none was looked for). Logged either way.
  void announce(const config::KeysSettings& keys);
  /// Window thread, every frame: the capture's news handed to the flow: advice to say; a picture taken (the
  /// Shutter earcon, its scene put on the stage with the fade, KioskFlow::capture_done); a failure or a
  /// time-out (KioskFlow::capture_failed).
  void poll(KioskFlow& flow, double now_s);
  /// The capture under way's latest frame and page (for the preview), empty when none is under way.
  CapturePreview preview() const { return capture_.busy() ? capture_.preview() : CapturePreview{}; }
  /// New settings, for the next capture.
  void set_settings(const config::Settings& s) { capture_.set_settings(s); }

 private:
  Stage& stage_;
  PictureShelf& shelf_;
  Voice& voice_;
  audio::AudioSystem& audio_;
  bool looked_for_;
  int captures_ = 0;        // captures shown so far (ids kFirstCaptureId, kFirstCaptureId − 1, ...)
  CaptureService capture_;  // last: its worker stops first
};

}  // namespace hk::app
