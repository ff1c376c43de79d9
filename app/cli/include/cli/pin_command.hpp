#pragma once
/// @file pin_command.hpp
/// `haptic-kiosk pin set|check --config FILE`: sets or checks the operator's PIN, read from
/// standard input, with the lockout of config/operator_pin.hpp (shared with the kiosk's panel).

#include <string>

namespace hk::app {

/// What `haptic-kiosk pin` was asked to do.
struct PinOptions {
  std::string action;       ///< "set", "check", "hash" or "set-hash"
  std::string config_path;  ///< the settings file (TOML) holding [operator] pin_hash (not for "hash")
};

/// Runs the command. Reads the PIN from standard input: one line, a trailing "\n" or "\r\n" stripped
/// (at most 255 bytes are kept; a longer line is not a PIN). When standard input is a terminal, echo is
/// turned off (termios) while reading and restored after (also on SIGINT, SIGTERM, SIGHUP, SIGQUIT),
/// with a prompt on stderr; `set` then asks a second time and refuses when the two differ.
/// The PIN is never echoed, printed or put into a message; its buffer is wiped after use.
/// Returns the exit status:
/// - set: 0 when set (a line on stderr says where), 1 with a one-line reason on stderr ("pin: ...": not
///   4 to 12 digits, settings file that does not parse, cannot be written, ...);
/// - check: 0 right, 1 wrong ("pin: wrong PIN; N failed attempts ..."), 2 while locked ("pin: locked for
///   27 s after 3 failed attempts"), 3 when no PIN is set or the settings or state file is unusable (one
///   line). The time of the attempt is the system clock's.
/// - hash: 0 with the argon2id hash of the PIN on standard output (one line), 1 when the line is not a PIN;
/// - set-hash: reads a hash (one line); 0 with "set" or "unchanged" on standard output (the file is written only
///   when its hash differs; a missing file starts from the defaults), 1 when the line is not an argon2id hash or
///   the file does not load or cannot be written (one line on stderr; nothing changed). The lockout state is
///   left as it is.
/// Without --config, every action but hash fails with a line saying so (3 for check, 1 otherwise).
/// Any other action: 3 with a line saying so. Never throws.
int run_pin(const PinOptions& options);

}  // namespace hk::app
