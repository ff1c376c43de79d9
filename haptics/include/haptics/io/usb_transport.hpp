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
///  - Bytes cross between the caller and the event thread in two ByteChannels (byte_channel.hpp: a
///    lock-free SPSC ring plus eventfds), capacity kRingBytes each: "out" (caller → event thread) and
///    "in" (event thread → caller).
///  - The event thread polls libusb's file descriptors (libusb_get_pollfds, refreshed when libusb's
///    pollfd notifiers say they changed) together with the out channel's data eventfd and its own "wake"
///    eventfd (stop, pollfd changes), then runs
///    libusb_handle_events_timeout_completed with a zero timeout. Transfer callbacks run on it: IN data is
///    pushed into the in channel (bytes that do not fit are dropped and counted: dropped_in_bytes()) and
///    the transfer resubmitted; the one OUT transfer (up to 4096 bytes, LIBUSB_TRANSFER_ADD_ZERO_PACKET,
///    Linux) is filled from the out channel and submitted when its data eventfd fires or the previous OUT
///    transfer completes.
///  - write() (caller) = out.push_wait(): pushes into the ring and writes 1 to the data eventfd
///    (eventfd(2) on an EFD_NONBLOCK eventfd: one syscall, never blocks, no user-space lock). If the ring
///    is full it waits for room with ppoll() on the channel's space eventfd, bounded by timeout_us.
///  - read() (caller) = in.pop_wait(): pops; if empty it waits with ppoll() on the data eventfd, bounded by
///    timeout_us. Nothing else blocks on the caller's side; libusb is never called from read/write.
///  - LIBUSB_TRANSFER_NO_DEVICE in a callback or LIBUSB_ERROR_NO_DEVICE on submit marks the device gone:
///    read() returns the bytes already received, then kGone; write() returns kGone.
///  - close() drops DTR/RTS (best effort), stops the thread (which cancels the transfers and waits for
///    their callbacks, at most 2 s; if some never complete they are leaked rather than freed while
///    pending), releases the interfaces, closes the handle and exits the context.
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
  /// See the file comment; blocks up to ~2 s when the device does not complete cancelled transfers.
  void close() noexcept override;
  /// ByteTransport::write through the out channel (see the file comment for what blocks). Real-time.
  int write(const std::uint8_t* data, int n, int timeout_us) noexcept override;
  /// ByteTransport::read from the in channel (see the file comment for what blocks). Real-time.
  int read(std::uint8_t* buf, int capacity, int timeout_us) noexcept override;
  /// Drops the bytes in the in channel (not those still in flight in IN transfers). Real-time.
  void flush_input() noexcept override;
  /// True between open() and close(), even after the device went.
  bool is_open() const noexcept override;
  /// "usb 2341:804d bus 1 addr 5" when open, "usb 2341:804d" before.
  std::string name() const override;
  /// IN bytes dropped because the in ring was full (the reader fell behind). Real-time.
  std::uint64_t dropped_in_bytes() const noexcept;

  /// Capacity of each byte ring [bytes].
  static constexpr std::size_t kRingBytes = 16384;
  /// IN transfers kept submitted, and the size of each [bytes], rounded down to a multiple of the bulk
  /// IN wMaxPacketSize, and at least one packet.
  static constexpr int kInTransfers = 4, kInTransferBytes = 512;

  struct Impl;  ///< libusb state (usb_transport.cpp)

 private:
  std::uint16_t vid_, pid_;
  int baud_;
  std::string serial_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hk::io
