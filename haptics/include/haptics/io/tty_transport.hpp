#pragma once
/// @file tty_transport.hpp
/// ByteTransport over a POSIX serial tty (Linux cdc_acm driver: /dev/ttyACM0, /dev/serial/by-id/...).
///
/// Sources: termios(3) (cfmakeraw, VMIN/VTIME), tty_ioctl(4) (TIOCEXCL, TIOCNXCL), poll(2)/ppoll(2).
/// Baud 1200 is refused: opening a SAMD21 (Arduino Zero / Haply 2DIY) CDC port at 1200 baud and closing it
/// (the "1200 baud touch") resets the board into its bootloader.

#include <string>
#include <vector>

#include "haptics/io/byte_transport.hpp"

namespace hk::io {

/// Serial tty transport. open(): O_RDWR|O_NOCTTY|O_NONBLOCK|O_CLOEXEC, TIOCEXCL (other opens fail with
/// EBUSY, except by a process with CAP_SYS_ADMIN), raw 8N1 termios with CLOCAL|CREAD, VMIN=0 VTIME=0.
/// read/write use ppoll() bounded by the timeout; POLLHUP/POLLERR/POLLNVAL, EIO, ENXIO → kGone.
class TtyTransport final : public ByteTransport {
 public:
  /// `path` of the tty; `baud` one of the standard termios rates (9600 ... 4000000) except 1200.
  /// Throws hk::DeviceError naming the baud when it is 1200 or not a standard rate. Does not open.
  explicit TtyTransport(std::string path, int baud = 115200);
  ~TtyTransport() override;
  TtyTransport(const TtyTransport&) = delete;
  TtyTransport& operator=(const TtyTransport&) = delete;

  /// Opens and configures the tty. Throws hk::DeviceError "tty <path>: <strerror> (<step>)" on failure.
  void open() override;
  /// Releases TIOCEXCL (TIOCNXCL) and closes. Idempotent.
  void close() noexcept override;
  /// ByteTransport::write: non-blocking write(2), then ppoll(POLLOUT) up to timeout_us. Real-time.
  int write(const std::uint8_t* data, int n, int timeout_us) noexcept override;
  /// ByteTransport::read: ppoll(POLLIN) up to timeout_us, then read(2). Real-time.
  int read(std::uint8_t* buf, int capacity, int timeout_us) noexcept override;
  /// tcflush(TCIFLUSH): drops the driver's input queue.
  void flush_input() noexcept override;
  bool is_open() const noexcept override { return fd_ >= 0; }
  /// "tty <path>".
  std::string name() const override;
  /// The path given at construction.
  const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
  int baud_;
  int fd_ = -1;
};

/// Full paths of the entries of /dev/serial/by-id (udev's stable names, which include the USB serial
/// number), sorted. Empty when the folder is missing (no serial device plugged, or no udev). Never throws.
std::vector<std::string> list_serial_by_id();
/// Same, for any folder (tests). Empty when `dir` is missing or unreadable.
std::vector<std::string> list_serial_by_id(const std::string& dir);

}  // namespace hk::io
