#pragma once
/// @file app_error.hpp
/// The app's own error: a command-line option, an output file, the picture library, a kiosk script or
/// the display that cannot be used. One line naming the option or file and what is wrong with it, as
/// every hk::Error (hk/error.hpp).
#include "hk/error.hpp"

namespace hk::app {

/// A bad option, an unwritable output, an unreadable picture library or script, no display.
class AppError : public hk::Error {
 public:
  using hk::Error::Error;
};

}  // namespace hk::app
