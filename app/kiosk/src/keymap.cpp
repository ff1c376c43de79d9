#include "kiosk/keymap.hpp"

#include <GLFW/glfw3.h>

#include <cctype>

namespace hk::app {

int glfw_key(const std::string& name) {
  if (name.size() == 1 && name[0] >= 'A' && name[0] <= 'Z') return GLFW_KEY_A + (name[0] - 'A');
  if (name.size() == 1 && name[0] >= '0' && name[0] <= '9') return GLFW_KEY_0 + (name[0] - '0');
  if (name.size() >= 2 && name.size() <= 3 && name[0] == 'F' && std::isdigit(static_cast<unsigned char>(name[1]))) {
    const int n = std::stoi(name.substr(1));
    return n >= 1 && n <= 12 ? GLFW_KEY_F1 + n - 1 : GLFW_KEY_UNKNOWN;
  }
  if (name.size() == 4 && name.rfind("KP_", 0) == 0 && std::isdigit(static_cast<unsigned char>(name[3])))
    return GLFW_KEY_KP_0 + (name[3] - '0');
  static const std::map<std::string, int> named{{"SPACE", GLFW_KEY_SPACE},
                                                {"ENTER", GLFW_KEY_ENTER},
                                                {"TAB", GLFW_KEY_TAB},
                                                {"BACKSPACE", GLFW_KEY_BACKSPACE},
                                                {"LEFT", GLFW_KEY_LEFT},
                                                {"RIGHT", GLFW_KEY_RIGHT},
                                                {"UP", GLFW_KEY_UP},
                                                {"DOWN", GLFW_KEY_DOWN},
                                                {"PAGE_UP", GLFW_KEY_PAGE_UP},
                                                {"PAGE_DOWN", GLFW_KEY_PAGE_DOWN},
                                                {"HOME", GLFW_KEY_HOME},
                                                {"END", GLFW_KEY_END},
                                                {"INSERT", GLFW_KEY_INSERT},
                                                {"DELETE", GLFW_KEY_DELETE},
                                                {"MINUS", GLFW_KEY_MINUS},
                                                {"EQUAL", GLFW_KEY_EQUAL},
                                                {"KP_ADD", GLFW_KEY_KP_ADD},
                                                {"KP_SUBTRACT", GLFW_KEY_KP_SUBTRACT},
                                                {"KP_ENTER", GLFW_KEY_KP_ENTER},
                                                {"ESCAPE", GLFW_KEY_ESCAPE}};
  const auto it = named.find(name);
  return it == named.end() ? GLFW_KEY_UNKNOWN : it->second;
}

bool is_modifier_key(int key) {
  switch (key) {
    case GLFW_KEY_LEFT_SHIFT:
    case GLFW_KEY_RIGHT_SHIFT:
    case GLFW_KEY_LEFT_CONTROL:
    case GLFW_KEY_RIGHT_CONTROL:
    case GLFW_KEY_LEFT_ALT:
    case GLFW_KEY_RIGHT_ALT:
    case GLFW_KEY_LEFT_SUPER:
    case GLFW_KEY_RIGHT_SUPER:
      return true;
    default:
      return false;
  }
}

std::string key_name_of(int key) {
  if (key == GLFW_KEY_UNKNOWN) return {};
  for (const std::string_view name : config::visitor_key_names())
    if (glfw_key(std::string(name)) == key) return std::string(name);
  for (const char* name : {"O", "C", "ESCAPE"})
    if (glfw_key(name) == key) return name;
  return {};
}

std::map<int, KioskKey> visitor_key_map(const config::KeysSettings& k) {
  std::map<int, KioskKey> map;
  const auto actions = config::key_actions(k);
  for (std::size_t i = 0; i < actions.size(); ++i)
    map[glfw_key(std::string(actions[i].second))] = static_cast<KioskKey>(i);
  return map;
}

int glfw_mods(const config::KeyChord& c) {
  return (c.ctrl ? GLFW_MOD_CONTROL : 0) | (c.alt ? GLFW_MOD_ALT : 0) | (c.shift ? GLFW_MOD_SHIFT : 0) |
         (c.super ? GLFW_MOD_SUPER : 0);
}

bool chord_pressed(const config::KeyChord& chord, int key, int mods) {
  constexpr int kModifierBits = GLFW_MOD_CONTROL | GLFW_MOD_ALT | GLFW_MOD_SHIFT | GLFW_MOD_SUPER;
  return key == glfw_key(chord.key) && (mods & kModifierBits) == glfw_mods(chord);
}

}  // namespace hk::app
