#pragma once
/// @file usb_cdc.hpp
/// The pure, testable parts of USB CDC-ACM: finding the interfaces and endpoints in a raw configuration
/// descriptor, and the class requests' constants and payloads.
///
/// Sources:
///   USB 2.0 spec §9.6.3 (configuration), §9.6.5 (interface), §9.6.6 (endpoint) descriptor layouts;
///   USB ECN "Interface Association Descriptors" (bDescriptorType 0x0B, 8 bytes);
///   USB CDC 1.2 (CDC120) §4.2 (Communications Interface Class 0x02), §4.3 (subclass 0x02 = ACM),
///   §4.5 (Data Interface Class 0x0A), §5.2.3 (functional descriptors, CS_INTERFACE 0x24),
///   §5.2.3.8 Union functional descriptor (subtype 0x06);
///   USB PSTN 1.2 (PSTN120) §6.3.10 SetLineCoding (0x20), Table 17 line coding structure,
///   §6.3.12 SetControlLineState (0x22, wValue bit0 DTR, bit1 RTS), §6.2 (bmRequestType 0x21:
///   host-to-device, class, interface).

#include <array>
#include <cstdint>

#include "haptics/device.hpp"

namespace hk::io {

/// bmRequestType of CDC class requests to the control interface (PSTN120 §6.2).
inline constexpr std::uint8_t kCdcRequestTypeOut = 0x21;
/// SET_LINE_CODING request code (PSTN120 §6.3.10); data = line_coding_bytes(), wIndex = interface.
inline constexpr std::uint8_t kCdcSetLineCoding = 0x20;
/// SET_CONTROL_LINE_STATE request code (PSTN120 §6.3.12); wValue = kCdcDtr | kCdcRts, no data.
inline constexpr std::uint8_t kCdcSetControlLineState = 0x22;
/// wValue bit of SET_CONTROL_LINE_STATE: DTR present (PSTN120 §6.3.12).
inline constexpr std::uint16_t kCdcDtr = 0x01;
/// wValue bit of SET_CONTROL_LINE_STATE: RTS / carrier on (PSTN120 §6.3.12).
inline constexpr std::uint16_t kCdcRts = 0x02;
/// Interface class codes (CDC120 §4.2, §4.5) and the ACM subclass (§4.3).
inline constexpr std::uint8_t kCdcClassComm = 0x02, kCdcSubclassAcm = 0x02, kCdcClassData = 0x0A;

/// Where a CDC-ACM function lives in a configuration: interface numbers, bulk endpoint addresses
/// (bulk_in has bit 7 set) and their wMaxPacketSize [bytes].
struct CdcEndpoints {
  int control_interface = -1;  ///< bInterfaceNumber of the CDC ACM (class 0x02/0x02) interface
  int data_interface = -1;     ///< bInterfaceNumber of the CDC data (class 0x0A) interface
  std::uint8_t bulk_in = 0;    ///< bEndpointAddress of the bulk IN endpoint (0x80 | n)
  std::uint8_t bulk_out = 0;   ///< bEndpointAddress of the bulk OUT endpoint (n)
  int max_packet_in = 0;       ///< wMaxPacketSize of bulk_in [bytes] (bits 0..10)
  int max_packet_out = 0;      ///< wMaxPacketSize of bulk_out [bytes] (bits 0..10)
};

/// Finds the first CDC-ACM function in a raw configuration descriptor of `length` bytes (the
/// configuration descriptor followed by its interface, class-specific, IAD and endpoint descriptors,
/// wTotalLength bytes in all). The data interface is the Union descriptor's first subordinate interface
/// when there is a Union, else the first class-0x0A interface of the same IAD, else the first one after
/// the control interface; it must have one bulk IN and one bulk OUT endpoint.
/// Throws hk::DeviceError (one line, naming the offset or what is missing) when the bytes are not a
/// well-formed configuration descriptor (bad bLength, wTotalLength beyond `length`) or hold no CDC-ACM
/// function. Reads only config_descriptor[0, length).
CdcEndpoints find_cdc_endpoints(const std::uint8_t* config_descriptor, int length);

/// The 7-byte SET_LINE_CODING payload (PSTN120 Table 17): dwDTERate `baud` [bit/s] little-endian,
/// bCharFormat 0 (1 stop bit), bParityType 0 (none), bDataBits `data_bits`.
/// Throws hk::DeviceError when baud is 1200 (the SAMD "1200 baud touch" resets into the bootloader),
/// baud ≤ 0, or data_bits is not 5, 6, 7, 8 or 16.
std::array<std::uint8_t, 7> line_coding_bytes(int baud, int data_bits = 8);

}  // namespace hk::io
