#pragma once
/// @file usb_devices.hpp
/// USB discovery through libusb: a list of attached devices, and arrival/departure notifications.
///
/// Sources (libusb 1.0 API, https://libusb.sourceforge.io/api-1.0/): libusb_init, libusb_get_device_list,
/// libusb_get_device_descriptor, libusb_get_bus_number, libusb_get_device_address, libusb_open,
/// libusb_get_string_descriptor_ascii ("Device handling and enumeration", "USB descriptors");
/// libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG), libusb_hotplug_register_callback,
/// libusb_hotplug_deregister_callback ("Device hotplug event notification");
/// libusb_handle_events_timeout_completed, libusb_interrupt_event_handler ("Polling and timing").

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace hk::io {

/// One attached USB device.
struct UsbDeviceInfo {
  std::uint16_t vid = 0, pid = 0;  ///< idVendor, idProduct of the device descriptor
  int bus = 0, address = 0;        ///< bus number and device address on it
  /// String descriptors (iManufacturer, iProduct, iSerialNumber) in ASCII; empty when the device has
  /// none or they cannot be read (opening the device needs permission on /dev/bus/usb/BBB/DDD).
  std::string manufacturer, product, serial;
};

/// The attached USB devices (root hubs included), in libusb's order. Never throws: when libusb cannot
/// start (no usbfs, e.g. in a container) or cannot list, returns an empty list and, if `reason` is not
/// null, sets *reason to a one-line cause ("libusb_init: LIBUSB_ERROR_OTHER ..."); *reason is cleared
/// on success. Setup-time: allocates and does I/O.
std::vector<UsbDeviceInfo> list_usb_devices(std::string* reason = nullptr);

/// Calls `on_change(true)` when a device with `vid`:`pid` (any product of `vid` when pid < 0) arrives and
/// `on_change(false)` when one leaves.
/// Devices already attached are reported as arrivals too (LIBUSB_HOTPLUG_ENUMERATE), from inside the
/// constructor on the constructing thread; the libusb docs warn that with ENUMERATE one arrival may be
/// reported twice and a departure may come without its arrival, so treat calls as "state may have
/// changed" and re-check with list_usb_devices() if exact counts matter. Runs its own libusb context and
/// event thread; later calls come on that thread and must not block long or call back into the monitor. When libusb
/// cannot start or lacks hotplug support (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) == 0), supported() is false,
/// nothing is ever called, and callers poll list_usb_devices() instead. Never throws from the constructor for lack of
/// USB.
class UsbHotplugMonitor {
 public:
  UsbHotplugMonitor(std::uint16_t vid, int pid, std::function<void(bool arrived)> on_change);
  /// Deregisters the callback and joins the event thread; no call to on_change after it returns.
  ~UsbHotplugMonitor();
  UsbHotplugMonitor(const UsbHotplugMonitor&) = delete;
  UsbHotplugMonitor& operator=(const UsbHotplugMonitor&) = delete;

  /// True when notifications are delivered.
  bool supported() const noexcept { return supported_; }
  /// Why not supported (one line), empty when supported.
  const std::string& reason() const noexcept { return reason_; }

 private:
  std::function<void(bool)> on_change_;
  void* ctx_ = nullptr;  // libusb_context*
  int handle_ = 0;       // libusb_hotplug_callback_handle
  bool supported_ = false;
  std::string reason_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace hk::io
