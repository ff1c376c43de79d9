#pragma once
/// @file error.hpp
/// The one base of every error haptic-kiosk throws at setup and I/O (never in the servo path, which
/// returns status enums instead; DESIGN.md "Real-time rules").
///
/// Each module derives its own errors from hk::Error: haptics (CurveError, DeviceError, HandFileError),
/// vision (InputError, PdfError, CameraError, StickError, StickMountError), config (ConfigError), audio
/// (SpeechError, MessageError, WavError) and the app (ExploreError, DeviceChoiceError, PictureNotesError).
/// Every what() is one line naming the input (a file, a key, a device) and the limit it broke, with
/// whatever came from outside passed through hk::one_line(); a caller that only reports can catch
/// `const hk::Error&` and print what().
#include <stdexcept>

namespace hk {

/// Base of haptic-kiosk's errors: a std::runtime_error whose what() is one line naming the input and
/// the limit.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A parameter outside the range its docstring gives (a caller's or a settings mistake), thrown at setup,
/// never in the servo path. what() is one line naming the parameter and its limit.
class ArgumentError : public Error {
 public:
  using Error::Error;
};

}  // namespace hk
