#pragma once
/// @file pty_emulator.hpp
/// Serves a FirmwareEmulator (hapi_emulator.hpp) on a pseudo-terminal, so that host code can open a
/// real tty path (e.g. /dev/pts/N) as if a Haply board were plugged in. POSIX (openpty).
///
/// A background thread polls the master side (1 ms timeout), feeds every byte read to
/// FirmwareEmulator::receive and writes FirmwareEmulator::take_output back. Both ends are in raw mode
/// (no echo, no line editing, no CR/NL translation), like the board's CDC stream.

#include <atomic>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "haptics/hapi_emulator.hpp"

namespace hk::hapi {

/// The pty server. Not copyable. The emulator must outlive it.
class PtyEmulator {
 public:
  /// Opens the pty pair and starts the thread. Throws hk::DeviceError (one line) when openpty or the
  /// terminal setup fails.
  explicit PtyEmulator(FirmwareEmulator& emulator);
  /// stop(), then closes both ends.
  ~PtyEmulator();
  PtyEmulator(const PtyEmulator&) = delete;
  PtyEmulator& operator=(const PtyEmulator&) = delete;

  /// Path of the slave tty to open (O_RDWR | O_NOCTTY), e.g. "/dev/pts/3".
  std::string device_path() const;
  /// Stops and joins the thread (idempotent). The pty stays open until destruction.
  void stop();
  /// Runs f on the emulator under the lock the server thread takes (for inspection from tests).
  void with_emulator(const std::function<void(FirmwareEmulator&)>& f);

 private:
  void run();

  FirmwareEmulator& emulator_;
  std::mutex mutex_;
  int master_fd_ = -1;
  int slave_fd_ = -1;  ///< kept open so the master never sees a hang-up while no client is attached
  std::string path_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace hk::hapi
