#pragma once
/// @file byte_transport.hpp
/// A byte stream to a device (serial over USB): the tty driver (tty_transport.hpp) or libusb talking
/// CDC-ACM directly (usb_transport.hpp). The pantograph protocol sits on top of it.
///
/// Real-time contract: `read`, `write`, `flush_input` and `is_open` are called from the servo thread; they
/// do not allocate, lock or throw, and never block longer than their `timeout_us`. `open` and `close` are
/// called at setup / teardown, outside the servo loop.

#include <cstdint>
#include <string>

#include "haptics/device.hpp"

namespace hk::io {

/// A byte stream to a device. One thread calls read/flush_input and one thread calls write (they may be
/// the same thread); open/close are not called concurrently with them.
class ByteTransport {
 public:
  virtual ~ByteTransport() = default;
  /// Connects. Throws hk::DeviceError with a one-line reason naming the device (missing, busy, no
  /// permission, not CDC-ACM, ...). Calling it on an open transport is a no-op.
  virtual void open() = 0;
  /// Disconnects and frees what open() took. Idempotent, never throws.
  virtual void close() noexcept = 0;
  /// Writes up to `n` bytes from `data`, waiting at most `timeout_us` [µs] for room (0 = only what fits
  /// now). Returns the bytes accepted (0..n), or kGone when the device is gone or the transport closed.
  /// Real-time.
  virtual int write(const std::uint8_t* data, int n, int timeout_us) noexcept = 0;
  /// Reads up to `capacity` bytes into `buf`, waiting at most `timeout_us` [µs] for the first one
  /// (0 = just what is there). Returns the bytes read (0 = none), or kGone when the device is gone (bytes
  /// received before it went are returned first) or the transport closed. Real-time.
  virtual int read(std::uint8_t* buf, int capacity, int timeout_us) noexcept = 0;
  /// Discards bytes received and not yet read. Real-time.
  virtual void flush_input() noexcept = 0;
  /// True between a successful open() and close(), even if the device has since gone.
  virtual bool is_open() const noexcept = 0;
  /// Short name for logs: "tty /dev/ttyACM0", "usb 2341:804d bus 1 addr 5".
  virtual std::string name() const = 0;
  /// Returned by read/write when the device is gone (unplugged, hung up) or the transport is closed.
  static constexpr int kGone = -1;
};

}  // namespace hk::io
