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
