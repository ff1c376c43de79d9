// The Capture key in the visitor's flow: started, guided aloud, cancelled by any key,
// captured or failed, and said so; without a camera the key says there is none and the help does not name it.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "every_effect.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {
namespace {

struct CameraRecorder final : hk::test::EveryEffect {
  bool camera = true;
  int started = 0, cancelled = 0;
  std::vector<std::string> said;
  void say(const std::string& t) override { said.push_back(t); }
  void show_tutorial(TutorialShape) override {}
  int show_picture(int) override { return 2; }
  int picture_count() const override { return 3; }
  std::string describe() override { return "2 shapes."; }
  bool change_level(int) override { return true; }
  bool change_volume(int) override { return true; }
  void new_session() override {}
  void show_document(int, int) override {}
  void forget_stick() override {}
  bool start_capture() override {
    if (!camera) return false;
    ++started;
    return true;
  }
  void cancel_capture() override { ++cancelled; }
};

/// A flow woken and past the tutorial, on picture 1.
KioskFlow on_picture(CameraRecorder& fx, bool camera) {
  KioskFlowParams p;
  p.camera = camera;
  KioskFlow flow(fx, audio::MessageCatalog::english(), p);
  flow.key(KioskKey::Other, 0.0);
  for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 0.1 * (i + 1));
  return flow;
}

TEST(CaptureFlow, GuidedThenCapturedAndSaid) {
  CameraRecorder fx;
  KioskFlow flow = on_picture(fx, true);
  flow.key(KioskKey::Capture, 1.0);
  EXPECT_EQ(fx.started, 1);
  EXPECT_TRUE(flow.view().capturing);
  EXPECT_EQ(fx.said.back().rfind("Place the picture under the camera, face up.", 0), 0u) << fx.said.back();
  flow.capture_advice(audio::MessageId::capture_move_left, 2.0);
  EXPECT_EQ(fx.said.back(), "Move it left.");
  flow.capture_advice(audio::MessageId::capture_hold_still, 3.0);
  EXPECT_EQ(fx.said.back(), "Hold still.");
  flow.capture_done(5, 4.5);
  EXPECT_EQ(fx.said.back(), "Captured. It has 5 shapes.");
  EXPECT_FALSE(flow.view().capturing);
  EXPECT_EQ(flow.view().state, KioskState::Picture);
  // A late advice after the end is not said.
  const std::size_t n = fx.said.size();
  flow.capture_advice(audio::MessageId::capture_move_left, 4.6);
  EXPECT_EQ(fx.said.size(), n);
  flow.capture_done(1, 4.7);
  EXPECT_EQ(fx.said.size(), n) << "nothing under way: ignored";
}

TEST(CaptureFlow, OneShapeNoShapeFailureAndTimeOutAreSaid) {
  CameraRecorder fx;
  KioskFlow flow = on_picture(fx, true);
  flow.key(KioskKey::Capture, 1.0);
  flow.capture_done(1, 2.0);
  EXPECT_EQ(fx.said.back(), "Captured. It has one shape.");
  flow.key(KioskKey::Capture, 3.0);
  flow.capture_done(0, 4.0);
  EXPECT_EQ(fx.said.back(), "Captured, but I found no shapes in it.");
  flow.key(KioskKey::Capture, 5.0);
  flow.capture_failed(false, 6.0);
  EXPECT_EQ(fx.said.back(), "The camera does not answer. Press the space bar to try again.");
  flow.key(KioskKey::Capture, 7.0);
  flow.capture_failed(true, 8.0);
  EXPECT_EQ(fx.said.back(),
            "I could not take the picture: it did not lie still long enough. Press the space bar to try again.");
  EXPECT_EQ(fx.started, 4);
  EXPECT_EQ(fx.cancelled, 0);
}

TEST(CaptureFlow, AnyKeyCancelsAndDoesNothingElse) {
  for (KioskKey k : {KioskKey::Next, KioskKey::Capture, KioskKey::Describe, KioskKey::Other}) {
    CameraRecorder fx;
    KioskFlow flow = on_picture(fx, true);
    const int picture = flow.view().picture;
    flow.key(KioskKey::Capture, 1.0);
    flow.key(k, 2.0);
    EXPECT_EQ(fx.cancelled, 1);
    EXPECT_FALSE(flow.view().capturing);
    EXPECT_EQ(fx.said.back(), "Capture stopped.");
    EXPECT_EQ(flow.view().picture, picture) << "the key did not also move on";
    EXPECT_EQ(fx.started, 1);
  }
}

/// Help's second layer, every group of it (Next steps through), joined.
std::string every_key(KioskFlow& flow, CameraRecorder& fx) {
  flow.key(KioskKey::Help, 2.0);
  flow.key(KioskKey::Help, 2.5);
  std::string all = fx.said.back();
  for (int g = 0; g < 10 && fx.said.back().find("That is every key.") == std::string::npos; ++g) {
    flow.key(KioskKey::Next, 2.6 + 0.1 * g);
    all += " " + fx.said.back();
  }
  return all;
}

TEST(CaptureFlow, WithoutACameraTheKeySaysSoAndTheHelpDoesNotNameIt) {
  CameraRecorder fx;
  fx.camera = false;
  KioskFlow flow = on_picture(fx, false);
  flow.key(KioskKey::Capture, 1.0);
  EXPECT_EQ(fx.said.back(), "There is no camera on this kiosk.");
  EXPECT_FALSE(flow.view().capturing);
  EXPECT_EQ(every_key(flow, fx).find("camera"), std::string::npos);
  CameraRecorder fx2;
  KioskFlow with = on_picture(fx2, true);
  const std::string help = every_key(with, fx2);
  EXPECT_NE(help.find("Press the space bar to feel a picture of your own under the camera."), std::string::npos)
      << help;
}

TEST(CaptureFlow, GuidanceKeepsTheSessionAliveAndTheTimeOutCancels) {
  CameraRecorder fx;
  KioskFlowParams p;
  p.camera = true;
  p.timeout_s = 30;
  p.warning_s = 10;
  KioskFlow flow(fx, audio::MessageCatalog::english(), p);
  flow.key(KioskKey::Other, 0.0);
  flow.key(KioskKey::Capture, 1.0);
  for (double t = 10; t <= 100; t += 10) {
    flow.capture_advice(audio::MessageId::capture_move_up, t);
    flow.tick(t + 1);
  }
  EXPECT_TRUE(flow.view().capturing) << "advice is activity: no time-out while the visitor places the picture";
  EXPECT_EQ(fx.cancelled, 0);
  flow.tick(200);
  EXPECT_FALSE(flow.view().capturing);
  EXPECT_EQ(fx.cancelled, 1);
  EXPECT_EQ(flow.view().state, KioskState::Attract);
}

}  // namespace
}  // namespace hk::app
