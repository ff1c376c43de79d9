#pragma once
/// @file keys.hpp
/// Key names of the settings file: the keys a visitor presses ([keys]) and the operator's key chord
/// ([operator] open_chord). Names are GLFW's without the GLFW_KEY_ prefix; the window layer maps them.

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace hk::config {

/// Every name a [keys] value may take, in a fixed order: F1..F12, the letters but O and C (the
/// operator's), 0..9, SPACE, ENTER, TAB, BACKSPACE, LEFT, RIGHT, UP, DOWN, PAGE_UP, PAGE_DOWN, HOME, END,
/// INSERT, DELETE, MINUS, EQUAL, KP_0..KP_9, KP_ADD, KP_SUBTRACT, KP_ENTER. Static storage.
[[nodiscard]] std::span<const std::string_view> visitor_key_names() noexcept;

/// A key chord: modifiers and one key.
struct KeyChord {
  bool ctrl = false, alt = false, shift = false, super = false;
  std::string key;  ///< a visitor key name (visitor_key_names()), "O", "C" or "ESCAPE"

  bool operator==(const KeyChord&) const = default;
};

/// Parses "CTRL+ALT+O": modifiers CTRL, ALT, SHIFT, SUPER (each at most once, any order, upper case)
/// and exactly one key, last, joined by '+'. At least one of CTRL, ALT, SUPER is required, so no
/// visitor reaches the PIN prompt by pressing one key. On failure returns nullopt and, when `why` is
/// given, sets it to one phrase saying what is wrong (e.g. "needs CTRL, ALT or SUPER").
[[nodiscard]] std::optional<KeyChord> parse_chord(std::string_view text, std::string* why = nullptr);

/// The chord as parse_chord() reads it, modifiers in the order CTRL, ALT, SHIFT, SUPER.
[[nodiscard]] std::string chord_text(const KeyChord& chord);

}  // namespace hk::config
