#pragma once
/// @file usb_transport.hpp
/// ByteTransport speaking USB CDC-ACM directly through libusb (no cdc_acm tty in between).
///
/// Threads and what blocks:
///  - open() creates a libusb context, finds the device, sets auto-detach of the kernel driver, claims the
///    control and data interfaces found by find_cdc_endpoints(), sends SET_LINE_CODING and
///    SET_CONTROL_LINE_STATE(DTR|RTS) (synchronous libusb_control_transfer, 1 s timeout each), allocates
///    the two byte rings, the asynchronous transfers and their buffers, submits the IN transfers and
///    starts the event thread. Everything that allocates happens here.
///  - The event thread polls libusb's file descriptors (libusb_get_pollfds, refreshed when libusb's
///    pollfd notifiers say they changed) together with a "wake" eventfd, then runs
///    libusb_handle_events_timeout_completed with a zero timeout. Transfer callbacks run on it: IN data is
///    pushed into the in ring (bytes that do not fit are dropped and counted: dropped_in_bytes()) and the
///    transfer resubmitted; OUT transfers are filled from the out ring and submitted when the wake eventfd
///    fires or an OUT transfer completes.
///  - write() (caller) pushes into the out ring (SPSC, lock-free) and writes 1 to the wake eventfd
///    (eventfd(2) write: a syscall that never blocks with EFD_NONBLOCK and takes no user-space lock). If
///    the ring is full it waits for room with ppoll() on the "space" eventfd, bounded by timeout_us.
///  - read() (caller) pops from the in ring; if empty it waits with ppoll() on the "data" eventfd, bounded
///    by timeout_us. Nothing else blocks on the caller's side; libusb is never called from read/write.
///  - LIBUSB_TRANSFER_NO_DEVICE in a callback or LIBUSB_ERROR_NO_DEVICE on submit marks the device gone:
///    read() returns the bytes already received, then kGone; write() returns kGone.
///  - close() drops DTR/RTS (best effort), stops the thread (which cancels the transfers and waits for
///    their callbacks), releases the interfaces, closes the handle and exits the context.
///
/// Sources (libusb 1.0 API, https://libusb.sourceforge.io/api-1.0/): "Asynchronous device I/O"
/// (libusb_alloc_transfer, libusb_fill_bulk_transfer, libusb_submit_transfer, libusb_cancel_transfer,
/// transfer status LIBUSB_TRANSFER_NO_DEVICE / CANCELLED), "Polling and timing" (libusb_get_pollfds,
/// libusb_set_pollfd_notifiers, libusb_get_next_timeout, libusb_handle_events_timeout_completed),
/// "Synchronous device I/O" (libusb_control_transfer), "Device handling and enumeration"
/// (libusb_set_auto_detach_kernel_driver, libusb_claim_interface, libusb_get_descriptor);
/// CDC requests: PSTN120 §6.3.10, §6.3.12 (see usb_cdc.hpp).

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "haptics/io/byte_transport.hpp"

namespace hk::io {

/// CDC-ACM over libusb. One reader thread and one writer thread (SPSC rings).
class UsbCdcTransport final : public ByteTransport {
 public:
  /// The device `vid`:`pid` (and, when not empty, the iSerialNumber string `serial`) at `baud` [bit/s].
  /// Throws hk::DeviceError naming the baud when it is 1200 (bootloader touch) or ≤ 0. Does not open.
  UsbCdcTransport(std::uint16_t vid, std::uint16_t pid, int baud = 115200, std::string serial = "");
  ~UsbCdcTransport() override;
  UsbCdcTransport(const UsbCdcTransport&) = delete;
  UsbCdcTransport& operator=(const UsbCdcTransport&) = delete;

  /// See the file comment. Throws hk::DeviceError, one line: "no USB device 2341:804d found",
  /// "usb 2341:804d: libusb_open: LIBUSB_ERROR_ACCESS ...", "usb 2341:804d: no CDC-ACM function ...", or
  /// "libusb_init: ..." when there is no USB at all.
  void open() override;
  void close() noexcept override;
  int write(const std::uint8_t* data, int n, int timeout_us) noexcept override;
  int read(std::uint8_t* buf, int capacity, int timeout_us) noexcept override;
  void flush_input() noexcept override;
  bool is_open() const noexcept override;
  /// "usb 2341:804d bus 1 addr 5" when open, "usb 2341:804d" before.
  std::string name() const override;
  /// IN bytes dropped because the in ring was full (the reader fell behind). Real-time.
  std::uint64_t dropped_in_bytes() const noexcept;

  /// Capacity of each byte ring [bytes].
  static constexpr std::size_t kRingBytes = 16384;
  /// IN transfers kept submitted, and the size of each [bytes] (a multiple of wMaxPacketSize).
  static constexpr int kInTransfers = 4, kInTransferBytes = 512;

  struct Impl;  ///< libusb state (usb_transport.cpp)

 private:
  std::uint16_t vid_, pid_;
  int baud_;
  std::string serial_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hk::io
