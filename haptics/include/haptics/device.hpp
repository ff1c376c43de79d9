#pragma once
/// @file device.hpp
/// The device interface every haptic device implements (DESIGN.md "Devices"): open, read the handle
/// position, write a force, close, status. Implementations: the simulated pantograph (sim_pantograph.hpp);
/// later a USB pantograph and a mouse-only device.
///
/// Real-time contract: `read` and `write_force` are called from the servo thread once per tick; they
/// must not allocate, lock, throw or block. `open` and `close` are called outside the servo loop and may
/// throw `DeviceError`.

#include <cstdint>
#include <stdexcept>
#include <string>
#include "hk/error.hpp"

#include "hk/vec2.hpp"

namespace hk {

/// Device health as seen by the servo loop. Anything but `Ok` makes the force guard output zero.
enum class DeviceStatus : std::uint8_t {
  Closed,  ///< not opened yet, or closed
  Ok,      ///< streaming
  Lost,    ///< stopped answering (unplugged, timed out)
  Fault,   ///< reported a fault (over-temperature, torque limit tripped)
};

/// One sample from the device: the handle position in the workspace frame [m] and when it was taken.
struct DeviceSample {
  Vec2 handle_m;             ///< handle position, workspace frame [m]
  std::int64_t time_ns = 0;  ///< device time of the sample [ns]
  DeviceStatus status = DeviceStatus::Closed;
};

/// Setup or I/O failure of a device (only thrown from `open` / `close`, never from the servo path).
class DeviceError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// A 2-DOF force-feedback device seen through its handle.
class Device {
 public:
  virtual ~Device() = default;
  /// Connects and starts streaming. Throws DeviceError with a one-line reason.
  virtual void open() = 0;
  /// Latest handle sample. Real-time safe.
  virtual DeviceSample read() noexcept = 0;
  /// Commands a force on the handle [N], workspace frame, held until the next call. Real-time safe.
  /// The device may clamp it further to what its motors can give.
  virtual void write_force(Vec2 force_n) noexcept = 0;
  /// Stops the motors and disconnects. Never throws.
  virtual void close() noexcept = 0;
  /// Current status. Real-time safe.
  virtual DeviceStatus status() const noexcept = 0;
  /// Short human-readable name for logs ("simulated pantograph").
  virtual std::string name() const = 0;
};

}  // namespace hk
