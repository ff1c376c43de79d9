// The kiosk: window, drawing, keys, servo thread, audio and flow put together (issue 5).
#include "kiosk_app.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl2.h>
#include <spdlog/spdlog.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "audio/system.hpp"
#include "audio_settings.hpp"
#include "config/load.hpp"
#include "describe.hpp"
#include "haptics/hand_path.hpp"
#include "haptics/sim_pantograph.hpp"
#include "haptics/triple_buffer.hpp"
#include "image_scene.hpp"
#include "kiosk_flow.hpp"
#include "picture_library.hpp"
#include "servo_core.hpp"
#include "servo_thread.hpp"
#include "simulation.hpp"
#include "stick_service.hpp"

#ifndef HK_DATA_DIR
#define HK_DATA_DIR "data"
#endif

namespace hk::app {
namespace {

// ---- scripted input ---------------------------------------------------------------------------------
struct ScriptLine {
  int frame = 0;
  std::string what;  // "key", "cursor", "move", "stick", "unstick", "wait_loaded"
  std::string key;   // key name, or the stick's folder
  Vec2 cursor_m;
};

const std::map<std::string, KioskKey>& key_names() {
  static const std::map<std::string, KioskKey> m{{"help", KioskKey::Help},         {"next", KioskKey::Next},
                                                 {"previous", KioskKey::Previous}, {"describe", KioskKey::Describe},
                                                 {"finer", KioskKey::Finer},       {"coarser", KioskKey::Coarser},
                                                 {"volume_up", KioskKey::VolumeUp}, {"volume_down", KioskKey::VolumeDown},
                                                 {"tutorial", KioskKey::Tutorial}, {"other", KioskKey::Other}};
  return m;
}

std::vector<ScriptLine> load_script(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("script '" + path + "': cannot read the file");
  std::vector<ScriptLine> out;
  std::string line;
  int n = 0;
  while (std::getline(f, line)) {
    ++n;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    ScriptLine s;
    ss >> s.frame >> s.what;
    bool ok = static_cast<bool>(ss) && s.frame >= 0;
    if (ok && s.what == "key") ok = static_cast<bool>(ss >> s.key) && key_names().count(s.key);
    else if (ok && s.what == "cursor") ok = static_cast<bool>(ss >> s.cursor_m.x >> s.cursor_m.y);
    else if (ok && s.what == "stick") ok = static_cast<bool>(ss >> s.key);
    else if (ok && s.what != "move" && s.what != "unstick" && s.what != "wait_loaded") ok = false;
    if (!ok) {
      throw std::runtime_error("script '" + path + "': line " + std::to_string(n) +
                               " is not 'FRAME key NAME', 'FRAME cursor X_M Y_M', 'FRAME move', 'FRAME stick DIR', 'FRAME unstick' or 'FRAME wait_loaded'");
    }
    out.push_back(s);
  }
  return out;
}

// ---- what is on the device and on the screen ----------------------------------------------------------
struct Shown {
  std::vector<Polyline> polylines;                     // level 0 source curves (for Describe)
  std::vector<std::vector<std::vector<Vec2>>> levels;  // [curve][level] → points
  std::vector<bool> closed;
  cv::Mat picture;                                     // BGR, empty for tutorial shapes
  vision::PxToM px_to_m{1, 0, 0};
  const Scene* scene = nullptr;                        // the published scene (read-only here; for the overlay)
  std::vector<TextBlockM> text_blocks;                 // a document page's text (Describe reads the one under the hand)
};

std::unique_ptr<vision::BlockEventSource> block_events(bool hotplug) {
  if (!hotplug) return nullptr;
  try {
    return std::make_unique<vision::UdevBlockEventSource>();
  } catch (const std::exception& e) {
    spdlog::warn("usb sticks: no hot-plug ({}); the kiosk runs on without sticks", e.what());
    return nullptr;
  }
}

class App final : public KioskEffects {
 public:
  App(const KioskOptions& o, const config::Settings& s)
      : opt_(o), s_(s), audio_(audio_params_from(s)), half_{s.workspace.width_m / 2, s.workspace.height_m / 2},
        sp_(servo_params_from(s)), device_(sim_params_from(s), {0.0, -0.9 * s.workspace.height_m / 2}),
        core_(device_, cue_params(), &audio_.cues()),
        sticks_(s, block_events(o.hotplug), o.mount_root.empty() ? std::string(vision::kDefaultStickMountRoot) : o.mount_root) {
    pictures_ = list_pictures(o.library.empty() ? std::string(HK_DATA_DIR) + "/pictures" : o.library);
    device_.open();
    hand_ = hand_params_from(s);
    cursor_.back() = device_.true_position_m();
    cursor_.publish();
    level_ = s.haptics.level;
    auto_level_ = s.haptics.level_mode == "auto";
    high_contrast_ = o.high_contrast;
    overlay_ = o.overlay;
  }

  void start_servo() {
    ServoThreadParams tp;
    tp.rate_hz = s_.haptics.servo_rate_hz;
    servo_ = std::make_unique<ServoThread>(core_, tp, [this](double dt) {
      // The simulated pantograph: the model hand pulls the handle towards the cursor.
      const Vec2 target = cursor_.read();
      device_.step(dt, model_hand_force(hand_, target, device_.true_position_m(), device_.velocity_m_per_s()));
    });
  }
  void stop_servo() {
    if (servo_) servo_->stop();
  }

  // ---- KioskEffects ----
  void say(const std::string& text) override {
    spdlog::info("say: {}", text);
    last_said_ = text;
    audio_.say_text(text);
  }
  const std::string& last_said() const { return last_said_; }
  void show_tutorial(TutorialShape shape) override {
    Shown sh;
    sh.polylines = {tutorial_polyline(shape, half_)};
    publish(std::move(sh), std::make_unique<Scene>(Scene::build({tutorial_polyline(shape, half_)}, s_.haptics.max_levels)), -1 - static_cast<int>(shape));
  }
  int show_picture(int index) override {
    ImageScene is = build_image_scene(pictures_[static_cast<std::size_t>(index)], s_);
    const int shapes = static_cast<int>(is.scene->curve_count());
    show_built(is, index);
    shown_page_ = 0;
    return shapes;
  }
  /// Puts a built scene on the device and the screen (the old one's force fades out first: ServoCore).
  void show_built(ImageScene& is, int id) {
    Shown sh;
    sh.polylines = is.polylines;
    sh.picture = is.picture.empty() ? cv::imread(is.image_path, cv::IMREAD_COLOR) : is.picture;
    sh.px_to_m = is.px_to_m;
    sh.text_blocks = is.text_blocks;
    publish(std::move(sh), std::move(is.scene), id, text_block_regions(is.text_blocks));
  }
  int picture_count() const override { return static_cast<int>(pictures_.size()); }
  std::string describe() override {
    if (shown_page_ > 0) {
      // A document page: the block of text under the hand is read; elsewhere, what the page holds.
      if (const TextBlockM* b = text_block_at(shown_.text_blocks, core_.display().proxy_m)) {
        return audio_.messages().text(audio::MessageId::text_block, {{"text", b->text}});
      }
      const std::string page = describe_page(static_cast<int>(shown_.text_blocks.size()), count_figures(shown_.polylines));
      return shown_.polylines.empty() ? page : page + " " + describe_scene(shown_.polylines, half_);
    }
    return describe_scene(shown_.polylines, half_);
  }
  void show_document(int document, int page) override { sticks_.load(stick_id_, document, page); }
  void forget_stick() override {
    sticks_.forget();
    stick_id_ = 0;
  }

  /// Window thread, every frame: news of sticks and finished loads, handed to the flow.
  void poll_sticks(KioskFlow& flow, double now_s) {
    for (StickNews& n : sticks_.poll_news()) {
      if (n.kind == StickNews::Kind::Inserted) {
        stick_id_ = n.stick;
        std::vector<StickEntry> entries;
        for (const ListedDocument& d : n.documents) entries.push_back({d.doc.display_name, d.doc.kind == vision::DocumentKind::Pdf, d.pages});
        stick_busy_ = !entries.empty();
        flow.stick_inserted(entries, now_s);
      } else if (n.kind == StickNews::Kind::Refused) {
        stick_busy_ = false;
        flow.stick_refused(n.reason, now_s);
      } else {
        stick_id_ = 0;
        stick_busy_ = false;
        flow.stick_removed(now_s);
      }
    }
    for (LoadedDocument& d : sticks_.poll_loaded()) {
      if (d.stick != stick_id_) continue;  // a stick taken out or forgotten meanwhile
      DocumentResult r;
      r.document = d.document;
      r.page = d.page;
      if (d.scene) {
        ImageScene& is = *d.scene;
        r.ok = true;
        r.description = is.page > 0 ? describe_page(static_cast<int>(is.text_blocks.size()), count_figures(is.polylines))
                                    : describe_shapes(static_cast<int>(is.scene->curve_count()));
        show_built(is, 1000 + d.document * 100000 + d.page);
        shown_page_ = is.page;
      } else {
        r.reason = d.reason;
      }
      stick_busy_ = false;
      flow.document_ready(r, now_s);
    }
    if (flow.loading()) stick_busy_ = true;
  }
  /// Whether stick work (scan or load) may still bring news (scripted runs wait for it).
  bool stick_busy() const { return stick_busy_; }
  void insert_stick_folder(const std::string& dir) {
    stick_busy_ = true;
    sticks_.insert_folder(dir);
  }
  void remove_stick_folder() {
    stick_busy_ = true;  // until the news of the removal arrives
    sticks_.remove_folder();
  }
  bool change_level(int delta) override {
    // From the level in use (chosen by hand speed in auto mode): the visitor's choice then holds until
    // the session ends.
    const int next = level() + delta;
    if (next < 0 || next > s_.haptics.max_levels) return false;
    level_ = next;
    auto_level_ = false;
    core_.request_level(level_);
    return true;
  }
  bool change_volume(int delta) override { return delta > 0 ? audio_.volume_up() : audio_.volume_down(); }
  void new_session() override {
    if (servo_) {  // the servo thread's timing, once per visitor's session
      const ServoTimingStats t = servo_->take_stats();
      spdlog::info("session: servo {} ticks, {} missed deadlines, lateness p50 {:.0f} p99 {:.0f} max {:.0f} us, tick work p99 {:.0f} us",
                   t.ticks, t.missed_deadlines, t.lateness_p50_us, t.lateness_p99_us, t.lateness_max_us, t.compute_p99_us);
    }
    audio_.new_session();
    level_ = s_.haptics.level;
    auto_level_ = s_.haptics.level_mode == "auto";
    core_.request_level(auto_level_ ? ServoCore::kAutoLevel : level_);
    high_contrast_ = opt_.high_contrast;
  }

  // ---- window side ----
  void set_cursor(Vec2 m) {
    cursor_.back() = m;
    cursor_.publish();
  }
  ServoCore& core() { return core_; }
  audio::AudioSystem& audio() { return audio_; }
  const Shown& shown() const { return shown_; }
  int shown_id() const { return shown_id_; }
  /// Level in use (the servo thread's, which follows the hand's speed in auto mode).
  int level() { return core_.display().level; }
  Vec2 half() const { return half_; }
  bool& high_contrast() { return high_contrast_; }
  bool& overlay() { return overlay_; }
  ServoThread* servo() { return servo_.get(); }
  int find_picture(const std::string& path) const {
    for (std::size_t i = 0; i < pictures_.size(); ++i) {
      if (std::filesystem::equivalent(pictures_[i], path)) return static_cast<int>(i);
    }
    return -1;
  }
  void add_picture_first(const std::string& path) { pictures_.insert(pictures_.begin(), path); }
  void collect() { core_.collect_retired(); }

 private:
  CueTrackerParams cue_params() const {
    CueTrackerParams p;
    p.period_s = 1.0 / s_.haptics.servo_rate_hz;
    p.workspace_half_extent_m = half_;
    return p;
  }
  void publish(Shown sh, std::unique_ptr<Scene> scene, int id, std::vector<Aabb> text_boxes = {}) {
    const Scene& sc = *scene;
    sh.levels.resize(sc.curve_count());
    sh.closed.resize(sc.curve_count());
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      sh.closed[c] = sc.curve(c).closed;
      for (int l = 0; l < sc.curve(c).levels; ++l) {
        const Vec2* p = sc.points(c, l);
        sh.levels[c].emplace_back(p, p + sc.curve(c).point_count[l]);
      }
    }
    ServoParams sp = sp_;
    sp.level = auto_level_ ? s_.haptics.level : level_;  // auto: where the policy starts
    sp.auto_level = auto_level_;
    auto bundle = std::make_unique<SceneBundle>(std::move(scene), sp);
    bundle->id = id;
    bundle->text_blocks_m = std::move(text_boxes);
    sh.scene = bundle->scene.get();
    shown_ = std::move(sh);
    shown_id_ = id;
    core_.publish(std::move(bundle));
  }

  KioskOptions opt_;
  config::Settings s_;
  audio::AudioSystem audio_;
  Vec2 half_;
  ServoParams sp_;
  SimulatedPantograph device_;
  ModelHandParams hand_;
  ServoCore core_;
  TripleBuffer<Vec2> cursor_;
  std::unique_ptr<ServoThread> servo_;
  std::vector<std::string> pictures_;
  Shown shown_;
  int level_ = 1;           // the fixed level (auto_level_ false)
  bool auto_level_ = true;  // levels from hand speed
  bool high_contrast_ = false, overlay_ = false;
  std::string last_said_;
  int shown_id_ = -100;
  int shown_page_ = 0;      // a document page shown (from 1), 0 for a picture
  int stick_id_ = 0;        // the stick the flow browses (StickNews::stick), 0 for none
  bool stick_busy_ = false;
  StickService sticks_;     // last: its threads stop first
};

// ---- drawing (OpenGL 2, legacy pipeline: one draw per frame of a few thousand vertices) ---------------
// The documented view mapping (kiosk_app.hpp): the bottom 14 % of the screen is left to the captions.
struct View {
  int w = 0, h = 0;
  double s = 1;  // [px/m]
  double px(double x) const { return w / 2.0 + s * x; }
  double py(double y) const { return 0.43 * h - s * y; }
  Vec2 to_m(double x_px, double y_px) const { return {(x_px - w / 2.0) / s, (0.43 * h - y_px) / s}; }
};

View make_view(int w, int h, Vec2 half) { return {w, h, 0.9 * std::min(w / (2 * half.x), 0.8 * h / (2 * half.y))}; }

void disc(const View& v, Vec2 c, double r_px, bool filled) {
  glBegin(filled ? GL_TRIANGLE_FAN : GL_LINE_LOOP);
  for (int k = 0; k < 24; ++k) {
    const double a = 2 * M_PI * k / 24;
    glVertex2d(v.px(c.x) + r_px * std::cos(a), v.py(c.y) + r_px * std::sin(a));
  }
  glEnd();
}

void draw_frame(App& app, const View& v, GLuint tex, bool have_tex, int tex_w, int tex_h) {
  glViewport(0, 0, v.w, v.h);
  glClearColor(0.05f, 0.05f, 0.08f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glOrtho(0, v.w, v.h, 0, -1, 1);  // pixels, y down
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  const Shown& sh = app.shown();
  const bool hc = app.high_contrast();
  // The picture, in the workspace where its pixels map.
  if (have_tex) {
    const vision::PxToM& m = sh.px_to_m;
    const double x0 = m.x_m(-0.5), x1 = m.x_m(tex_w - 0.5), y0 = m.y_m(-0.5), y1 = m.y_m(tex_h - 0.5);
    glEnable(GL_TEXTURE_2D);
    glBindTexture(GL_TEXTURE_2D, tex);
    const float dim = hc ? 0.25f : 0.8f;
    glColor4f(dim, dim, dim, 1.0f);
    glBegin(GL_QUADS);
    glTexCoord2f(0, 0); glVertex2d(v.px(x0), v.py(y0));
    glTexCoord2f(1, 0); glVertex2d(v.px(x1), v.py(y0));
    glTexCoord2f(1, 1); glVertex2d(v.px(x1), v.py(y1));
    glTexCoord2f(0, 1); glVertex2d(v.px(x0), v.py(y1));
    glEnd();
    glDisable(GL_TEXTURE_2D);
  }
  // The usable rectangle's frame.
  glColor4f(0.4f, 0.4f, 0.45f, 1.0f);
  glLineWidth(1.0f);
  glBegin(GL_LINE_LOOP);
  glVertex2d(v.px(-app.half().x), v.py(-app.half().y));
  glVertex2d(v.px(app.half().x), v.py(-app.half().y));
  glVertex2d(v.px(app.half().x), v.py(app.half().y));
  glVertex2d(v.px(-app.half().x), v.py(app.half().y));
  glEnd();
  // Text blocks of a document page (spoken, not felt): pale blue frames, for a companion who sees.
  glColor4f(0.45f, 0.7f, 1.0f, hc ? 1.0f : 0.8f);
  glLineWidth(hc ? 3.0f : 1.5f);
  for (const TextBlockM& b : sh.text_blocks) {
    glBegin(GL_LINE_LOOP);
    glVertex2d(v.px(b.lo_m.x), v.py(b.lo_m.y));
    glVertex2d(v.px(b.hi_m.x), v.py(b.lo_m.y));
    glVertex2d(v.px(b.hi_m.x), v.py(b.hi_m.y));
    glVertex2d(v.px(b.lo_m.x), v.py(b.hi_m.y));
    glEnd();
  }
  // The curves at the level in use: bright yellow (RGB 255, 220, 0), thicker in high contrast.
  glColor4f(1.0f, 220.0f / 255.0f, 0.0f, 1.0f);
  glLineWidth(hc ? 6.0f : 3.0f);
  for (std::size_t c = 0; c < sh.levels.size(); ++c) {
    const int l = std::min<int>(app.level(), static_cast<int>(sh.levels[c].size()) - 1);
    glBegin(sh.closed[c] ? GL_LINE_LOOP : GL_LINE_STRIP);
    for (const Vec2& p : sh.levels[c][static_cast<std::size_t>(l)]) glVertex2d(v.px(p.x), v.py(p.y));
    glEnd();
  }
  // Error boxes of the level in use (operator overlay).
  if (app.overlay() && sh.scene) {
    const Scene& sc = *sh.scene;
    glColor4f(0.2f, 0.9f, 1.0f, 0.5f);
    glLineWidth(1.0f);
    for (std::size_t c = 0; c < sc.curve_count(); ++c) {
      const int l = sc.clamp_level(c, app.level());
      const std::uint32_t segs = sc.curve(c).point_count[l] - (sc.curve(c).closed ? 0 : 1);
      for (std::uint32_t k = 0; k < segs; ++k) {
        const ErrorBox& b = sc.box(sc.node_of({static_cast<std::int32_t>(c), l, static_cast<std::int32_t>(k)}));
        const Vec2 n = left_perp(b.axis);
        glBegin(GL_LINE_LOOP);
        for (const auto& [u, w] : {std::pair{b.u_min, b.n_min}, {b.u_max, b.n_min}, {b.u_max, b.n_max}, {b.u_min, b.n_max}}) {
          const Vec2 q = b.origin_m + u * b.axis + w * n;
          glVertex2d(v.px(q.x), v.py(q.y));
        }
        glEnd();
      }
    }
  }
  const ServoDisplayState& d = app.core().display();
  // The boundary section the servo thread keeps (operator overlay): magenta, segment boxes or node rectangles.
  if (app.overlay() && sh.scene && d.scene_id == app.shown_id()) {
    const Scene& sc = *sh.scene;
    glColor4f(1.0f, 0.3f, 1.0f, 0.8f);
    glLineWidth(1.5f);
    const int n = std::min(d.section_count, ServoDisplayState::kMaxSection);
    for (int i = 0; i < n; ++i) {
      const std::uint32_t node = d.section[i];
      if (node >= sc.node_count()) continue;
      glBegin(GL_LINE_LOOP);
      if (sc.is_segment(node)) {
        const ErrorBox& b = sc.box(node);
        const Vec2 nrm = left_perp(b.axis);
        for (const auto& [u, w] : {std::pair{b.u_min, b.n_min}, {b.u_max, b.n_min}, {b.u_max, b.n_max}, {b.u_min, b.n_max}}) {
          const Vec2 q = b.origin_m + u * b.axis + w * nrm;
          glVertex2d(v.px(q.x), v.py(q.y));
        }
      } else {
        const Aabb& a = sc.aabb(node);
        glVertex2d(v.px(a.lo.x), v.py(a.lo.y));
        glVertex2d(v.px(a.hi.x), v.py(a.lo.y));
        glVertex2d(v.px(a.hi.x), v.py(a.hi.y));
        glVertex2d(v.px(a.lo.x), v.py(a.hi.y));
      }
      glEnd();
    }
  }
  // Handle (red ring), proxy (white disc, on the curve in contact: seed §4), force arrow from the handle.
  glLineWidth(2.0f);
  glColor4f(1.0f, 0.3f, 0.3f, 1.0f);
  disc(v, d.handle_m, 9, false);
  glColor4f(1.0f, 1.0f, 1.0f, 1.0f);
  disc(v, d.proxy_m, 6, true);
  const double f = length(d.force_n);
  if (f > 0.05) {
    const Vec2 tip = d.handle_m + 0.006 * d.force_n;  // 6 mm per newton
    glColor4f(0.3f, 1.0f, 0.4f, 1.0f);
    glBegin(GL_LINES);
    glVertex2d(v.px(d.handle_m.x), v.py(d.handle_m.y));
    glVertex2d(v.px(tip.x), v.py(tip.y));
    glEnd();
    disc(v, tip, 3, true);
  }
}

const char* state_name(KioskState s) {
  switch (s) {
    case KioskState::Attract: return "attract";
    case KioskState::Tutorial: return "tutorial";
    case KioskState::Picture: return "picture";
  }
  return "?";
}

// GLFW key code of a [keys] name (config/settings.hpp lists the names; the config refuses others).
int glfw_key(const std::string& name) {
  if (name.size() == 1 && name[0] >= 'A' && name[0] <= 'Z') return GLFW_KEY_A + (name[0] - 'A');
  if (name.size() == 1 && name[0] >= '0' && name[0] <= '9') return GLFW_KEY_0 + (name[0] - '0');
  if (name.size() >= 2 && name[0] == 'F' && std::isdigit(static_cast<unsigned char>(name[1]))) return GLFW_KEY_F1 + std::stoi(name.substr(1)) - 1;
  if (name.size() == 4 && name.rfind("KP_", 0) == 0 && std::isdigit(static_cast<unsigned char>(name[3]))) return GLFW_KEY_KP_0 + (name[3] - '0');
  static const std::map<std::string, int> named{{"SPACE", GLFW_KEY_SPACE},         {"ENTER", GLFW_KEY_ENTER},
                                                {"TAB", GLFW_KEY_TAB},             {"BACKSPACE", GLFW_KEY_BACKSPACE},
                                                {"LEFT", GLFW_KEY_LEFT},           {"RIGHT", GLFW_KEY_RIGHT},
                                                {"UP", GLFW_KEY_UP},               {"DOWN", GLFW_KEY_DOWN},
                                                {"PAGE_UP", GLFW_KEY_PAGE_UP},     {"PAGE_DOWN", GLFW_KEY_PAGE_DOWN},
                                                {"HOME", GLFW_KEY_HOME},           {"END", GLFW_KEY_END},
                                                {"INSERT", GLFW_KEY_INSERT},       {"DELETE", GLFW_KEY_DELETE},
                                                {"MINUS", GLFW_KEY_MINUS},         {"EQUAL", GLFW_KEY_EQUAL},
                                                {"KP_ADD", GLFW_KEY_KP_ADD},       {"KP_SUBTRACT", GLFW_KEY_KP_SUBTRACT},
                                                {"KP_ENTER", GLFW_KEY_KP_ENTER}};
  const auto it = named.find(name);
  return it == named.end() ? GLFW_KEY_UNKNOWN : it->second;
}

std::map<int, KioskKey> key_map(const config::KeysSettings& k) {
  return {{glfw_key(k.help), KioskKey::Help},         {glfw_key(k.next), KioskKey::Next},
          {glfw_key(k.previous), KioskKey::Previous}, {glfw_key(k.describe), KioskKey::Describe},
          {glfw_key(k.finer), KioskKey::Finer},       {glfw_key(k.coarser), KioskKey::Coarser},
          {glfw_key(k.volume_up), KioskKey::VolumeUp}, {glfw_key(k.volume_down), KioskKey::VolumeDown},
          {glfw_key(k.tutorial), KioskKey::Tutorial}};
}

struct WindowState {
  App* app = nullptr;
  KioskFlow* flow = nullptr;
  double now_s = 0;
  bool windowed = false;
  std::map<int, KioskKey> keys;  // GLFW key → action, from [keys]
};

}  // namespace

int run_kiosk(const KioskOptions& o) {
  const config::Settings s = o.config_path.empty() ? config::Settings{} : config::load_settings(o.config_path);
  const std::vector<ScriptLine> script = o.script.empty() ? std::vector<ScriptLine>{} : load_script(o.script);
  if (!o.screenshot.empty()) {
    const std::filesystem::path p(o.screenshot);
    if (p.extension() != ".png") throw std::runtime_error("--screenshot '" + o.screenshot + "': must name a .png file");
    const auto parent = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
    if (!std::filesystem::is_directory(parent)) throw std::runtime_error("--screenshot '" + o.screenshot + "': folder '" + parent.string() + "' does not exist");
    if (o.frames < 1 || o.frames > 100000) throw std::runtime_error("--frames " + std::to_string(o.frames) + " is outside [1, 100000]");
  }
  App app(o, s);
  KioskFlowParams fp;
  fp.timeout_s = s.kiosk.timeout_s;
  fp.warning_s = s.kiosk.warning_s;
  KioskFlow flow(app, app.audio().messages(), fp);

  glfwSetErrorCallback([](int code, const char* what) { spdlog::error("glfw {}: {}", code, what ? what : ""); });
  if (!glfwInit()) throw std::runtime_error("display: GLFW could not start (no X display? run under xvfb-run for headless use)");
  struct GlfwTerm {
    ~GlfwTerm() { glfwTerminate(); }
  } glfw_term;
  GLFWmonitor* monitor = o.windowed ? nullptr : glfwGetPrimaryMonitor();
  int w = 1280, h = 720;
  if (monitor) {
    const GLFWvidmode* mode = glfwGetVideoMode(monitor);
    w = mode->width;
    h = mode->height;
    glfwWindowHint(GLFW_REFRESH_RATE, mode->refreshRate);
  }
  GLFWwindow* win = glfwCreateWindow(w, h, "haptic-kiosk", monitor, nullptr);
  if (!win) throw std::runtime_error("display: cannot open a window");
  glfwMakeContextCurrent(win);
  glfwSwapInterval(1);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui_ImplGlfw_InitForOpenGL(win, true);
  ImGui_ImplOpenGL2_Init();

  WindowState ws{&app, &flow, 0.0, o.windowed, key_map(s.keys)};
  glfwSetWindowUserPointer(win, &ws);
  glfwSetKeyCallback(win, [](GLFWwindow* wnd, int key, int, int action, int) {
    if (action != GLFW_PRESS) return;
    auto* st = static_cast<WindowState*>(glfwGetWindowUserPointer(wnd));
    if (key == GLFW_KEY_O) {
      st->app->overlay() = !st->app->overlay();
      return;
    }
    if (key == GLFW_KEY_C) {
      st->app->high_contrast() = !st->app->high_contrast();
      return;
    }
    if (key == GLFW_KEY_ESCAPE && st->windowed) {
      glfwSetWindowShouldClose(wnd, 1);
      return;
    }
    const auto it = st->keys.find(key);
    st->flow->key(it == st->keys.end() ? KioskKey::Other : it->second, st->now_s);
  });

  app.start_servo();
  if (!o.stick.empty()) app.insert_stick_folder(o.stick);
  if (!o.show.empty()) {
    int idx = app.find_picture(o.show);
    if (idx < 0) {
      app.add_picture_first(o.show);
      idx = 0;
    }
    flow.key(KioskKey::Other, 0.0);  // wake: welcome + tutorial
    for (int i = 0; i < 3; ++i) flow.key(KioskKey::Next, 0.0);  // through the tutorial to picture 1
    for (int i = 0; i < idx; ++i) flow.key(KioskKey::Next, 0.0);
  }

  GLuint tex = 0;
  glGenTextures(1, &tex);
  const Scene* tex_for = nullptr;
  bool have_tex = false;
  int tex_w = 0, tex_h = 0;
  const auto t0 = std::chrono::steady_clock::now();
  Vec2 last_moved_at;
  bool have_baseline = false;
  bool mouse_seen = false, mouse_moved = false;
  Vec2 mouse_rest;  // [px]
  int frame = 0;
  std::size_t next_script = 0;
  int held_frames = 0;
  constexpr int kMaxHeldFrames = 3600;  // 60 s of scripted frames
  while (!glfwWindowShouldClose(win)) {
    glfwPollEvents();
    const bool scripted = !o.screenshot.empty();
    ws.now_s = scripted ? frame / 60.0 : std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    app.poll_sticks(flow, ws.now_s);
    bool holding = false;  // a scripted run waits (frames do not count) while stick work is under way
    while (next_script < script.size() && script[next_script].frame <= frame) {
      const ScriptLine& l = script[next_script];
      if (l.what == "wait_loaded" && app.stick_busy()) {
        if (++held_frames > kMaxHeldFrames) throw std::runtime_error("script '" + o.script + "': stick work did not finish within 60 s");
        holding = true;
        break;
      }
      ++next_script;
      if (l.what == "key") flow.key(key_names().at(l.key), ws.now_s);
      if (l.what == "cursor") app.set_cursor(l.cursor_m);
      if (l.what == "move") flow.handle_moved(ws.now_s);
      if (l.what == "stick") app.insert_stick_folder(l.key);
      if (l.what == "unstick") app.remove_stick_folder();
    }
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(win, &fw, &fh);
    const View view = make_view(fw, fh, app.half());
    if (!scripted) {
      // The mouse stands in for the visitor's hand, but only once it has moved: where the pointer happens
      // to rest when the kiosk starts must not drag the handle (and wake the kiosk).
      double cx = 0, cy = 0;
      glfwGetCursorPos(win, &cx, &cy);
      if (!mouse_seen) {
        mouse_seen = true;
        mouse_rest = {cx, cy};
      }
      mouse_moved = mouse_moved || std::hypot(cx - mouse_rest.x, cy - mouse_rest.y) > 2.0;
    }
    if (!scripted && mouse_moved) {
      double cx = 0, cy = 0;
      glfwGetCursorPos(win, &cx, &cy);
      int ww = 0, wh = 0;
      glfwGetWindowSize(win, &ww, &wh);
      const View wv = make_view(ww, wh, app.half());
      const Vec2 m = wv.to_m(cx, cy);
      app.set_cursor({std::clamp(m.x, -app.half().x, app.half().x), std::clamp(m.y, -app.half().y, app.half().y)});
    }
    const ServoDisplayState& d = app.core().display();
    if (!have_baseline && d.tick > 0) {  // the first sample from the servo thread: where the handle rests
      have_baseline = true;
      last_moved_at = d.handle_m;
    }
    if (have_baseline && length(d.handle_m - last_moved_at) > 0.005) {
      last_moved_at = d.handle_m;
      flow.handle_moved(ws.now_s);
    }
    flow.tick(ws.now_s);
    app.collect();
    // Upload the picture when it changed.
    if (app.shown().scene != tex_for) {
      tex_for = app.shown().scene;
      have_tex = !app.shown().picture.empty();
      if (have_tex) {
        cv::Mat rgb;
        cv::cvtColor(app.shown().picture, rgb, cv::COLOR_BGR2RGB);
        tex_w = rgb.cols;
        tex_h = rgb.rows;
        glBindTexture(GL_TEXTURE_2D, tex);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, rgb.cols, rgb.rows, 0, GL_RGB, GL_UNSIGNED_BYTE, rgb.data);
      }
    }
    draw_frame(app, view, tex, have_tex, tex_w, tex_h);
    ImGui_ImplOpenGL2_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    {
      // Captions: what the kiosk says, large, for a companion who sees and for visitors with some sight.
      const std::string caption = flow.state() == KioskState::Attract ? app.audio().messages().raw(audio::MessageId::attract) : app.last_said();
      ImGui::SetNextWindowPos(ImVec2(0.05f * fw, 0.86f * fh));
      ImGui::SetNextWindowSize(ImVec2(0.9f * fw, 0.13f * fh));
      ImGui::SetNextWindowBgAlpha(0.75f);
      ImGui::Begin("caption", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoInputs | ImGuiWindowFlags_NoSavedSettings);
      ImGui::SetWindowFontScale(std::max(1.5f, fh / 400.0f));
      ImGui::TextWrapped("%s", caption.c_str());
      ImGui::End();
    }
    if (app.overlay()) {
      ImGui::SetNextWindowPos(ImVec2(10, 10));
      ImGui::Begin("operator", nullptr, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove);
      ImGui::Text("state %s   picture %d   level %d%s", state_name(flow.state()), flow.picture() + 1, app.level(), d.auto_level ? " (auto)" : "");
      ImGui::Text("contact %d   curve %d   force %.2f N", static_cast<int>(d.state), d.curve, length(d.force_n));
      if (ServoThread* st = app.servo()) {
        const ServoTimingStats t = st->stats();
        ImGui::Text("servo %.0f Hz %s   late p50 %.0f p99 %.0f max %.0f us", s.haptics.servo_rate_hz, st->realtime() ? "FIFO" : "normal",
                    t.lateness_p50_us, t.lateness_p99_us, t.lateness_max_us);
        ImGui::Text("tick work p50 %.0f p99 %.0f us   missed %lld", t.compute_p50_us, t.compute_p99_us, static_cast<long long>(t.missed_deadlines));
      }
      ImGui::Text("volume %d/10   sound %s   cues dropped %llu", app.audio().volume().step(), app.audio().sound_output() ? "on" : "no device",
                  static_cast<unsigned long long>(app.audio().cues_dropped()));
      ImGui::End();
    }
    ImGui::Render();
    ImGui_ImplOpenGL2_RenderDrawData(ImGui::GetDrawData());
    if (!holding) ++frame;
    if (scripted && frame >= o.frames) {
      glFinish();
      std::vector<unsigned char> px(static_cast<std::size_t>(fw) * static_cast<std::size_t>(fh) * 3);
      glPixelStorei(GL_PACK_ALIGNMENT, 1);
      glReadPixels(0, 0, fw, fh, GL_RGB, GL_UNSIGNED_BYTE, px.data());
      cv::Mat img(fh, fw, CV_8UC3, px.data());
      cv::Mat out;
      cv::flip(img, out, 0);
      cv::cvtColor(out, out, cv::COLOR_RGB2BGR);
      if (!cv::imwrite(o.screenshot, out)) throw std::runtime_error("--screenshot '" + o.screenshot + "': cannot write the PNG");
      break;
    }
    glfwSwapBuffers(win);
    if (scripted) std::this_thread::sleep_for(std::chrono::microseconds(16667));  // 60 Hz of servo time per frame
  }
  app.stop_servo();
  glDeleteTextures(1, &tex);
  ImGui_ImplOpenGL2_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(win);
  return 0;
}

}  // namespace hk::app
