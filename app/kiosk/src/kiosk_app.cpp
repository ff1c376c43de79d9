// The kiosk: the window (window.hpp), the runtime (kiosk_runtime.hpp), the visitor's flow, the operator's
// panel and scripted input put together. This file owns the frame loop and the routing of input.
#include "kiosk/kiosk_app.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <thread>
#include <utility>

#include "config/device_profile.hpp"
#include "config/keys.hpp"
#include "config/load.hpp"
#include "config/store.hpp"
#include "formats/app_error.hpp"
#include "kiosk/frame_stats.hpp"
#include "kiosk/hud.hpp"
#include "kiosk/keymap.hpp"
#include "kiosk/operator_panel.hpp"
#include "kiosk/script.hpp"
#include "kiosk/view.hpp"
#include "kiosk/window.hpp"
#include "pictures/picture_library.hpp"
#include "runtime/event_log.hpp"
#include "visit/fleet_settings.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/kiosk_runtime.hpp"
#include "visit/operator_session.hpp"

#ifndef HK_DATA_DIR
#define HK_DATA_DIR "data"
#endif

namespace hk::app {
namespace {

std::int64_t unix_now_s() { return static_cast<std::int64_t>(std::time(nullptr)); }

/// The settings the kiosk starts with: the file, or (when it is corrupt) its .bak or the defaults, said in
/// the log and kept for the operator's panel; then the museum's fleet file beside it over them
/// (fleet_settings.hpp), or, when that is refused, the file alone (said the same way).
struct StartSettings {
  config::Settings settings;
  std::string notice;
  std::string fleet_path;            ///< the fleet file in force ("" none)
  std::vector<std::string> managed;  ///< the keys it sets
};

/// `start` with the fleet file beside `path` over it, when there is one and it holds.
void add_fleet(StartSettings& start, const std::string& path) {
  const std::string fleet_path = fleet_path_for(path);
  try {
    if (std::optional<FleetSettings> f = load_fleet(fleet_path)) {
      start.settings = with_fleet(start.settings, *f);
      start.fleet_path = f->path;
      start.managed = f->keys;
      spdlog::info("settings: {} sets {} of them (the museum's; locked in the panel)", f->path, f->keys.size());
    }
  } catch (const config::ConfigError& e) {
    log_event(KioskEvent::settings_refused, spdlog::level::err,
              fmt::format("settings: {}; the museum's settings are not used, the kiosk runs on {}", e.what(), path));
    if (!start.notice.empty()) start.notice += " ";
    start.notice += e.what();
  }
}

StartSettings start_settings(const std::string& path) {
  if (path.empty()) return {};
  config::LoadedSettings l = config::load_settings_with_fallback(path, unix_now_s());
  if (!l.notice.empty()) {
    log_event(KioskEvent::settings_refused, spdlog::level::err, "settings: " + l.notice);
    if (l.from == config::LoadedSettings::From::backup) {
      // The kiosk runs on the .bak: it becomes the settings file again (the .bak stays as it is), so the PIN
      // in it opens the panel and the next save has a file to keep as .bak.
      try {
        config::SaveOptions so;
        so.keep_backup = false;
        config::save_settings_atomic(l.settings, path, so);
      } catch (const std::exception& e) {
        spdlog::error("settings: the .bak could not be made the settings file again: {}", e.what());
      }
    }
  }
  StartSettings start{l.settings, l.notice, {}, {}};
  add_fleet(start, path);
  return start;
}

void check_screenshot_options(const KioskOptions& o) {
  if (o.screenshot.empty()) return;
  const std::filesystem::path p(o.screenshot);
  if (p.extension() != ".png") throw AppError("--screenshot '" + o.screenshot + "': must name a .png file");
  const auto parent = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(parent))
    throw AppError("--screenshot '" + o.screenshot + "': folder '" + parent.string() + "' does not exist");
  if (o.frames < 1 || o.frames > 100000)
    throw AppError("--frames " + std::to_string(o.frames) + " is outside [1, 100000]");
}

/// What --frame-stats measured, said in its file.
constexpr const char* kScriptedFrames =
    "scripted run (--screenshot): interval = work + buffer swap + the fixed 16.7 ms pause per frame (under Xvfb the "
    "swap is "
    "Mesa's software GL drawing and copying the frame, tens of ms at 1920 x 1080, not a vsync wait); "
    "work = frame start to before the swap";
constexpr const char* kLiveFrames =
    "live run: interval = frame start to next frame start, paced by the buffer swap (vsync on a monitor; Xvfb has no "
    "vsync, there the swap's cost paces it); work = frame start to before the swap";

/// Input routing and the frame loop's state: what a key does depends on who has the keyboard.
class Kiosk final : public ScriptTarget {
 public:
  Kiosk(const KioskOptions& o, KioskRuntime& runtime, KioskFlow& flow, OperatorSession& session, OperatorPanel& panel,
        KioskWindow& window)
      : o_(o), rt_(runtime), flow_(flow), session_(session), panel_(panel), window_(window) {
    keys_changed();
  }

  /// The visitor's keys and the operator's chord, again from the settings in use.
  void keys_changed() {
    keys_ = visitor_key_map(rt_.settings().keys);
    chord_ = config::parse_chord(rt_.settings().operator_.open_chord)
                 .value_or(config::KeyChord{true, true, false, false, "O"});
  }

  /// One event, real or scripted.
  void input(const InputEvent& e) override {
    if (captures_keyboard(session_.state())) {
      session_.touch(now_s_);
      if (e.kind == InputEvent::Kind::key && e.action == GLFW_PRESS && e.key == GLFW_KEY_ESCAPE) {
        session_.close(unix_now_s());
        return;
      }
      window_.to_imgui(e);  // the panel's: typed into its boxes, never a visitor's action
      return;
    }
    const auto it = e.kind == InputEvent::Kind::key ? keys_.find(e.key) : keys_.end();
    const bool help = it != keys_.end() && it->second == KioskKey::Help;
    if (e.kind == InputEvent::Kind::mouse_button || (e.kind == InputEvent::Kind::key && e.action == GLFW_RELEASE)) {
      if (help && e.action == GLFW_RELEASE) flow_.help_held(false);      // learning mode ends
      if (e.kind == InputEvent::Kind::key && e.key == lone_modifier_) {  // a modifier pressed and let go alone
        lone_modifier_ = 0;
        flow_.key(KioskKey::Other, now_s_, key_name_of(e.key));
      }
      window_.to_imgui(e);  // buttons and releases always (ImGui must not see a key held for ever)
      return;
    }
    if (e.kind != InputEvent::Kind::key || e.action != GLFW_PRESS) return;
    if (chord_pressed(chord_, e.key, e.mods)) {
      lone_modifier_ = 0;
      session_.chord(now_s_, unix_now_s());
      return;
    }
    // A modifier is half of a chord: answered when it is let go alone, else with its chord.
    if (is_modifier_key(e.key)) {
      lone_modifier_ = e.mods == 0 ? e.key : 0;
      return;
    }
    lone_modifier_ = 0;
    if (e.mods & (GLFW_MOD_CONTROL | GLFW_MOD_ALT | GLFW_MOD_SUPER)) {  // no visitor key has modifiers: a chord
      flow_.key(KioskKey::Other, now_s_);                               // Ctrl+Q, Alt+F4: "That key does nothing here."
      return;
    }
    if (e.key == GLFW_KEY_ESCAPE && o_.windowed) {
      window_.request_close();
      return;
    }
    // High contrast and the overlay are the operator's (the panel): O and C are keys like any other here.
    const KioskKey k = it == keys_.end() ? KioskKey::Other : it->second;
    note_picture_key(k);
    flow_.key(k, now_s_, key_name_of(e.key));
    if (help) flow_.help_held(true);  // held: the next keys are named, not done (learning mode)
  }

  // ---- ScriptTarget ----
  void action_key(KioskKey k) override {
    note_picture_key(k);
    flow_.key(k, now_s_);
  }
  void cursor(Vec2 m) override { rt_.tour().set_cursor(m); }
  void moved() override { flow_.handle_moved(now_s_); }
  void stick(const std::string& dir) override { rt_.sticks().insert_folder(dir); }
  void unstick() override { rt_.sticks().remove_folder(); }
  bool busy() override {
    return rt_.sticks().busy() || rt_.stage().text_busy() || rt_.library().busy() ||
           session_.state() == PanelState::checking;
  }
  std::optional<WidgetRect> widget(const std::string& name) override { return panel_.widget(name); }

  /// The mouse stands in for the visitor's hand, but only once it has moved: where the pointer happens to
  /// rest when the kiosk starts must not drag the handle (and wake the kiosk). Not while the operator's
  /// panel is open (the operator's pointer is not a visitor's hand).
  void follow_mouse() {
    const auto [cx, cy] = window_.cursor();
    if (!mouse_seen_) {
      mouse_seen_ = true;
      mouse_rest_ = {cx, cy};
    }
    mouse_moved_ = mouse_moved_ || std::hypot(cx - mouse_rest_.x, cy - mouse_rest_.y) > 2.0;
    if (!mouse_moved_ || session_.state() == PanelState::open) return;
    const auto [ww, wh] = window_.window_size();
    const Vec2 m = make_view(ww, wh, rt_.half()).to_m(cx, cy);
    rt_.tour().set_cursor({std::clamp(m.x, -rt_.half().x, rt_.half().x), std::clamp(m.y, -rt_.half().y, rt_.half().y)});
  }

  /// The handle moved noticeably (5 mm) since the last report, or slides along a shape (1 mm in contact since
  /// the last report): the visitor is there. A handle resting against a wall, or pinned, keeps no visit alive.
  void watch_handle() {
    const ServoDisplayState& d = rt_.core().display();
    if (d.state != ContactState::Free && length(d.handle_m - last_touched_at_) > 0.001) {
      last_touched_at_ = d.handle_m;
      flow_.touching(now_s_);
    }
    if (!have_baseline_ && d.tick > 0) {  // the first sample from the servo thread: where the handle rests
      have_baseline_ = true;
      last_moved_at_ = d.handle_m;
    }
    if (have_baseline_ && length(d.handle_m - last_moved_at_) > 0.005) {
      last_moved_at_ = d.handle_m;
      flow_.handle_moved(now_s_);
    }
  }

  /// Whether a Next or Previous key went to the visitor's flow since the last call (--frame-stats).
  bool take_picture_key() { return std::exchange(picture_key_, false); }

  double now_s_ = 0;

 private:
  void note_picture_key(KioskKey k) { picture_key_ = picture_key_ || k == KioskKey::Next || k == KioskKey::Previous; }

  const KioskOptions& o_;
  KioskRuntime& rt_;
  KioskFlow& flow_;
  OperatorSession& session_;
  OperatorPanel& panel_;
  KioskWindow& window_;
  std::map<int, KioskKey> keys_;
  config::KeyChord chord_;
  bool mouse_seen_ = false, mouse_moved_ = false;
  Vec2 mouse_rest_;
  bool have_baseline_ = false;
  Vec2 last_moved_at_;
  Vec2 last_touched_at_;
  bool picture_key_ = false;
  int lone_modifier_ = 0;  // a modifier key pressed with no other key down yet (GLFW key code), else 0
};

/// --show: straight to a picture, past the welcome and the tutorial.
void show_first(const std::string& path, KioskRuntime& rt, KioskFlow& flow) {
  int idx = rt.library().find(path);
  if (idx < 0) {
    rt.library().add_first(path);
    idx = 0;
  }
  flow.key(KioskKey::Other, 0.0);                             // wake: welcome + tutorial
  for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 0.0);  // through the tutorial to picture 1
  for (int i = 0; i < idx; ++i) flow.key(KioskKey::Next, 0.0);
}

/// The runtime's options from the command line and the settings in use.
RuntimeOptions runtime_options(const KioskOptions& o, const config::Settings& settings) {
  RuntimeOptions ro;
  ro.shipped_library = std::string(HK_DATA_DIR) + "/pictures";
  ro.library = !o.library.empty() ? o.library : library_dir(settings);
  if (ro.library.empty()) ro.library = ro.shipped_library;
  // Watched unless it is the shipped folder, or --show puts a picture from elsewhere first.
  ro.library_settle_s = ro.library != ro.shipped_library && o.show.empty() ? kLibrarySettle_s : 0.0;
  ro.hotplug = o.hotplug;
  ro.mount_root = o.mount_root;
  ro.high_contrast = o.high_contrast;
  ro.overlay = o.overlay;
  // Scripted runs (documentation, tests) never depend on hardware they were not told of: [device] type "auto"
  // stays simulated there, a type the settings name ("haply") is looked for as at the kiosk.
  ro.probe_usb_device = o.screenshot.empty() || config::is_usb_type(settings.device.type);
  ro.probe_camera = o.screenshot.empty();
  ro.device = o.device;
  // Scripted runs (documentation, tests) build every scene afresh and leave no cache behind.
  ro.scene_cache_dir = o.screenshot.empty() ? scene_cache_dir(settings) : std::string{};
  return ro;
}

/// Starts the servo thread, says which device and camera are in use, and takes --stick and --show.
void start_kiosk(const KioskOptions& o, const RuntimeOptions& ro, KioskRuntime& rt, KioskFlow& flow) {
  rt.start_servo();
  if (ro.probe_usb_device || !ro.device.empty()) rt.announce_device();
  rt.camera().announce(rt.settings().keys);
  if (!o.stick.empty()) rt.sticks().insert_folder(o.stick);
  if (!o.show.empty()) show_first(o.show, rt, flow);
}

/// One frame's input and time: events (real, then the script's step), sticks, capture, text, device, mouse,
/// handle, tour, display modes, the flow and the operator's session. Returns whether the script holds this
/// frame (waiting for the runtime).
bool update_frame(Kiosk& kiosk, KioskRuntime& rt, KioskFlow& flow, OperatorSession& session, KioskWindow& window,
                  ScriptPlayer& script, bool scripted, int frame) {
  for (const InputEvent& e : window.poll()) kiosk.input(e);
  rt.poll(&flow, kiosk.now_s_);  // pictures, sticks, capture, text, device
  // A scripted run's clock is its frame count: it holds while a picture asked for is being built, so the
  // same script shows the same frames however fast the machine builds.
  const bool holding = scripted && (rt.library().busy() || script.step(frame, kiosk));
  if (!scripted) kiosk.follow_mouse();
  kiosk.watch_handle();
  rt.poll_after_input();  // tour, display switches, retired scenes
  flow.tick(kiosk.now_s_);
  session.tick(kiosk.now_s_, unix_now_s());
  return holding;
}

/// The frame's drawing, not yet shown: the scene, the camera preview while capturing, then (ImGui) the
/// captions, the overlay's status and the operator's panel.
void draw_frame(KioskRuntime& rt, KioskFlow& flow, OperatorSession& session, OperatorPanel& panel, KioskWindow& window,
                const ScriptPlayer& script, bool scripted, double now_s, PictureTexture& texture,
                CapturePreviewView& preview) {
  const auto [fw, fh] = window.framebuffer_size();
  texture.update(rt.stage().shown());
  draw_scene(rt, make_view(fw, fh, rt.half()), texture);
  if (flow.view().capturing) preview.draw(rt.camera().preview(), make_view(fw, fh, rt.half()), rt.half());
  window.begin_frame(scripted ? script.mouse() : std::nullopt);
  draw_captions(rt, flow, fw, fh);
  if (rt.switches().overlay() && session.state() != PanelState::open) draw_overlay_status(rt, flow);
  panel.draw(rt, flow, fw, fh, now_s, unix_now_s());
  window.end_frame();
}

}  // namespace

int run_kiosk(const KioskOptions& o) {
  check_screenshot_options(o);
  const StartSettings start = start_settings(o.config_path);
  const std::vector<ScriptLine> script_lines = o.script.empty() ? std::vector<ScriptLine>{} : load_script(o.script);

  const RuntimeOptions ro = runtime_options(o, start.settings);
  KioskRuntime rt(ro, start.settings);
  KioskFlow flow(rt.effects(), rt.audio().messages(), flow_params_from(start.settings, rt.camera().available()));

  KioskWindow window(o.windowed);
  const int picture_side = [&] {
    const auto [fw, fh] = window.framebuffer_size();
    return picture_side_px(make_view(fw, fh, rt.half()), rt.half());
  }();
  rt.set_screen_picture_side_px(picture_side);
  Kiosk* kiosk_ptr = nullptr;
  OperatorSession session(o.config_path, start.settings, start.notice, [&](const config::Settings& s) {
    const ApplyReport r = rt.apply_settings(s, flow);
    if (kiosk_ptr) kiosk_ptr->keys_changed();  // the visitor's keys, and the operator's chord
    return r;
  });
  session.set_fleet(start.fleet_path, start.managed);
  OperatorPanel panel(session);
  Kiosk kiosk(o, rt, flow, session, panel, window);
  kiosk_ptr = &kiosk;
  ScriptPlayer script(script_lines, o.script);
  start_kiosk(o, ro, rt, flow);
  log_event(KioskEvent::kiosk_started, spdlog::level::info,
            fmt::format("kiosk: started, {} library pictures, device {}", rt.library().picture_count(),
                        rt.devices().usb() ? "USB pantograph" : "simulated"));

  PictureTexture texture(picture_side);
  CapturePreviewView preview;
  const bool scripted = !o.screenshot.empty();
  // Allocated once, here: recording a frame never allocates (frame_stats.hpp).
  const auto stats = o.frame_stats.empty() ? nullptr : std::make_unique<FrameStats>();
  const auto t0 = std::chrono::steady_clock::now();
  int frame = 0;
  while (!window.should_close()) {
    if (stats) stats->frame_started(std::chrono::steady_clock::now());
    const Scene* const scene_at_start = rt.stage().shown().scene;
    const int id_at_start = rt.stage().shown_id();
    kiosk.now_s_ =
        scripted ? frame / 60.0 : std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const bool holding = update_frame(kiosk, rt, flow, session, window, script, scripted, frame);
    if (kiosk.take_picture_key() && stats) stats->picture_key(scene_at_start, id_at_start);
    draw_frame(rt, flow, session, panel, window, script, scripted, kiosk.now_s_, texture, preview);
    if (stats) stats->frame_drawn(std::chrono::steady_clock::now(), rt.stage().shown().scene, rt.stage().shown_id());
    if (!holding) ++frame;
    if (scripted && frame >= o.frames) {
      if (!cv::imwrite(o.screenshot, window.read_pixels()))
        throw AppError("--screenshot '" + o.screenshot + "': cannot write the PNG");
      break;
    }
    window.swap();
    if (scripted) std::this_thread::sleep_for(std::chrono::microseconds(16667));  // 60 Hz of servo time per frame
  }
  rt.devices().stop_servo();
  if (stats) {
    write_frame_stats(*stats, o.frame_stats, scripted ? kScriptedFrames : kLiveFrames);
    spdlog::info("{} -> {}", stats->log_line(), o.frame_stats);
  }
  return 0;
}

}  // namespace hk::app
