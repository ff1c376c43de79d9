#pragma once
/// @file operator_pin.hpp
/// The operator's PIN: its rules, its argon2id hash (libsodium), and the lockout after failed
/// attempts, persisted in a small state file so that it survives restarts and every `haptic-kiosk pin
/// check` process. Shared by the command line (`haptic-kiosk pin set|check`) and the kiosk's panel.
///
/// The PIN itself is never printed, logged or put into a message or exception by anything here.
/// Time is always a parameter (`now_unix_s`, seconds since the Unix epoch) so the lockout can be tested
/// with explicit times.

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include "config/load.hpp"
#include "config/settings.hpp"

namespace hk::config {

/// Fewest digits of a PIN.
inline constexpr int kPinMinDigits = 4;
/// Most digits of a PIN.
inline constexpr int kPinMaxDigits = 12;

/// Why `pin` is not a PIN, or empty when it is one: 4 to 12 ASCII digits. The reason is one line that
/// never contains the PIN, e.g. "a PIN is 4 to 12 digits (0-9); this one has 3" or "a PIN is 4 to 12
/// digits (0-9); this one has other characters than digits".
[[nodiscard]] std::string pin_problem(std::string_view pin);

/// The argon2id hash of `pin` as libsodium's crypto_pwhash_str_alg writes it ("$argon2id$v=19$m=...",
/// at most crypto_pwhash_STRBYTES − 1 = 127 printable bytes; a fresh random salt each call), with
/// crypto_pwhash_OPSLIMIT_INTERACTIVE and crypto_pwhash_MEMLIMIT_INTERACTIVE (64 MiB).
/// @throws ConfigError (source "PIN", key "operator.pin_hash") when `pin` is not a PIN (pin_problem's
///         line) or when libsodium fails (out of memory).
[[nodiscard]] std::string hash_pin(std::string_view pin);

/// True when `pin` matches `hash` (libsodium crypto_pwhash_str_verify, constant time in the PIN).
/// False for an empty, too long or malformed hash.
[[nodiscard]] bool verify_pin(std::string_view hash, std::string_view pin) noexcept;

/// True when `hash` was made with other parameters than the INTERACTIVE limits hash_pin() uses
/// (libsodium crypto_pwhash_str_needs_rehash), or is not an argon2id hash at all.
[[nodiscard]] bool pin_hash_needs_rehash(std::string_view hash) noexcept;

/// Rate limiting of failed attempts, after NIST SP 800-63B §5.2.2: the first `free_failures` failures
/// cost nothing; from then on each attempt waits first_delay_s after the last failure, doubling with
/// each further failure up to max_delay_s; after lock_after_failures failures the PIN is locked until
/// a new one is set (`haptic-kiosk pin set`).
struct LockoutPolicy {
  int free_failures = 3;          ///< failures without a delay
  double first_delay_s = 30;      ///< delay after failure number free_failures, s
  double max_delay_s = 900;       ///< the delay doubles up to this, s
  int lock_after_failures = 100;  ///< locked for good (until `pin set`) from this many failures
};

/// What the state file holds: failed attempts since the last right one (or `pin set`), and when the
/// last of them was.
struct LockoutState {
  int failures = 0;                      ///< failed attempts in a row, >= 0
  std::int64_t last_failure_unix_s = 0;  ///< time of the last failure, s since the epoch; 0 = none
  /// Field-by-field equality.
  bool operator==(const LockoutState&) const = default;
};

/// lockout_wait_s() when the PIN is locked until a new one is set.
inline constexpr double kLockedUntilPinSet = std::numeric_limits<double>::infinity();

/// Seconds until the next attempt is heard at `now_unix_s`: 0 = now; kLockedUntilPinSet once
/// `s.failures` >= p.lock_after_failures. A clock that went back (now < last failure) counts as "the
/// failure was just now": the full delay, never longer.
/// Golden values with the default policy, at the time of the last failure: failures 0..2 → 0, 3 → 30,
/// 4 → 60, 5 → 120, 6 → 240, 7 → 480, 8..99 → 900, 100 → infinity.
[[nodiscard]] double lockout_wait_s(const LockoutState& s, std::int64_t now_unix_s, const LockoutPolicy& p = {});

/// Where the lockout state of the settings file at `settings_path` lives: [operator] state_file, or
/// "<settings_path>.state" when that is empty. A relative state_file is taken relative to the folder of
/// the settings file (not to the working directory), so the kiosk and the CLI agree wherever they run.
[[nodiscard]] std::string state_file_path(const Settings& s, const std::string& settings_path);

/// Reads the lockout state file at `path` (TOML: `failures = N`, `last_failure_unix_s = T`, both
/// integers >= 0, nothing else, at most 4096 bytes). A missing file is {0, 0}. A file that cannot be
/// read, does not parse or holds nonsense counts as LockoutPolicy{}.free_failures failures at
/// `now_unix_s` (the delay starts: fail safe); `*note` (when given) then says so in one line, and is
/// cleared otherwise.
[[nodiscard]] LockoutState read_lockout_state(const std::string& path, std::int64_t now_unix_s,
                                              std::string* note = nullptr);

/// Writes `s` to `path` atomically (a temporary file in the same folder, fsync, rename; then the folder
/// is fsync'ed, best effort), mode 0600.
/// @throws ConfigError (source `path`) when any step before the rename fails; the old file is then
///         untouched and the temporary removed.
void write_lockout_state(const std::string& path, const LockoutState& s);

/// The outcome of a PIN attempt (check_pin) or of a look at the lockout (pin_status).
enum class PinVerdict {
  right,   ///< the PIN is right (pin_status: an attempt would be heard now)
  wrong,   ///< the PIN is wrong (counted)
  locked,  ///< refused unheard: wait PinAttempt::wait_s (kLockedUntilPinSet: until `pin set`)
  no_pin,  ///< the settings file has no pin_hash: nothing can open the panel
};

/// One attempt's outcome.
struct PinAttempt {
  PinVerdict verdict = PinVerdict::no_pin;  ///< see PinVerdict
  int failures = 0;                         ///< failed attempts counted after this one
  double wait_s = 0;  ///< s until the next attempt is heard (kLockedUntilPinSet when locked for good)
};

/// The whole check, shared by the CLI and the panel:
/// 1. reads pin_hash fresh from the settings file at `settings_path` (so a `pin set` made while the
///    kiosk runs counts at once); `no_pin` when it has none;
/// 2. takes an exclusive flock on "<state file>.lock" (state_file_path) for the read-modify-write of
///    the lockout state (attempts from several processes are heard one after another);
/// 3. refuses with `locked` (without verifying, without counting) while lockout_wait_s > 0; a corrupt
///    state file is then rewritten as read (free_failures failures at `now_unix_s`) so its delay ends;
/// 4. else counts the attempt as a failure in the state file *before* verifying (killing the process
///    during the slow hash does not save an attempt), then verifies: right → the state is reset to
///    {0, 0} and, when pin_hash_needs_rehash, the PIN is re-hashed and the settings file saved keeping
///    every other value (best effort: a failed save leaves the old hash, which still works); wrong →
///    the failure stays counted (failures + 1, last failure = now). Anything but 4 to 12 digits is
///    wrong without hashing.
/// @throws ConfigError when the settings file cannot be read or parsed (the loader's message), or the
///         lock or state file cannot be opened or written.
[[nodiscard]] PinAttempt check_pin(const std::string& settings_path, std::string_view pin, std::int64_t now_unix_s);

/// The lockout as it stands at `now_unix_s`, without an attempt, for the panel's wait display: verdict
/// no_pin when no PIN is set, locked while waiting (wait_s > 0), else right meaning "an attempt would be
/// heard". Reads only (no lock, nothing written).
/// @throws ConfigError when the settings file cannot be read or parsed.
[[nodiscard]] PinAttempt pin_status(const std::string& settings_path, std::int64_t now_unix_s);

/// Sets the PIN: refuses a bad PIN (pin_problem) with ConfigError; loads the settings file (a missing
/// file starts from the defaults; a file that does not parse is refused with the loader's message and
/// left untouched), sets pin_hash = hash_pin(pin), saves it with save_settings_atomic (mode 0600, every
/// other value kept), and resets the lockout state to {0, 0} — under the same lock as check_pin.
/// @throws ConfigError (one line, never the PIN) on any of these; when the settings were saved but the
///         state could not be reset, the message says so.
void set_pin(const std::string& settings_path, std::string_view pin);

/// Overwrites the bytes of `s` with zeros (sodium_memzero, not optimised away) and clears it. For the
/// copies of a PIN that callers hold.
void wipe_pin(std::string& s) noexcept;

}  // namespace hk::config
