#pragma once
/// @file pin_verifier.hpp
/// PIN attempts from the operator's panel, verified off the window and servo threads: argon2id takes
/// ~0.1-0.5 s and 64 MiB, which would stall a frame or the servo loop.

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "config/operator_pin.hpp"

namespace hk::app {

/// The outcome of one attempt handed to PinVerifier.
struct PinOutcome {
  config::PinAttempt attempt;  ///< config::check_pin's answer (meaningless when `error` is set)
  std::string error;           ///< one line (a ConfigError's what()), empty when the check ran
};

/// Verifies PINs on its own worker thread with config::check_pin (settings file read fresh, lockout
/// state under its flock), one attempt at a time. All members may be called from one thread (the
/// window's); the worker only runs check_pin.
class PinVerifier {
 public:
  /// Starts the worker thread. `settings_path` is the settings file holding [operator] pin_hash.
  explicit PinVerifier(std::string settings_path);
  /// Joins the worker; an attempt already submitted is finished (and counted) first.
  ~PinVerifier();
  PinVerifier(const PinVerifier&) = delete;
  PinVerifier& operator=(const PinVerifier&) = delete;

  /// Hands `pin` to the worker with the time of the attempt (s since the epoch); false, and nothing
  /// happens, while an attempt is under way. The caller's string is wiped (zeroed and cleared) either
  /// way, and the worker wipes its copy after use. An outcome not yet taken by poll() is dropped.
  bool submit(std::string pin, std::int64_t now_unix_s);

  /// The outcome of the last submitted attempt, once: nullopt while it is under way, when it was
  /// already taken, or when nothing was submitted. A ConfigError (or any exception) in the worker
  /// becomes an outcome with `error` set.
  std::optional<PinOutcome> poll();

  /// True from submit() until its outcome is ready.
  [[nodiscard]] bool busy() const;

 private:
  void run();

  const std::string settings_path_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool pending_ = false;  ///< an attempt submitted, not started
  bool busy_ = false;     ///< submitted and not finished
  /// The PIN of the pending attempt; never longer than kPinMaxDigits + 1 (a longer string is cut there
  /// and stays no PIN), so the string's storage never moves.
  std::string pin_;
  std::int64_t now_unix_s_ = 0;
  std::optional<PinOutcome> outcome_;
  std::thread worker_;  ///< last: started after everything above exists
};

}  // namespace hk::app
