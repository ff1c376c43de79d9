#pragma once
// A fake of the libusb calls usb_transport.cpp makes (fake_libusb.cpp defines them with C linkage, and
// test_haptics_io_fakeusb links it instead of libusb): one CDC-ACM device whose bulk endpoints are byte
// queues the test feeds and inspects, so UsbCdcTransport's open sequence, event thread and close run
// without hardware. Not a model of timing or of the kernel.
#include <cstdint>
#include <string>
#include <vector>

namespace fake_usb {

struct ControlRequest {
  std::uint8_t request_type, request;
  std::uint16_t value, index;
  std::vector<std::uint8_t> data;
};

struct Options {
  bool present = true;  // the device is in the list
  std::uint16_t vid = 0x2341, pid = 0x804d;
  std::string serial = "FAKE0001";
  std::vector<std::uint8_t> config_descriptor;  // returned by GET_DESCRIPTOR(CONFIGURATION)
  int open_error = 0;                           // libusb_open's result (e.g. LIBUSB_ERROR_ACCESS)
};

/// An Arduino-Zero-style CDC-ACM configuration descriptor (control interface 0 with its interrupt IN
/// endpoint 0x81, data interface 1 with bulk OUT 0x02 and bulk IN 0x83), as Haply's M0 boards present.
inline const std::vector<std::uint8_t>& arduino_zero_cdc_config() {
  static const std::vector<std::uint8_t> kConfig = {
      0x09, 0x02, 0x4B, 0x00, 0x02, 0x01, 0x00, 0xA0, 0xFA, 0x08, 0x0B, 0x00, 0x02, 0x02, 0x02, 0x00, 0x00, 0x09, 0x04,
      0x00, 0x00, 0x01, 0x02, 0x02, 0x00, 0x00, 0x05, 0x24, 0x00, 0x10, 0x01, 0x05, 0x24, 0x01, 0x01, 0x01, 0x04, 0x24,
      0x02, 0x06, 0x05, 0x24, 0x06, 0x00, 0x01, 0x07, 0x05, 0x81, 0x03, 0x10, 0x00, 0x10, 0x09, 0x04, 0x01, 0x00, 0x02,
      0x0A, 0x00, 0x00, 0x00, 0x07, 0x05, 0x02, 0x02, 0x40, 0x00, 0x00, 0x07, 0x05, 0x83, 0x02, 0x40, 0x00, 0x00};
  return kConfig;
}

/// Resets the fake to `o` (no context, nothing claimed, empty queues and logs).
void reset(const Options& o);
/// Device → host bytes: completes pending bulk IN transfers with them (at most one transfer's length each).
void device_send(const std::vector<std::uint8_t>& bytes);
/// Waits (condition variable, bounded by timeout_ms) until the host has written at least n bytes to the
/// bulk OUT endpoint; returns what it wrote.
std::vector<std::uint8_t> wait_host_bytes(std::size_t n, int timeout_ms);
/// Unplugs the device: pending and later transfers complete with LIBUSB_TRANSFER_NO_DEVICE.
void unplug();

/// What happened so far.
std::vector<ControlRequest> class_requests();  // control transfers other than GET_DESCRIPTOR
std::vector<int> claimed();                    // interfaces claimed now
bool auto_detach();                            // libusb_set_auto_detach_kernel_driver(h, 1) called
int live_transfers();                          // allocated and not freed
int live_contexts();                           // libusb_init minus libusb_exit
int live_handles();                            // libusb_open minus libusb_close

}  // namespace fake_usb
