#pragma once
/// @file app_error.hpp
/// The app's own error: a command-line option, an output file, the picture library, a kiosk script or
/// the display that cannot be used. One line naming the option or file and what is wrong with it, as
/// every hk::Error (hk/error.hpp).
#include <string>

#include "hk/error.hpp"

namespace hk::app {

/// The problem part of a one-line error "kind 'name': problem" (what is said after the name, so a visitor
/// never hears a file's path), or the whole line when it names nothing. Never throws but std::bad_alloc.
inline std::string problem_of(const std::string& what) {
  const std::size_t k = what.find("': ");
  return k == std::string::npos ? what : what.substr(k + 3);
}

/// A bad option, an unwritable output, an unreadable picture library or script, no display.
class AppError : public hk::Error {
 public:
  using hk::Error::Error;
};

}  // namespace hk::app
