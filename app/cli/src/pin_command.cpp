/// @file pin_command.cpp
/// `haptic-kiosk pin set|check --config FILE`: the PIN from standard input (echo off on a terminal), then
/// config::set_pin / config::check_pin.

#include "cli/pin_command.hpp"

#include <termios.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "config/load.hpp"
#include "config/operator_pin.hpp"

namespace hk::app {

namespace {

/// Bytes of a line kept; a longer line is still read to its end, and is not a PIN.
constexpr std::size_t kMaxLineBytes = 255;

/// "pin: <text>" on stderr as one line (line breaks folded).
void say(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  std::fprintf(stderr, "pin: %s\n", text.c_str());
}

/// The terminal settings to put back if a signal ends the process while echo is off.
termios g_saved_termios{};
volatile std::sig_atomic_t g_echo_off = 0;

extern "C" void restore_echo_and_reraise(int sig) {
  if (g_echo_off) ::tcsetattr(STDIN_FILENO, TCSAFLUSH, &g_saved_termios);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

/// Echo off on the terminal at standard input for its life (no-op when it is not a terminal); signals
/// that end the process put the echo back first.
class EchoOff {
 public:
  EchoOff() {
    if (::tcgetattr(STDIN_FILENO, &g_saved_termios) != 0) return;
    struct sigaction sa {};
    sa.sa_handler = &restore_echo_and_reraise;
    sigemptyset(&sa.sa_mask);
    for (std::size_t i = 0; i < kSignals.size(); ++i) {
      ::sigaction(kSignals[i], nullptr, &old_[i]);
      if (old_[i].sa_handler != SIG_IGN) ::sigaction(kSignals[i], &sa, nullptr);  // an ignored signal stays so
    }
    termios quiet = g_saved_termios;
    quiet.c_lflag &= ~static_cast<tcflag_t>(ECHO | ECHOE | ECHOK);
    quiet.c_lflag |= ECHONL;  // the Enter still moves to the next line
    g_echo_off = 1;
    if (::tcsetattr(STDIN_FILENO, TCSAFLUSH, &quiet) != 0) g_echo_off = 0;
    active_ = true;
  }
  ~EchoOff() {
    if (!active_) return;
    if (g_echo_off) ::tcsetattr(STDIN_FILENO, TCSAFLUSH, &g_saved_termios);
    g_echo_off = 0;
    for (std::size_t i = 0; i < kSignals.size(); ++i) ::sigaction(kSignals[i], &old_[i], nullptr);
  }
  EchoOff(const EchoOff&) = delete;
  EchoOff& operator=(const EchoOff&) = delete;

 private:
  static constexpr std::array<int, 4> kSignals{SIGINT, SIGTERM, SIGHUP, SIGQUIT};
  std::array<struct sigaction, 4> old_{};
  bool active_ = false;
};

/// A PIN read from standard input; its bytes are wiped when it goes.
struct SecretLine {
  std::string text;       ///< at most kMaxLineBytes (capacity reserved once: no copies left behind)
  bool too_long = false;  ///< the line had more than kMaxLineBytes bytes
  SecretLine() { text.reserve(kMaxLineBytes); }
  ~SecretLine() { config::wipe_pin(text); }
  SecretLine(const SecretLine&) = delete;
  SecretLine& operator=(const SecretLine&) = delete;
};

/// Reads one line from standard input into `line` (the "\n" or "\r\n" at its end dropped). On a
/// terminal, `prompt` goes to stderr first and echo is off while reading.
void read_line(const char* prompt, SecretLine& line) {
  const bool tty = ::isatty(STDIN_FILENO) != 0;
  EchoOff quiet_if_tty;
  if (tty) {
    std::fputs(prompt, stderr);
    std::fflush(stderr);
  }
  for (;;) {
    char c = 0;
    const ssize_t n = ::read(STDIN_FILENO, &c, 1);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0 || c == '\n') break;
    if (line.text.size() < kMaxLineBytes) {
      line.text.push_back(c);
    } else {
      line.too_long = true;
    }
    c = 0;
  }
  if (!line.text.empty() && line.text.back() == '\r') line.text.pop_back();
}

std::int64_t now_unix_s() {
  using namespace std::chrono;
  return duration_cast<seconds>(system_clock::now().time_since_epoch()).count();
}

std::string seconds_text(double s) { return std::to_string(static_cast<long long>(std::ceil(s))) + " s"; }

std::string attempts_text(int n) { return std::to_string(n) + (n == 1 ? " failed attempt" : " failed attempts"); }

int run_set(const std::string& config_path) {
  SecretLine pin;
  read_line("New PIN (4 to 12 digits, not shown): ", pin);
  if (pin.too_long) {
    say("PIN not set: a PIN is " + std::to_string(config::kPinMinDigits) + " to " +
        std::to_string(config::kPinMaxDigits) + " digits (0-9); this line has more than " +
        std::to_string(kMaxLineBytes) + " bytes; nothing was changed");
    return 1;
  }
  if (::isatty(STDIN_FILENO) != 0 && config::pin_problem(pin.text).empty()) {
    SecretLine again;
    read_line("The same PIN again: ", again);
    if (again.too_long || again.text != pin.text) {
      say("PIN not set: the two PINs differ; nothing was changed");
      return 1;
    }
  }
  try {
    config::set_pin(config_path, pin.text);
  } catch (const std::exception& e) {
    say(e.what());
    return 1;
  }
  say("PIN set in '" + config_path + "'; failed attempts reset");
  return 0;
}

int run_check(const std::string& config_path) {
  SecretLine pin;
  read_line("PIN (not shown): ", pin);
  if (pin.too_long) pin.text.resize(config::kPinMaxDigits + 1, '0');  // still not a PIN: counted as wrong
  config::PinAttempt a;
  try {
    a = config::check_pin(config_path, pin.text, now_unix_s());
  } catch (const std::exception& e) {
    say(e.what());
    return 3;
  }
  switch (a.verdict) {
    case config::PinVerdict::right:
      return 0;
    case config::PinVerdict::wrong: {
      std::string msg = "wrong PIN; " + attempts_text(a.failures) + " in a row";
      if (a.wait_s == config::kLockedUntilPinSet) {
        msg += "; locked until a new PIN is set with 'haptic-kiosk pin set'";
      } else if (a.wait_s > 0) {
        msg += "; the next attempt is heard in " + seconds_text(a.wait_s);
      }
      say(msg);
      return 1;
    }
    case config::PinVerdict::locked:
      if (a.wait_s == config::kLockedUntilPinSet) {
        say("locked after " + attempts_text(a.failures) + " until a new PIN is set with 'haptic-kiosk pin set'");
      } else {
        say("locked for " + seconds_text(a.wait_s) + " after " + attempts_text(a.failures) + "; the PIN was not tried");
      }
      return 2;
    case config::PinVerdict::no_pin:
      say("no PIN is set in '" + config_path + "'; set one with 'haptic-kiosk pin set --config FILE'");
      return 3;
  }
  return 3;
}

/// `hash`: the argon2id hash of the PIN read, on standard output (for a museum's inventory; the PIN never leaves).
int run_hash() {
  SecretLine pin;
  read_line("PIN to hash (4 to 12 digits, not shown): ", pin);
  if (pin.too_long || !config::pin_problem(pin.text).empty()) {
    say("no hash: a PIN is " + std::to_string(config::kPinMinDigits) + " to " + std::to_string(config::kPinMaxDigits) +
        " digits (0-9)");
    return 1;
  }
  std::printf("%s\n", config::hash_pin(pin.text).c_str());
  return 0;
}

/// `set-hash`: the hash read (one line, as `hash` prints it) becomes [operator] pin_hash of the settings file; the
/// file is left as it is when it already holds it ("unchanged" on standard output, for a roll-out's idempotence).
int run_set_hash(const std::string& config_path) {
  SecretLine line;
  read_line("PIN hash: ", line);
  const config::FieldDescriptor* d = config::find_field("operator", "pin_hash");
  const std::string why = line.too_long ? std::string("is longer than an argon2id hash") : d->check(line.text);
  if (line.text.empty() || !why.empty()) {
    say("PIN hash not set: the line read " + (line.text.empty() ? std::string("is empty") : why) +
        "; nothing was changed");
    return 1;
  }
  config::Settings s;
  std::error_code ec;
  if (std::filesystem::exists(config_path, ec)) s = config::load_settings(config_path);
  if (s.operator_.pin_hash == line.text) {
    std::printf("unchanged\n");
    return 0;
  }
  s.operator_.pin_hash = line.text;
  config::save_settings_atomic(s, config_path);
  std::printf("set\n");
  say("PIN hash set in '" + config_path + "'");
  return 0;
}

}  // namespace

int run_pin(const PinOptions& options) {
  try {
    if (options.action == "hash") return run_hash();
    if (options.config_path.empty()) {
      say("--config FILE is needed to " + options.action + " the PIN");
      return options.action == "check" ? 3 : 1;
    }
    if (options.action == "set") return run_set(options.config_path);
    if (options.action == "check") return run_check(options.config_path);
    if (options.action == "set-hash") return run_set_hash(options.config_path);
    say("unknown action '" + options.action + "'; expected set, check, hash or set-hash");
  } catch (const std::exception& e) {
    say(e.what());
  }
  return 3;
}

}  // namespace hk::app
