// The visitor's walk through the kiosk, driven by scripted keys and handle motion, checked by what the
// kiosk says (issue 5: attract → tutorial → picture → next picture → time-out → attract), and the
// spoken description of a picture.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "describe.hpp"
#include "kiosk_flow.hpp"

namespace hk::app {
namespace {

struct Recorder final : KioskEffects {
  std::vector<std::string> said;
  std::vector<std::string> shown;
  int level = 1, volume = 7, sessions = 0;
  void say(const std::string& t) override { said.push_back(t); }
  void show_tutorial(TutorialShape s) override { shown.push_back("tutorial " + std::to_string(static_cast<int>(s))); }
  int show_picture(int i) override {
    shown.push_back("picture " + std::to_string(i));
    return i == 1 ? 1 : 4;
  }
  int picture_count() const override { return 3; }
  std::string describe() override { return "4 shapes. A large closed shape in the middle."; }
  bool change_level(int d) override {
    if (level + d < 0 || level + d > 3) return false;
    level += d;
    return true;
  }
  bool change_volume(int d) override {
    if (volume + d < 1 || volume + d > 10) return false;
    volume += d;
    return true;
  }
  void new_session() override {
    ++sessions;
    level = 1;
    volume = 7;
  }
};

TEST(KioskFlow, AttractTutorialPicturesTimeoutAndBack) {
  Recorder fx;
  const auto& en = audio::MessageCatalog::english();
  KioskFlow flow(fx, en, {120.0, 20.0});
  flow.tick(10.0);
  EXPECT_EQ(flow.state(), KioskState::Attract);
  EXPECT_TRUE(fx.said.empty()) << "attract is silent until someone comes";

  flow.handle_moved(11.0);
  EXPECT_EQ(flow.state(), KioskState::Tutorial);
  ASSERT_EQ(fx.said.size(), 1u);
  EXPECT_EQ(fx.said.back().rfind("Welcome.", 0), 0u);
  EXPECT_NE(fx.said.back().find("First, a square."), std::string::npos);
  EXPECT_EQ(fx.shown.back(), "tutorial 0");

  flow.key(KioskKey::Next, 20.0);
  EXPECT_EQ(fx.said.back(), en.raw(audio::MessageId::tutorial_circle));
  EXPECT_EQ(fx.shown.back(), "tutorial 1");
  flow.key(KioskKey::Next, 30.0);
  EXPECT_EQ(fx.said.back(), en.raw(audio::MessageId::tutorial_triangle));
  flow.key(KioskKey::Next, 40.0);
  EXPECT_EQ(flow.state(), KioskState::Picture);
  EXPECT_EQ(fx.said.back(), "Well done. Here is the first picture. Picture 1 of 3. It has 4 shapes.");
  EXPECT_EQ(fx.shown.back(), "picture 0");

  flow.key(KioskKey::Next, 50.0);
  EXPECT_EQ(fx.said.back(), "Picture 2 of 3. It has one shape.");
  flow.key(KioskKey::Previous, 51.0);
  flow.key(KioskKey::Previous, 52.0);
  EXPECT_EQ(fx.said.back(), "Picture 3 of 3. It has 4 shapes.") << "previous wraps round";
  flow.key(KioskKey::Describe, 53.0);
  EXPECT_EQ(fx.said.back(), "4 shapes. A large closed shape in the middle.");
  flow.key(KioskKey::Finer, 54.0);
  EXPECT_EQ(fx.said.back(), "More detail.");
  flow.key(KioskKey::Finer, 55.0);
  EXPECT_EQ(fx.said.back(), "This is the finest detail.");
  flow.key(KioskKey::VolumeUp, 56.0);
  EXPECT_EQ(fx.said.back(), "Louder.");
  EXPECT_EQ(fx.volume, 8);

  // Quiet for 100 s: the warning, 20 s before the end. A key extends the time.
  const std::size_t before = fx.said.size();
  flow.tick(155.0);
  EXPECT_EQ(fx.said.size(), before) << "no warning before timeout - warning";
  flow.tick(156.0);
  ASSERT_EQ(fx.said.size(), before + 1);
  EXPECT_NE(fx.said.back().find("in 20 seconds"), std::string::npos) << fx.said.back();
  flow.tick(157.0);
  EXPECT_EQ(fx.said.size(), before + 1) << "warned once";
  flow.handle_moved(160.0);
  flow.tick(200.0);
  EXPECT_EQ(flow.state(), KioskState::Picture) << "the motion extended the session";
  flow.tick(280.0);
  EXPECT_EQ(flow.state(), KioskState::Attract);
  EXPECT_EQ(fx.said.back(), en.raw(audio::MessageId::goodbye));
  EXPECT_EQ(fx.sessions, 1);
  EXPECT_EQ(fx.volume, 7) << "the operator's default again";

  // The next visitor starts with the tutorial again.
  flow.key(KioskKey::Other, 300.0);
  EXPECT_EQ(flow.state(), KioskState::Tutorial);
}

TEST(KioskFlow, EveryKeyIsAnsweredInSpeech) {
  Recorder fx;
  KioskFlow flow(fx, audio::MessageCatalog::english());
  flow.key(KioskKey::Other, 0.0);  // wake
  double t = 1.0;
  for (KioskState want : {KioskState::Tutorial, KioskState::Picture}) {
    if (want == KioskState::Picture) {
      for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, t++);
    }
    ASSERT_EQ(flow.state(), want);
    for (KioskKey k : {KioskKey::Help, KioskKey::Describe, KioskKey::Finer, KioskKey::Coarser, KioskKey::VolumeUp, KioskKey::VolumeDown,
                       KioskKey::Other}) {
      const std::size_t n = fx.said.size();
      flow.key(k, t++);
      EXPECT_EQ(fx.said.size(), n + 1) << "key " << static_cast<int>(k) << " in state " << static_cast<int>(want);
    }
  }
}

Polyline rect(Vec2 c, Vec2 half, bool closed = true) {
  Polyline p;
  p.closed = closed;
  p.points_m = {{c.x - half.x, c.y - half.y}, {c.x + half.x, c.y - half.y}, {c.x + half.x, c.y + half.y}, {c.x - half.x, c.y + half.y}};
  return p;
}

TEST(Describe, SizesKindsAndPlaces) {
  const Vec2 half{0.07, 0.045};
  const std::vector<Polyline> curves{rect({0.06, -0.035}, {0.004, 0.004}), rect({0, 0}, {0.05, 0.03}),
                                     rect({-0.05, 0.03}, {0.006, 0.003}, false)};
  EXPECT_EQ(describe_scene(curves, half),
            "3 shapes. A large closed shape in the middle, a small line at the top left, and a small closed shape at the bottom right.");
  EXPECT_EQ(describe_scene({curves[1]}, half), "One shape. A large closed shape in the middle.");
  EXPECT_EQ(describe_scene({}, half), "There are no shapes in this picture.");
  std::vector<Polyline> many(6, rect({0.05, 0.03}, {0.002, 0.002}));
  many.push_back(rect({-0.04, 0}, {0.015, 0.01}));
  EXPECT_EQ(describe_scene(many, half, 2), "7 shapes. A medium closed shape on the left, a small closed shape at the top right, and 5 more, smaller ones.");
}

}  // namespace
}  // namespace hk::app
