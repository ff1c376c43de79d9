#pragma once
/// @file keymap.hpp
/// Key names of the settings (config/keys.hpp) → GLFW key codes, the visitor's key map, and the operator's
/// key chord. GLFW's names without the GLFW_KEY_ prefix are the settings' names.

#include <map>
#include <string>

#include "config/keys.hpp"
#include "config/settings.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {

/// GLFW key code of a settings key name ("F1", "A", "PAGE_UP", "KP_5", "O", "ESCAPE", ...), or
/// GLFW_KEY_UNKNOWN (−1) for a name the settings do not allow.
int glfw_key(const std::string& name);

/// The settings' name of GLFW key code `key` ("Q", "F5", "O"; config::visitor_key_names() and O, C,
/// ESCAPE), or "" for a key the settings do not name. For speaking the name of a key that does nothing.
std::string key_name_of(int key);

/// Whether GLFW key code `key` is a modifier (Shift, Control, Alt or Super, left or right).
bool is_modifier_key(int key);

/// The visitor's actions by GLFW key code, from [keys] (config::key_actions: Help .. Finish).
std::map<int, KioskKey> visitor_key_map(const config::KeysSettings& keys);

/// GLFW modifier bits (GLFW_MOD_CONTROL, GLFW_MOD_ALT, GLFW_MOD_SHIFT, GLFW_MOD_SUPER) of a chord.
int glfw_mods(const config::KeyChord& chord);

/// True when a press of `key` with modifier bits `mods` (GLFW's; Caps Lock and Num Lock ignored) is `chord`.
bool chord_pressed(const config::KeyChord& chord, int key, int mods);

}  // namespace hk::app
