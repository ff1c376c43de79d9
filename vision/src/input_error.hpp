#pragma once
// Private to the vision library. Builds InputError messages in one place so that every refusal
// has the same one-line "image '<path>': <problem>" shape the kiosk shows and logs, even when a
// hostile file name contains newlines or terminal escape sequences.

#include <string>

#include "vision/intake.hpp"

namespace hk::vision::detail {

/// The path with control characters (< 0x20, 0x7F) written as \xNN, so it prints on one line.
std::string printable_path(const std::string& path);

/// Throws InputError("image '<printable path>': <problem>"). problem must be one line.
[[noreturn]] void throw_input_error(const std::string& path, const std::string& problem);

}  // namespace hk::vision::detail
