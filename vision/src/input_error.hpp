#pragma once
// Private to the vision library. Builds InputError messages in one place so that every refusal
// has the same one-line "image '<path>': <problem>" shape the kiosk shows and logs, even when a
// hostile file name contains newlines or terminal escape sequences.

#include <string>

#include "hk/text.hpp"
#include "vision/intake.hpp"

namespace hk::vision::detail {

/// Throws InputError("image '<hk::one_line(path)>': <problem>"). problem must be one line.
[[noreturn]] void throw_input_error(const std::string& path, const std::string& problem);

}  // namespace hk::vision::detail
