/// @file operator_pin.cpp
/// The operator's PIN: rules, argon2id hash (libsodium), lockout state file and the shared check.

#include "config/operator_pin.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "config/load.hpp"
#include "detail.hpp"

namespace hk::config {

namespace {

namespace fs = std::filesystem;
using detail::one_line;

/// Largest state file read_lockout_state() accepts, bytes.
constexpr std::size_t kMaxStateFileBytes = 4096;

/// sodium_init() once; false when libsodium cannot be initialised (no entropy source).
bool sodium_ready() noexcept {
  static const bool ok = ::sodium_init() >= 0;
  return ok;
}

/// `hash` NUL-terminated in a buffer of crypto_pwhash_STRBYTES, as libsodium wants it; false when it
/// does not fit (or is empty).
bool to_hash_buffer(std::string_view hash, std::array<char, crypto_pwhash_STRBYTES>& buf) noexcept {
  if (hash.empty() || hash.size() >= buf.size()) return false;
  buf.fill('\0');
  std::memcpy(buf.data(), hash.data(), hash.size());
  return true;
}

/// "PIN lockout state '<path>': <body>" as a ConfigError with source `path`.
[[noreturn]] void state_fail(const std::string& path, const std::string& body) {
  std::string msg = "PIN lockout state '" + one_line(path) + "': " + body;
  for (char& c : msg)
    if (c == '\n' || c == '\r') c = ' ';
  throw ConfigError(path, "", msg);
}

/// An exclusive flock on "<state file>.lock", held for the object's life. The lock file is created
/// (mode 0600) and never removed: removing it would let two processes lock two different files.
class StateLock {
 public:
  explicit StateLock(const std::string& state_path) {
    const std::string lock_path = state_path + ".lock";
    fd_ = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
    if (fd_ < 0)
      state_fail(state_path,
                 "cannot open the lock file '" + one_line(lock_path) + "': " + one_line(std::strerror(errno)));
    while (::flock(fd_, LOCK_EX) != 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd_);
      state_fail(state_path, "cannot lock '" + one_line(lock_path) + "': " + one_line(std::strerror(err)));
    }
  }
  ~StateLock() { ::close(fd_); }  // closing releases the flock
  StateLock(const StateLock&) = delete;
  StateLock& operator=(const StateLock&) = delete;

 private:
  int fd_ = -1;
};

/// The fail-safe state for a state file that cannot be trusted, with the note saying so.
LockoutState fail_safe(const std::string& path, std::int64_t now_unix_s, const std::string& why, std::string* note) {
  const LockoutPolicy p{};
  if (note)
    *note = "PIN lockout state '" + one_line(path) + "' " + why + "; counted as " + std::to_string(p.free_failures) +
            " failed attempts now (fail safe)";
  return LockoutState{p.free_failures, now_unix_s};
}

/// The settings at `path`; Settings{} when there is no file there (nothing at all, not even a link).
Settings load_or_defaults(const std::string& path) {
  std::error_code ec;
  // not_found comes with ec set (ENOENT) in libstdc++; any other trouble is load_settings' to report.
  if (fs::symlink_status(path, ec).type() == fs::file_type::not_found) return Settings{};
  return load_settings(path);  // reports every other problem (unreadable, not a file, bad TOML, ...)
}

/// Re-hashes the PIN with the current parameters and saves it, when the settings file still holds
/// `old_hash`. Best effort: the old hash still verifies, so a failure here is not the caller's.
void rehash_best_effort(const std::string& settings_path, const std::string& old_hash, std::string_view pin) noexcept {
  try {
    Settings fresh = load_settings(settings_path);
    if (fresh.operator_.pin_hash != old_hash) return;
    fresh.operator_.pin_hash = hash_pin(pin);
    save_settings_atomic(fresh, settings_path);
  } catch (...) {
    // Left as it was: the old hash works; the next right attempt tries again.
  }
}

}  // namespace

std::string pin_problem(std::string_view pin) {
  const std::string rule =
      "a PIN is " + std::to_string(kPinMinDigits) + " to " + std::to_string(kPinMaxDigits) + " digits (0-9); ";
  if (pin.empty()) return rule + "this one is empty";
  if (!std::all_of(pin.begin(), pin.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return rule + "this one has other characters than digits";
  if (pin.size() < static_cast<std::size_t>(kPinMinDigits) || pin.size() > static_cast<std::size_t>(kPinMaxDigits))
    return rule + "this one has " + std::to_string(pin.size());
  return {};
}

std::string hash_pin(std::string_view pin) {
  if (std::string why = pin_problem(pin); !why.empty()) throw ConfigError("PIN", "operator.pin_hash", why);
  if (!sodium_ready())
    throw ConfigError("PIN", "operator.pin_hash", "the PIN cannot be hashed: libsodium could not be initialised");
  std::array<char, crypto_pwhash_STRBYTES> out{};
  if (::crypto_pwhash_str_alg(out.data(), pin.data(), pin.size(), crypto_pwhash_OPSLIMIT_INTERACTIVE,
                              crypto_pwhash_MEMLIMIT_INTERACTIVE, crypto_pwhash_ALG_ARGON2ID13) != 0)
    throw ConfigError("PIN", "operator.pin_hash",
                      "the PIN cannot be hashed: libsodium's argon2id failed (out of memory? it needs " +
                          std::to_string(crypto_pwhash_MEMLIMIT_INTERACTIVE >> 20) + " MiB)");
  return std::string(out.data());
}

bool verify_pin(std::string_view hash, std::string_view pin) noexcept {
  std::array<char, crypto_pwhash_STRBYTES> buf;
  if (!to_hash_buffer(hash, buf) || !sodium_ready()) return false;
  return ::crypto_pwhash_str_verify(buf.data(), pin.data(), pin.size()) == 0;
}

bool pin_hash_needs_rehash(std::string_view hash) noexcept {
  std::array<char, crypto_pwhash_STRBYTES> buf;
  if (!to_hash_buffer(hash, buf) || !sodium_ready()) return true;
  // 1: other parameters, -1: not a hash of this algorithm; both mean "make a new one".
  return ::crypto_pwhash_str_needs_rehash(buf.data(), crypto_pwhash_OPSLIMIT_INTERACTIVE,
                                          crypto_pwhash_MEMLIMIT_INTERACTIVE) != 0;
}

void wipe_pin(std::string& s) noexcept {
  if (!s.empty()) ::sodium_memzero(s.data(), s.size());
  s.clear();
}

double lockout_wait_s(const LockoutState& s, std::int64_t now_unix_s, const LockoutPolicy& p) {
  if (s.failures <= 0 || s.failures < p.free_failures) return 0.0;
  if (s.failures >= p.lock_after_failures) return kLockedUntilPinSet;
  // Doubling per failure past the free ones; the exponent is capped so the product stays finite.
  const int doublings = std::min(s.failures - std::max(p.free_failures, 0), 1000);
  const double delay = std::min(std::ldexp(p.first_delay_s, doublings), p.max_delay_s);
  // In double: a state file's times cannot overflow the subtraction. A clock gone back = just now.
  const double elapsed = std::max(0.0, static_cast<double>(now_unix_s) - static_cast<double>(s.last_failure_unix_s));
  return std::max(0.0, delay - elapsed);
}

std::string state_file_path(const Settings& s, const std::string& settings_path) {
  const std::string& configured = s.operator_.state_file;
  if (configured.empty()) return settings_path + ".state";
  const fs::path p(configured);
  if (p.is_absolute()) return configured;
  return (fs::path(settings_path).parent_path() / p).string();
}

LockoutState read_lockout_state(const std::string& path, std::int64_t now_unix_s, std::string* note) {
  if (note) note->clear();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) return LockoutState{};
    return fail_safe(path, now_unix_s, "cannot be read (" + one_line(std::strerror(errno)) + ")", note);
  }
  std::string text;
  struct stat st {};
  bool too_big = false, not_file = false;
  int read_err = 0;
  if (::fstat(fd, &st) != 0) {
    read_err = errno;
  } else if (!S_ISREG(st.st_mode)) {
    not_file = true;
  } else {
    std::array<char, 1024> buf;
    for (;;) {
      const ssize_t n = ::read(fd, buf.data(), buf.size());
      if (n < 0) {
        if (errno == EINTR) continue;
        read_err = errno;
        break;
      }
      if (n == 0) break;
      text.append(buf.data(), static_cast<std::size_t>(n));
      if (text.size() > kMaxStateFileBytes) {
        too_big = true;
        break;
      }
    }
  }
  ::close(fd);
  if (read_err != 0)
    return fail_safe(path, now_unix_s, "cannot be read (" + one_line(std::strerror(read_err)) + ")", note);
  if (not_file) return fail_safe(path, now_unix_s, "is not a regular file", note);
  if (too_big)
    return fail_safe(path, now_unix_s, "is larger than " + std::to_string(kMaxStateFileBytes) + " bytes", note);

  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    return fail_safe(path, now_unix_s,
                     "does not parse (TOML syntax error at line " + std::to_string(e.source().begin.line) + ")", note);
  }
  LockoutState s;
  bool have_failures = false, have_time = false;
  for (auto&& [key, node] : root) {
    const auto* v = node.as_integer();
    if (key.str() == "failures" && v && v->get() >= 0 && v->get() <= INT_MAX) {
      s.failures = static_cast<int>(v->get());
      have_failures = true;
    } else if (key.str() == "last_failure_unix_s" && v && v->get() >= 0) {
      s.last_failure_unix_s = v->get();
      have_time = true;
    } else {
      return fail_safe(path, now_unix_s, "holds '" + one_line(key.str(), 40) + "', which it should not", note);
    }
  }
  if (!have_failures || !have_time) return fail_safe(path, now_unix_s, "lacks failures or last_failure_unix_s", note);
  return s;
}

void write_lockout_state(const std::string& path, const LockoutState& s) {
  std::string text;
  text += "# haptic-kiosk: failed attempts at the operator's PIN in a row, and when the last was (Unix time, s).\n";
  text += "# Written by the kiosk and 'haptic-kiosk pin check'; 'haptic-kiosk pin set' resets it.\n";
  text += "failures = " + std::to_string(s.failures) + "\n";
  text += "last_failure_unix_s = " + std::to_string(s.last_failure_unix_s) + "\n";

  const fs::path target(path);
  if (target.filename().empty()) state_fail(path, "not saved: the path names no file");
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::string tmp = detail::temp_prefix(dir.string(), target.filename().string());
  tmp += "XXXXXX";
  std::vector<char> tmpl(tmp.begin(), tmp.end());
  tmpl.push_back('\0');
  const int fd = ::mkostemp(tmpl.data(), O_CLOEXEC);
  if (fd < 0)
    state_fail(path, "not saved: cannot create a temporary file in '" + one_line(dir.string()) +
                         "': " + one_line(std::strerror(errno)));
  tmp.assign(tmpl.data());

  const auto abandon = [&](const std::string& what, int err) {
    ::close(fd);
    ::unlink(tmp.c_str());
    state_fail(path, "not saved: " + what + ": " + one_line(std::strerror(err)) + " (the old state is kept)");
  };
  if (int err = detail::write_all(fd, text)) abandon("cannot write '" + one_line(tmp) + "'", err);
  if (::fchmod(fd, 0600) != 0) abandon("cannot set the mode of '" + one_line(tmp) + "'", errno);
  if (::fsync(fd) != 0) abandon("cannot flush '" + one_line(tmp) + "' to disk", errno);
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    state_fail(path, "not saved: cannot close '" + one_line(tmp) + "': " + one_line(std::strerror(err)));
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    state_fail(path, "not saved: cannot rename the temporary file over it: " + one_line(std::strerror(err)));
  }
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {  // best effort, as for the settings file
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

PinAttempt check_pin(const std::string& settings_path, std::string_view pin, std::int64_t now_unix_s) {
  const Settings first = load_settings(settings_path);
  if (first.operator_.pin_hash.empty()) return PinAttempt{PinVerdict::no_pin, 0, 0.0};
  const std::string state_path = state_file_path(first, settings_path);
  const StateLock lock(state_path);
  // Fresh under the lock: a `pin set` that finished while we waited counts.
  const std::string hash = load_settings(settings_path).operator_.pin_hash;
  if (hash.empty()) return PinAttempt{PinVerdict::no_pin, 0, 0.0};

  std::string note;
  const LockoutState before = read_lockout_state(state_path, now_unix_s, &note);
  if (const double wait = lockout_wait_s(before, now_unix_s); wait > 0) {
    // A corrupt file is replaced by what it was read as, so its delay runs out.
    if (!note.empty()) write_lockout_state(state_path, before);
    return PinAttempt{PinVerdict::locked, before.failures, wait};
  }

  // Counted before the slow verification: a process killed meanwhile has still spent its attempt.
  const LockoutState counted{before.failures == INT_MAX ? INT_MAX : before.failures + 1, now_unix_s};
  write_lockout_state(state_path, counted);
  const bool right = pin_problem(pin).empty() && verify_pin(hash, pin);
  if (!right) return PinAttempt{PinVerdict::wrong, counted.failures, lockout_wait_s(counted, now_unix_s)};

  write_lockout_state(state_path, LockoutState{});
  if (pin_hash_needs_rehash(hash)) rehash_best_effort(settings_path, hash, pin);
  return PinAttempt{PinVerdict::right, 0, 0.0};
}

PinAttempt pin_status(const std::string& settings_path, std::int64_t now_unix_s) {
  const Settings s = load_settings(settings_path);
  if (s.operator_.pin_hash.empty()) return PinAttempt{PinVerdict::no_pin, 0, 0.0};
  const LockoutState st = read_lockout_state(state_file_path(s, settings_path), now_unix_s);
  const double wait = lockout_wait_s(st, now_unix_s);
  return PinAttempt{wait > 0 ? PinVerdict::locked : PinVerdict::right, st.failures, wait};
}

void set_pin(const std::string& settings_path, std::string_view pin) {
  if (std::string why = pin_problem(pin); !why.empty())
    throw ConfigError(settings_path, "operator.pin_hash",
                      "config '" + one_line(settings_path) + "': PIN not set: " + why + "; nothing was changed");
  const Settings first = load_or_defaults(settings_path);
  const std::string state_path = state_file_path(first, settings_path);
  const StateLock lock(state_path);
  Settings s = load_or_defaults(settings_path);  // fresh under the lock
  try {
    s.operator_.pin_hash = hash_pin(pin);
  } catch (const ConfigError& e) {
    throw ConfigError(settings_path, e.key(),
                      "config '" + one_line(settings_path) + "': PIN not set: " + e.what() + "; nothing was changed");
  }
  save_settings_atomic(s, settings_path);
  try {
    write_lockout_state(state_path, LockoutState{});
  } catch (const ConfigError& e) {
    throw ConfigError(settings_path, "",
                      "config '" + one_line(settings_path) +
                          "': the PIN was set, but the failed attempts could not be reset: " + e.what());
  }
}

}  // namespace hk::config
