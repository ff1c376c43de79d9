/// @file pin_verifier.cpp
/// PinVerifier: config::check_pin on a worker thread, one attempt at a time.

#include "visit/pin_verifier.hpp"

#include <algorithm>
#include <exception>
#include <string_view>
#include <utility>

#include "config/load.hpp"

namespace hk::app {

PinVerifier::PinVerifier(std::string settings_path) : settings_path_(std::move(settings_path)) {
  pin_.reserve(config::kPinMaxDigits + 1);
  worker_ = std::thread([this] { run(); });
}

PinVerifier::~PinVerifier() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  worker_.join();
  config::wipe_pin(pin_);
}

bool PinVerifier::submit(std::string pin, std::int64_t now_unix_s) {
  const std::lock_guard lock(mutex_);
  if (busy_ || stop_) {
    config::wipe_pin(pin);
    return false;
  }
  // At most kPinMaxDigits + 1 bytes: a longer string is cut there and still is no PIN (so it counts as
  // wrong), and pin_'s reserved storage is never reallocated (no stray copy).
  const std::size_t keep = std::min(pin.size(), static_cast<std::size_t>(config::kPinMaxDigits + 1));
  pin_.assign(pin.data(), keep);
  config::wipe_pin(pin);
  now_unix_s_ = now_unix_s;
  outcome_.reset();
  pending_ = true;
  busy_ = true;
  wake_.notify_all();
  return true;
}

std::optional<PinOutcome> PinVerifier::poll() {
  const std::lock_guard lock(mutex_);
  if (busy_) return std::nullopt;
  return std::exchange(outcome_, std::nullopt);
}

bool PinVerifier::busy() const {
  const std::lock_guard lock(mutex_);
  return busy_;
}

void PinVerifier::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || pending_; });
    if (!pending_) return;  // stop_ and nothing submitted; a submitted attempt is heard first
    pending_ = false;
    const std::string_view pin = pin_;  // submit() leaves pin_ alone while busy_
    const std::int64_t now = now_unix_s_;
    lock.unlock();

    PinOutcome out;
    try {
      out.attempt = config::check_pin(settings_path_, pin, now);
    } catch (const std::exception& e) {
      out.error = e.what();
      for (char& c : out.error)
        if (c == '\n' || c == '\r') c = ' ';
    }

    lock.lock();
    config::wipe_pin(pin_);
    outcome_ = std::move(out);
    busy_ = false;
  }
}

}  // namespace hk::app
