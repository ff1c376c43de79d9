#include "kiosk/script.hpp"

#include <GLFW/glfw3.h>

#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "config/keys.hpp"
#include "formats/app_error.hpp"
#include "kiosk/keymap.hpp"

namespace hk::app {
namespace {

const std::map<std::string, KioskKey>& action_names() {
  static const std::map<std::string, KioskKey> m{{"help", KioskKey::Help},
                                                 {"next", KioskKey::Next},
                                                 {"previous", KioskKey::Previous},
                                                 {"describe", KioskKey::Describe},
                                                 {"finer", KioskKey::Finer},
                                                 {"coarser", KioskKey::Coarser},
                                                 {"volume_up", KioskKey::VolumeUp},
                                                 {"volume_down", KioskKey::VolumeDown},
                                                 {"tutorial", KioskKey::Tutorial},
                                                 {"guide", KioskKey::Guide},
                                                 {"capture", KioskKey::Capture},
                                                 {"repeat", KioskKey::Repeat},
                                                 {"pause", KioskKey::Pause},
                                                 {"where", KioskKey::Where},
                                                 {"finish", KioskKey::Finish},
                                                 {"next_sentence", KioskKey::NextSentence},
                                                 {"previous_sentence", KioskKey::PreviousSentence},
                                                 {"next_paragraph", KioskKey::NextParagraph},
                                                 {"previous_paragraph", KioskKey::PreviousParagraph},
                                                 {"language", KioskKey::Language},
                                                 {"copy", KioskKey::Copy},
                                                 {"other", KioskKey::Other}};
  return m;
}

constexpr const char* kAllowed =
    "'FRAME key ACTION', 'FRAME press KEYS', 'FRAME type TEXT', 'FRAME click NAME', 'FRAME shows NAME', 'FRAME cursor "
    "X_M Y_M', 'FRAME move', "
    "'FRAME stick DIR', 'FRAME unstick' or 'FRAME wait'";

/// KEYS of a press line: a key name, or modifiers and a key joined by '+'. False when it is neither.
bool parse_keys(const std::string& text, int* key, int* mods) {
  if (text.find('+') == std::string::npos) {
    *key = glfw_key(text);
    *mods = 0;
    return *key != GLFW_KEY_UNKNOWN;
  }
  // A chord as the settings write it; SHIFT alone is allowed here (a script may type a shifted key).
  std::string rest = text;
  int m = 0;
  for (;;) {
    const std::size_t plus = rest.find('+');
    if (plus == std::string::npos) break;
    const std::string part = rest.substr(0, plus);
    if (part == "CTRL")
      m |= GLFW_MOD_CONTROL;
    else if (part == "ALT")
      m |= GLFW_MOD_ALT;
    else if (part == "SHIFT")
      m |= GLFW_MOD_SHIFT;
    else if (part == "SUPER")
      m |= GLFW_MOD_SUPER;
    else
      return false;
    rest = rest.substr(plus + 1);
  }
  *key = glfw_key(rest);
  *mods = m;
  return *key != GLFW_KEY_UNKNOWN;
}

std::string rest_of_line(std::istringstream& ss) {
  std::string rest;
  std::getline(ss, rest);
  if (!rest.empty() && rest[0] == ' ') rest.erase(0, 1);
  while (!rest.empty() && (rest.back() == '\r' || rest.back() == ' ')) rest.pop_back();
  return rest;
}

}  // namespace

std::vector<ScriptLine> load_script(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw AppError("script '" + path + "': cannot read the file");
  std::vector<ScriptLine> out;
  std::string line;
  int n = 0;
  while (std::getline(f, line)) {
    ++n;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    ScriptLine s;
    s.number = n;
    ss >> s.frame >> s.what;
    bool ok = static_cast<bool>(ss) && s.frame >= 0;
    if (ok && s.what == "key") {
      ok = static_cast<bool>(ss >> s.arg) && action_names().count(s.arg);
      if (ok) s.action = action_names().at(s.arg);
    } else if (ok && s.what == "press") {
      ok = static_cast<bool>(ss >> s.arg) && parse_keys(s.arg, &s.glfw_key, &s.glfw_mods);
    } else if (ok && (s.what == "type" || s.what == "click" || s.what == "shows")) {
      s.arg = rest_of_line(ss);
      ok = !s.arg.empty();
    } else if (ok && s.what == "cursor") {
      ok = static_cast<bool>(ss >> s.cursor_m.x >> s.cursor_m.y);
    } else if (ok && s.what == "stick") {
      ok = static_cast<bool>(ss >> s.arg);
    } else if (ok && s.what == "wait_loaded") {
      s.what = "wait";
    } else if (ok && s.what != "move" && s.what != "unstick" && s.what != "wait") {
      ok = false;
    }
    if (!ok) throw AppError("script '" + path + "': line " + std::to_string(n) + " is not " + kAllowed);
    out.push_back(s);
  }
  return out;
}

bool ScriptPlayer::step(int frame, ScriptTarget& t) {
  constexpr int kMaxHeldFrames = 3600;  // 60 s of frames
  for (const InputEvent& e : releases_) t.input(e);
  releases_.clear();
  if (!clicks_.empty()) {
    mouse_ = clicks_.front();  // the button state reaches ImGui through KioskWindow::begin_frame
    clicks_.pop_front();
  }
  while (next_ < lines_.size() && lines_[next_].frame <= frame) {
    const ScriptLine& l = lines_[next_];
    if (l.what == "wait" && t.busy()) {
      if (++held_ > kMaxHeldFrames)
        throw AppError("script '" + path_ + "': line " + std::to_string(l.number) +
                       ": the kiosk was still busy after 60 s");
      return true;
    }
    if (l.what == "click" && !clicks_.empty()) return false;  // one click at a time: this one waits a frame
    ++next_;
    if (l.what == "key") t.action_key(l.action);
    if (l.what == "cursor") t.cursor(l.cursor_m);
    if (l.what == "move") t.moved();
    if (l.what == "stick") t.stick(l.arg);
    if (l.what == "unstick") t.unstick();
    if (l.what == "press") {
      t.input({InputEvent::Kind::key, l.glfw_key, 0, GLFW_PRESS, l.glfw_mods, 0, 0});
      releases_.push_back({InputEvent::Kind::key, l.glfw_key, 0, GLFW_RELEASE, l.glfw_mods, 0, 0});
    }
    if (l.what == "type") {
      for (unsigned char c : l.arg) t.input({InputEvent::Kind::character, 0, 0, 0, 0, c, 0});
    }
    if (l.what == "shows" && !t.widget(l.arg)) {
      throw AppError("script '" + path_ + "': line " + std::to_string(l.number) + ": '" + l.arg +
                     "' is not on screen at frame " + std::to_string(frame));
    }
    if (l.what == "click") {
      const std::optional<WidgetRect> r = t.widget(l.arg);
      if (!r)
        throw AppError("script '" + path_ + "': line " + std::to_string(l.number) + ": no widget '" + l.arg +
                       "' on screen at frame " + std::to_string(frame));
      const ScriptedMouse at{0.5f * (r->x0 + r->x1), 0.5f * (r->y0 + r->y1), false};
      mouse_ = at;                            // this frame: the pointer arrives (hover)
      clicks_.push_back({at.x, at.y, true});  // next: button down
      clicks_.push_back(at);                  // then: up (the click)
    }
  }
  return false;
}

}  // namespace hk::app
