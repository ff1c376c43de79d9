#pragma once
/// @file random_visit.hpp
/// A seeded random visit to the kiosk without its window: what app/kiosk/src/kiosk_app.cpp's frame loop does each
/// frame (polls, the flow's tick, the handle watched for motion and sliding contact, the audio mix pulled as a
/// sound card would), the servo core stepped on its simulated pantograph (runtime_ticks.hpp), and around it,
/// drawn from one seed: every visitor key (the sentence and paragraph keys too), bursts of keys in one frame,
/// keys no action has and chords (as the window passes them: Other with the key's name), learning mode, a model
/// hand wandering to random targets, sticks of damaged files, of a picture and a PDF, or empty, put in and
/// taken out, and the operator applying settings. After every key it checks that the key was answered (a text
/// said; Volume while speech is heard and Pause are answered by the sound itself); at the end Finish twice and
/// a settling time, then that the kiosk is as a new visitor finds it.
///
/// Used by tests/app/test_random_visits.cpp (short runs) and bench/random_visits.cpp (long ones).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "config/settings.hpp"
#include "runtime_ticks.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"

namespace hk::test {

/// What a random visit is made of. Units in names.
struct RandomVisitParams {
  std::uint32_t seed = 1;
  int frames = 20000;               ///< window frames (60 a second of kiosk time)
  std::filesystem::path library;    ///< pictures
  std::filesystem::path data;       ///< tests/data (the sticks' files come from it)
  std::filesystem::path work;       ///< a folder of its own for the sticks
  double key_per_frame = 0.03;      ///< chance of a key in a frame (about 2 a second)
  double burst_per_frame = 0.002;   ///< chance of a burst of 3 to 8 keys in one frame
  double stick_per_frame = 0.0006;  ///< chance of a stick put in (or taken out, when one is in)
  double panel_per_frame = 0.0004;  ///< chance of the operator applying settings
  /// Chance of the visitor walking away for 150 s of kiosk time. The time-out ends the visit only once nothing is
  /// being said, and kiosk time here runs hundreds of times faster than the speaker synthesises, so a walk-away
  /// often ends with speech still under way: walk-aways test the warnings and the return, not the time-out.
  double leave_per_frame = 0.0;
  /// The sticks' PDF is a paragraph of 10 minutes' reading (read to its end even with nobody there: speech
  /// heard keeps a visit); false: a short titled PDF.
  bool long_text = true;
};

/// What happened, and what was wrong.
struct RandomVisitReport {
  int keys = 0, bursts = 0, sticks_in = 0, sticks_out = 0, panel_applies = 0, learning = 0;
  int sessions_ended = 0;                ///< visits ended by Finish (in the run) or by the time-out (a walk away)
  std::vector<std::string> unanswered;   ///< "frame F: key K said nothing"
  std::vector<std::string> left_behind;  ///< what the kiosk kept that a new visitor must not find
  int failures = 0;                      ///< actions answered with the sorry line (KioskFlow::failures)
};

/// Runs one visit; never throws for what the kiosk does (that goes in the report).
inline RandomVisitReport run_random_visit(const RandomVisitParams& p) {
  namespace fs = std::filesystem;
  using app::KioskKey;
  RandomVisitReport report;
  std::mt19937 rng(p.seed);
  auto chance = [&](double q) { return std::uniform_real_distribution<double>(0.0, 1.0)(rng) < q; };
  auto pick = [&](int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); };

  // Three sticks: damaged files beside a readable picture and PDF; a PDF alone; nothing at all.
  const fs::path sticks[] = {p.work / "damaged", p.work / "pdf", p.work / "empty"};
  for (const fs::path& s : sticks) fs::create_directories(s);
  fs::copy_file(p.data / "bad" / "bad_crc.png", sticks[0] / "bad_crc.png", fs::copy_options::overwrite_existing);
  fs::copy_file(p.data / "bad" / "damaged_idat.png", sticks[0] / "damaged_idat.png",
                fs::copy_options::overwrite_existing);
  fs::copy_file(p.data / "bad" / "empty.pdf", sticks[0] / "empty.pdf", fs::copy_options::overwrite_existing);
  fs::copy_file(p.data / "bad" / "truncated.pdf", sticks[0] / "truncated.pdf", fs::copy_options::overwrite_existing);
  fs::copy_file(p.data / "bad" / "pages_5000.pdf", sticks[1] / "pages_5000.pdf", fs::copy_options::overwrite_existing);
  fs::copy_file(p.data / "images" / "horse.png", sticks[0] / "horse.png", fs::copy_options::overwrite_existing);
  const fs::path pdf = p.data / "documents" / (p.long_text ? "long_paragraph.pdf" : "titled.pdf");
  fs::copy_file(pdf, sticks[0] / "manual.pdf", fs::copy_options::overwrite_existing);
  fs::copy_file(pdf, sticks[1] / "manual.pdf", fs::copy_options::overwrite_existing);

  config::Settings settings;
  settings.vision.ocr = "off";  // OCR's worker takes seconds a page: not what is visited here
  app::RuntimeOptions ro = headless_runtime_options(p.library);
  auto rt = std::make_unique<app::KioskRuntime>(ro, settings);
  app::KioskFlow flow(rt->effects(), rt->audio().messages(), app::KioskFlowParams{});

  const double dt_s = 1.0 / settings.haptics.servo_rate_hz;
  const int ticks_per_frame = static_cast<int>(std::lround(settings.haptics.servo_rate_hz / 60.0));
  std::vector<float> audio(800);  // 48 kHz / 60 Hz
  Vec2 target{0.0, 0.0};
  Vec2 watched = rt->core().display().handle_m, slid = watched;
  bool stick_in = false;
  const double half_w = settings.workspace.width_m / 2, half_h = settings.workspace.height_m / 2;
  auto hand = [&](const SimulatedPantograph& sim) {
    Vec2 f = 150.0 * (target - sim.true_position_m()) - 3.0 * sim.velocity_m_per_s();
    const double n = length(f);
    return n > 2.0 ? (2.0 / n) * f : f;
  };
  static const char* kStrayNames[] = {"Q", "Z", "F5", "TAB", "ESCAPE", ""};  // "" : a chord, unnamed
  // A key whose answer is a page or picture still being built: it is announced when it comes, or "Loading."
  // is said after loading_cue_s; checked this many frames later (loading_cue_s and a little more).
  const int answer_frames = static_cast<int>(std::ceil((app::KioskFlowParams{}.loading_cue_s + 0.1) * 60.0));
  struct Awaited {
    int due_frame;
    std::uint64_t said;
    std::string what;
  };
  std::vector<Awaited> awaited;

  auto press = [&](KioskKey k, double now_s, int frame) {
    const std::uint64_t said = rt->voice().texts_said();
    const bool heard = rt->voice().speaking();
    const std::string name = k == KioskKey::Other ? kStrayNames[pick(6)] : "";
    flow.key(k, now_s, name);
    ++report.keys;
    const bool volume = k == KioskKey::VolumeUp || k == KioskKey::VolumeDown;
    const bool silent_answer = (volume && heard) || k == KioskKey::Pause;
    const std::string what = "seed " + std::to_string(p.seed) + ", frame " + std::to_string(frame) + ": key " +
                             std::to_string(static_cast<int>(k)) + " (" + app::state_name(flow.view().state) +
                             (flow.view().source == app::KioskSource::Stick ? ", on a stick" : "") +
                             (flow.view().loading ? ", a page awaited" : "") +
                             (flow.view().picture_pending ? ", a picture awaited" : "") + ") said nothing";
    if (rt->voice().texts_said() != said || silent_answer) return;
    if (flow.view().loading || flow.view().picture_pending) {
      awaited.push_back({frame + answer_frames, said, what + " within " + std::to_string(answer_frames) + " frames"});
    } else {
      report.unanswered.push_back(what);
    }
  };
  auto check_awaited = [&](int frame) {
    for (auto it = awaited.begin(); it != awaited.end();) {
      if (rt->voice().texts_said() > it->said) {
        it = awaited.erase(it);
      } else if (frame >= it->due_frame) {
        report.unanswered.push_back(it->what + "; then: " + app::state_name(flow.view().state) +
                                    (flow.view().loading ? ", a page awaited" : "") +
                                    (flow.view().picture_pending ? ", a picture awaited" : "") +
                                    "; last said: " + rt->voice().last_said());
        it = awaited.erase(it);
      } else {
        ++it;
      }
    }
  };
  auto frame_step = [&](double now_s) {
    for (int t = 0; t < ticks_per_frame; ++t) runtime_tick(*rt, dt_s, hand);
    rt->poll(&flow, now_s);  // as the kiosk's frame: pictures, sticks, capture, text, device
    // The handle watched as the window does: motion wakes and keeps the visit, sliding contact keeps it.
    const app::ServoDisplayState& d = rt->core().display();
    if (length(d.handle_m - watched) > 0.005) {
      watched = d.handle_m;
      flow.handle_moved(now_s);
    }
    if (d.state != ContactState::Free && length(d.handle_m - slid) > 0.001) {
      slid = d.handle_m;
      flow.touching(now_s);
    }
    rt->poll_after_input();
    flow.tick(now_s);
    rt->audio().render(audio.data(), audio.size());
  };

  const int actions = static_cast<int>(KioskKey::Other) + 1;
  int away_until = -1;  // the visitor has walked away until this frame: no key, the hand at rest
  for (int frame = 0; frame < p.frames; ++frame) {
    const double now_s = frame / 60.0;
    if (frame < away_until) {
      const bool was_attract = flow.view().state == app::KioskState::Attract;
      frame_step(now_s);
      check_awaited(frame);
      if (!was_attract && flow.view().state == app::KioskState::Attract) ++report.sessions_ended;
      continue;
    }
    if (chance(p.leave_per_frame)) {
      away_until = frame + 150 * 60;
      continue;
    }
    if (frame % 120 == 0 && chance(0.5))
      target = {std::uniform_real_distribution<double>(-half_w, half_w)(rng),
                std::uniform_real_distribution<double>(-half_h, half_h)(rng)};
    if (chance(p.key_per_frame)) {
      const bool learn = chance(0.05);
      if (learn) {
        flow.help_held(true);
        ++report.learning;
      }
      press(static_cast<KioskKey>(pick(actions)), now_s, frame);
      if (learn) flow.help_held(false);
    }
    if (chance(p.burst_per_frame)) {
      ++report.bursts;
      for (int i = 0, n = 3 + pick(6); i < n; ++i) press(static_cast<KioskKey>(pick(actions)), now_s, frame);
    }
    if (chance(p.stick_per_frame)) {
      if (stick_in) {
        rt->sticks().remove_folder();
        ++report.sticks_out;
      } else {
        rt->sticks().insert_folder(sticks[pick(3)].string());
        ++report.sticks_in;
      }
      stick_in = !stick_in;
    }
    if (chance(p.panel_per_frame)) {
      config::Settings s = rt->settings();
      s.haptics.stiffness_n_per_m = s.haptics.stiffness_n_per_m == 800.0 ? 1200.0 : 800.0;
      s.vision.max_shapes = s.vision.max_shapes == 30 ? 20 : 30;  // the scene is built again
      rt->apply_settings(s, flow);
      ++report.panel_applies;
    }
    const bool was_attract = flow.view().state == app::KioskState::Attract;
    frame_step(now_s);
    check_awaited(frame);
    if (!was_attract && flow.view().state == app::KioskState::Attract) ++report.sessions_ended;
  }

  // The visitor leaves: what was under way settles (a stick put in at the last moment is announced: it wakes
  // the kiosk, as it should), then Finish twice; the stick stays in (a new visitor must not browse it).
  // The hand comes to rest where it is (2 s), so no motion wakes the kiosk again after Finish.
  double end_s = p.frames / 60.0;
  target = rt->core().display().handle_m;
  for (int f = 0; f < 120; ++f, end_s += 1.0 / 60.0) frame_step(end_s);
  // As a scripted `wait` does: the kiosk's clock holds while the work ends (at most 60 s of the machine's).
  auto settle = [&](double now_s) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while ((rt->sticks().busy() || rt->library().busy() || rt->stage().text_busy()) &&
           std::chrono::steady_clock::now() < give_up) {
      frame_step(now_s);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  };
  settle(end_s);
  check_awaited(p.frames + answer_frames);
  if (flow.view().state != app::KioskState::Attract) {  // in Attract the first key would only wake the kiosk
    flow.key(KioskKey::Finish, end_s);                  // asks, or ends a visit whose Finish was asked a moment ago
    if (flow.view().state != app::KioskState::Attract) flow.key(KioskKey::Finish, end_s + 0.5);
  }
  settle(end_s + 0.5);
  auto expect = [&](bool ok, const std::string& what) {
    if (!ok)
      report.left_behind.push_back("seed " + std::to_string(p.seed) + ": " + what + " (" +
                                   app::state_name(flow.view().state) + "; last said: " + rt->voice().last_said() +
                                   ")");
  };
  expect(flow.view().state == app::KioskState::Attract, "the kiosk is not waiting for a visitor");
  expect(flow.view().source == app::KioskSource::Library, "Next and Previous would still walk the stick");
  expect(!rt->sticks().busy(), "the stick is still 'working'");
  expect(!rt->library().busy(), "a picture is still awaited");
  expect(!rt->tour().running(), "a guided tour still runs");
  expect(!flow.view().reading && !flow.view().in_help && !flow.view().capturing && !flow.view().warned,
         "reading, help, capture or a warning is still on");
  expect(rt->audio().volume().step() == settings.audio.volume_default_step, "the volume is not the operator's default");
  expect(rt->stage().auto_level(), "the level does not follow the hand again");
  report.failures = flow.view().failures;
  return report;
}

}  // namespace hk::test
