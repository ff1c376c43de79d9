// The camera as the visitor uses it (camera_desk.hpp).
#include "visit/camera_desk.hpp"

#include <spdlog/spdlog.h>

#include "pictures/capture.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {

CameraDesk::CameraDesk(const config::Settings& settings, CameraChoice camera, bool looked_for, Stage& stage,
                       PictureShelf& shelf, Voice& voice, audio::AudioSystem& audio)
    : stage_(stage),
      shelf_(shelf),
      voice_(voice),
      audio_(audio),
      looked_for_(looked_for),
      capture_(settings, std::move(camera)) {}

bool CameraDesk::start_capture() {
  const bool started = capture_.start();
  if (started) shelf_.drop_want();  // the visitor's own picture comes next, not a library picture still being built
  return started;
}

void CameraDesk::announce(const config::KeysSettings& keys) {
  const CameraChoice& c = capture_.camera();
  if (c.spec) {
    spdlog::info("camera: {}", c.name);
    voice_.say(audio_.messages().text(audio::MessageId::camera_ready, {}, key_args(keys)));
    return;
  }
  spdlog::info("camera: none ({})", c.why);
  if (!looked_for_) return;
  voice_.say(audio_.messages().text(audio::MessageId::camera_none));
}

void CameraDesk::poll(KioskFlow& flow, double now_s) {
  for (CaptureNews& n : capture_.poll()) {
    switch (n.kind) {
      case CaptureNews::Kind::Advice:
        flow.capture_advice(advice_message(n.advice), now_s);
        break;
      case CaptureNews::Kind::Captured: {
        audio_.play(audio::CueKind::Shutter);
        const int shapes = static_cast<int>(n.scene->scene->curve_count());
        stage_.show(*n.scene, kFirstCaptureId - captures_++, ShownSource{}, {});
        flow.capture_done(shapes, now_s);
        break;
      }
      case CaptureNews::Kind::Failed:
        flow.capture_failed(false, now_s);
        break;
      case CaptureNews::Kind::TimedOut:
        flow.capture_failed(true, now_s);
        break;
    }
  }
}

}  // namespace hk::app
