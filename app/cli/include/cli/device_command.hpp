#pragma once
/// @file device_command.hpp
/// `haptic-kiosk devices`: the USB devices on the bus (those with an id of [device] usb_ids marked), the
/// serial devices of /dev/serial/by-id, and each way to a board asked for an hAPI reply, with what it
/// answered; and `haptic-kiosk calibrate`: with the handle resting at the park place ([device] park_x_m,
/// park_y_m; by default the board's home pose), set the encoder offsets so the angles read right.

#include <string>

namespace hk::app {

/// What `haptic-kiosk devices` was asked to do.
struct DevicesOptions {
  std::string config_path;  ///< settings ([device] usb_ids, transport, serial_path); empty: defaults
};

/// Prints the listing to standard output. Exit code 0, also when nothing is found ("no USB device found"
/// with the reason, e.g. no USB bus in a container; "none to ask"). Throws config::ConfigError for a bad settings file.
int run_devices(const DevicesOptions& options);

/// What `haptic-kiosk calibrate` was asked to do.
struct CalibrateOptions {
  std::string config_path;       ///< settings file to read and to write the new offsets into (required)
  std::string device = "haply";  ///< "haply" (the board per [device]) or "haply-emulator[:...]" (tests, demos: the
                                 ///< handle rests at the park place)
};

/// Opens the device, takes the angles of 50 zero-torque ticks (their mean), computes the offsets
/// (io::calibrated_offsets), writes encoder1_offset_deg and encoder2_offset_deg into the settings file
/// (atomically, every other value kept) and prints old and new offsets. Returns 0; throws DeviceError when the
/// device cannot be opened or stops answering, DeviceChoiceError for a bad --device, config::ConfigError for a
/// bad settings file, and AppError when the park place is out of the links' reach.
int run_calibrate(const CalibrateOptions& options);

}  // namespace hk::app
