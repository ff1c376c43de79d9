// CDC-ACM descriptor parsing and request payloads (usb_cdc.hpp).
#include "haptics/io/usb_cdc.hpp"

#include <string>
#include <vector>

namespace hk::io {
namespace {

constexpr std::uint8_t kDtConfig = 0x02, kDtInterface = 0x04, kDtEndpoint = 0x05, kDtIad = 0x0B, kDtCsInterface = 0x24,
                       kCdcUnion = 0x06;

struct Iface {
  int number = -1;
  std::uint8_t cls = 0, subclass = 0;
  int iad = -1;  // index of the IAD whose range holds it, -1 none
  std::uint8_t bulk_in = 0, bulk_out = 0;
  int max_in = 0, max_out = 0;
  int union_data = -1;  // Union's first subordinate interface, for a control interface
};

std::string at(int offset) { return " at byte " + std::to_string(offset); }

// The phases of find_cdc_endpoints, in order.

// Checks the configuration descriptor's own header (its length, type and wTotalLength against the bytes given) and
// returns wTotalLength: the bytes the walk of its descriptors may read.
int checked_total_length(const std::uint8_t* d, int length) {
  if (d == nullptr || length < 9) {
    throw DeviceError("USB configuration descriptor: " + std::to_string(length < 0 ? 0 : length) +
                      " bytes, need at least 9");
  }
  if (d[0] < 9 || d[1] != kDtConfig) {
    throw DeviceError("USB configuration descriptor: not a configuration descriptor (bLength " + std::to_string(d[0]) +
                      ", bDescriptorType " + std::to_string(d[1]) + ")");
  }
  const int total = d[2] | (d[3] << 8);
  if (total > length || total < d[0]) {
    throw DeviceError("USB configuration descriptor: wTotalLength " + std::to_string(total) + " outside [" +
                      std::to_string(d[0]) + ", " + std::to_string(length) + "] bytes given");
  }
  return total;
}

// Walks the descriptors after the header, each length checked against what is left, and lists the interfaces with
// what a CDC-ACM match needs: class and subclass, the IAD holding each, its first bulk IN and OUT endpoints, and a
// control interface's Union subordinate.
std::vector<Iface> list_interfaces(const std::uint8_t* d, int total) {
  struct Iad {
    int first, count;
  };
  std::vector<Iad> iads;
  std::vector<Iface> ifaces;
  Iface* cur = nullptr;
  for (int off = d[0]; off < total;) {
    if (total - off < 2) throw DeviceError("USB configuration descriptor: truncated descriptor" + at(off));
    const int len = d[off];
    const std::uint8_t type = d[off + 1];
    if (len < 2 || len > total - off) {
      throw DeviceError("USB configuration descriptor: bLength " + std::to_string(len) + at(off) + " outside [2, " +
                        std::to_string(total - off) + "]");
    }
    const std::uint8_t* p = d + off;
    if (type == kDtIad && len >= 8) {
      iads.push_back({p[2], p[3]});
    } else if (type == kDtInterface && len >= 9) {
      Iface f;
      f.number = p[2];
      f.cls = p[5];
      f.subclass = p[6];
      for (std::size_t i = 0; i < iads.size(); ++i) {
        if (f.number >= iads[i].first && f.number < iads[i].first + iads[i].count) f.iad = static_cast<int>(i);
      }
      ifaces.push_back(f);
      cur = &ifaces.back();
    } else if (type == kDtCsInterface && len >= 5 && p[2] == kCdcUnion && cur != nullptr && cur->union_data < 0) {
      cur->union_data = p[4];  // bControlInterface = p[3], bSubordinateInterface0 = p[4]
    } else if (type == kDtEndpoint && len >= 7 && cur != nullptr && (p[3] & 0x03) == 0x02) {
      const int mps = (p[4] | (p[5] << 8)) & 0x07FF;
      if ((p[2] & 0x80) != 0) {
        if (cur->bulk_in == 0) cur->bulk_in = p[2], cur->max_in = mps;
      } else if (cur->bulk_out == 0) {
        cur->bulk_out = p[2], cur->max_out = mps;
      }
    }
    off += len;
  }
  return ifaces;
}

// A data interface a byte stream can use: class 0x0A with bulk IN and OUT endpoints of non-zero packet size.
bool usable_data(const Iface& f) {
  return f.cls == kCdcClassData && f.bulk_in != 0 && f.bulk_out != 0 && f.max_in > 0 && f.max_out > 0;
}

// The data interface of the control interface ifaces[c], or null: boards describe the pairing differently, so
// tried in order of how explicit it is: 1. the Union's subordinate interface, 2. one in the same IAD, 3. the next
// usable data interface after it.
const Iface* data_interface_of(const std::vector<Iface>& ifaces, std::size_t c) {
  const Iface& ctl = ifaces[c];
  const Iface* data = nullptr;
  for (const Iface& f : ifaces) {  // 1. the Union's subordinate interface
    if (ctl.union_data >= 0 && f.number == ctl.union_data && usable_data(f)) {
      data = &f;
      break;
    }
  }
  for (std::size_t i = 0; data == nullptr && ctl.iad >= 0 && i < ifaces.size(); ++i) {  // 2. same IAD
    if (ifaces[i].iad == ctl.iad && usable_data(ifaces[i])) data = &ifaces[i];
  }
  for (std::size_t i = c + 1; data == nullptr && i < ifaces.size(); ++i) {  // 3. the next data interface
    if (usable_data(ifaces[i])) data = &ifaces[i];
  }
  return data;
}

}  // namespace

CdcEndpoints find_cdc_endpoints(const std::uint8_t* d, int length) {
  const int total = checked_total_length(d, length);
  const std::vector<Iface> ifaces = list_interfaces(d, total);
  for (std::size_t c = 0; c < ifaces.size(); ++c) {
    const Iface& ctl = ifaces[c];
    if (ctl.cls != kCdcClassComm || ctl.subclass != kCdcSubclassAcm) continue;
    const Iface* data = data_interface_of(ifaces, c);
    if (data == nullptr) continue;
    CdcEndpoints e;
    e.control_interface = ctl.number;
    e.data_interface = data->number;
    e.bulk_in = data->bulk_in;
    e.bulk_out = data->bulk_out;
    e.max_packet_in = data->max_in;
    e.max_packet_out = data->max_out;
    return e;
  }
  throw DeviceError(
      "USB configuration descriptor: no CDC-ACM function (interface class 0x02/0x02 with a class "
      "0x0A data interface holding bulk IN and OUT endpoints) among " +
      std::to_string(ifaces.size()) + " interfaces");
}

std::array<std::uint8_t, 7> line_coding_bytes(int baud, int data_bits) {
  if (baud == 1200) {
    throw DeviceError("line coding: baud 1200 refused (the 1200 baud touch resets SAMD boards into the bootloader)");
  }
  if (baud <= 0) throw DeviceError("line coding: baud " + std::to_string(baud) + " must be > 0");
  if (data_bits != 5 && data_bits != 6 && data_bits != 7 && data_bits != 8 && data_bits != 16) {
    throw DeviceError("line coding: data bits " + std::to_string(data_bits) + " not one of 5, 6, 7, 8, 16");
  }
  const auto b = static_cast<std::uint32_t>(baud);
  return {static_cast<std::uint8_t>(b & 0xFF),
          static_cast<std::uint8_t>((b >> 8) & 0xFF),
          static_cast<std::uint8_t>((b >> 16) & 0xFF),
          static_cast<std::uint8_t>((b >> 24) & 0xFF),
          0,  // bCharFormat: 1 stop bit
          0,  // bParityType: none
          static_cast<std::uint8_t>(data_bits)};
}

}  // namespace hk::io
