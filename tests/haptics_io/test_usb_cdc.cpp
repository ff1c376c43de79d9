// CDC-ACM descriptor parsing and line coding: a golden Arduino-Zero-style configuration descriptor,
// composite and fallback layouts, errors, and thousands of mutated descriptors read behind a guard page.
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "haptics/io/usb_cdc.hpp"

namespace hk::io {
namespace {

// Configuration descriptor of a SAMD21 (Arduino Zero core) CDC-ACM device, laid out per USB 2.0 §9.6
// and CDC120 §5.2.3 / PSTN120 §5.3: 75 bytes.
const std::vector<std::uint8_t> kArduinoZero = {
    // configuration: bLength 9, CONFIGURATION, wTotalLength 75, 2 interfaces, value 1, iConfig 0, bus powered
    // + remote wakeup, 500 mA
    0x09,
    0x02,
    0x4B,
    0x00,
    0x02,
    0x01,
    0x00,
    0xA0,
    0xFA,
    // IAD: first interface 0, 2 interfaces, class CDC 0x02, subclass ACM 0x02, protocol 0, iFunction 0
    0x08,
    0x0B,
    0x00,
    0x02,
    0x02,
    0x02,
    0x00,
    0x00,
    // interface 0 alt 0, 1 endpoint, class 0x02 subclass 0x02 protocol 0x00
    0x09,
    0x04,
    0x00,
    0x00,
    0x01,
    0x02,
    0x02,
    0x00,
    0x00,
    // CS_INTERFACE header (subtype 0x00), bcdCDC 1.10
    0x05,
    0x24,
    0x00,
    0x10,
    0x01,
    // call management (0x01): bmCapabilities 1, data interface 1
    0x05,
    0x24,
    0x01,
    0x01,
    0x01,
    // ACM (0x02): bmCapabilities 0x06 (line coding + break)
    0x04,
    0x24,
    0x02,
    0x06,
    // union (0x06): control 0, subordinate 1
    0x05,
    0x24,
    0x06,
    0x00,
    0x01,
    // endpoint 0x81 IN, interrupt, 16 bytes, interval 16
    0x07,
    0x05,
    0x81,
    0x03,
    0x10,
    0x00,
    0x10,
    // interface 1 alt 0, 2 endpoints, class 0x0A (CDC data)
    0x09,
    0x04,
    0x01,
    0x00,
    0x02,
    0x0A,
    0x00,
    0x00,
    0x00,
    // endpoint 0x02 OUT, bulk, 64 bytes
    0x07,
    0x05,
    0x02,
    0x02,
    0x40,
    0x00,
    0x00,
    // endpoint 0x83 IN, bulk, 64 bytes
    0x07,
    0x05,
    0x83,
    0x02,
    0x40,
    0x00,
    0x00,
};

CdcEndpoints parse(const std::vector<std::uint8_t>& d) {
  return find_cdc_endpoints(d.data(), static_cast<int>(d.size()));
}

std::string error_of(const std::vector<std::uint8_t>& d, int length) {
  try {
    find_cdc_endpoints(d.data(), length);
  } catch (const DeviceError& e) {
    return e.what();
  }
  return "";
}

void set_total(std::vector<std::uint8_t>& d) {
  d[2] = static_cast<std::uint8_t>(d.size() & 0xFF);
  d[3] = static_cast<std::uint8_t>(d.size() >> 8);
}

TEST(UsbCdc, GoldenArduinoZeroDescriptor) {
  ASSERT_EQ(kArduinoZero.size(), 75u);
  const CdcEndpoints e = parse(kArduinoZero);
  EXPECT_EQ(e.control_interface, 0);
  EXPECT_EQ(e.data_interface, 1);
  EXPECT_EQ(e.bulk_in, 0x83);
  EXPECT_EQ(e.bulk_out, 0x02);
  EXPECT_EQ(e.max_packet_in, 64);
  EXPECT_EQ(e.max_packet_out, 64);
}

TEST(UsbCdc, CompositeDeviceUsesTheUnionSubordinate) {
  // interface 0: HID with an interrupt IN; interface 1: CDC ACM whose Union names interface 3;
  // interface 2: a CDC data interface that is NOT the one named; interface 3: the named data interface.
  std::vector<std::uint8_t> d = {0x09, 0x02, 0,    0,    0x04, 0x01, 0x00, 0x80, 0x32, 0x09, 0x04, 0x00,
                                 0x00, 0x01, 0x03, 0x00, 0x00, 0x00,  // HID
                                 0x07, 0x05, 0x84, 0x03, 0x08, 0x00, 0x0A, 0x09, 0x04, 0x01, 0x00, 0x00,
                                 0x02, 0x02, 0x01, 0x00,                                // ACM, no endpoint
                                 0x05, 0x24, 0x06, 0x01, 0x03,                          // union → 3
                                 0x09, 0x04, 0x02, 0x00, 0x02, 0x0A, 0x00, 0x00, 0x00,  // data 2
                                 0x07, 0x05, 0x05, 0x02, 0x40, 0x00, 0x00, 0x07, 0x05, 0x86, 0x02, 0x40,
                                 0x00, 0x00, 0x09, 0x04, 0x03, 0x00, 0x02, 0x0A, 0x00, 0x00, 0x00,  // data 3
                                 0x07, 0x05, 0x87, 0x02, 0x00, 0x02, 0x00,  // IN 512 (high speed)
                                 0x07, 0x05, 0x08, 0x02, 0x00, 0x02, 0x00};
  set_total(d);
  const CdcEndpoints e = parse(d);
  EXPECT_EQ(e.control_interface, 1);
  EXPECT_EQ(e.data_interface, 3);
  EXPECT_EQ(e.bulk_in, 0x87);
  EXPECT_EQ(e.bulk_out, 0x08);
  EXPECT_EQ(e.max_packet_in, 512);
  EXPECT_EQ(e.max_packet_out, 512);
}

TEST(UsbCdc, WithoutUnionOrIadTheNextDataInterfaceIsUsed) {
  std::vector<std::uint8_t> d = {0x09, 0x02, 0,    0,    0x02, 0x01, 0x00, 0x80, 0x32, 0x09, 0x04, 0x00, 0x00, 0x00,
                                 0x02, 0x02, 0x01, 0x00, 0x09, 0x04, 0x01, 0x00, 0x02, 0x0A, 0x00, 0x00, 0x00, 0x07,
                                 0x05, 0x81, 0x02, 0x20, 0x00, 0x00, 0x07, 0x05, 0x01, 0x02, 0x20, 0x00, 0x00};
  set_total(d);
  const CdcEndpoints e = parse(d);
  EXPECT_EQ(e.control_interface, 0);
  EXPECT_EQ(e.data_interface, 1);
  EXPECT_EQ(e.bulk_in, 0x81);
  EXPECT_EQ(e.bulk_out, 0x01);
  EXPECT_EQ(e.max_packet_in, 32);
}

TEST(UsbCdc, NoCdcFunctionIsAnError) {
  std::vector<std::uint8_t> hid = {0x09, 0x02, 0,    0,    0x01, 0x01, 0x00, 0x80, 0x32, 0x09, 0x04, 0x00, 0x00,
                                   0x01, 0x03, 0x01, 0x02, 0x00, 0x07, 0x05, 0x81, 0x03, 0x08, 0x00, 0x0A};
  set_total(hid);
  EXPECT_NE(error_of(hid, static_cast<int>(hid.size())).find("no CDC-ACM function"), std::string::npos);
}

TEST(UsbCdc, DataInterfaceWithoutBulkOutIsAnError) {
  std::vector<std::uint8_t> d = kArduinoZero;
  d[d.size() - 14 + 3] = 0x03;  // bulk OUT 0x02 becomes interrupt
  EXPECT_NE(error_of(d, static_cast<int>(d.size())).find("no CDC-ACM function"), std::string::npos);
}

TEST(UsbCdc, EveryTruncationIsAnErrorNamingTheProblem) {
  for (int len = 0; len < static_cast<int>(kArduinoZero.size()); ++len) {
    EXPECT_FALSE(error_of(kArduinoZero, len).empty()) << "cut at " << len;
    // also with wTotalLength claiming the cut length, so the walk itself ends early
    std::vector<std::uint8_t> d(kArduinoZero.begin(), kArduinoZero.begin() + len);
    if (len >= 4) {
      d[2] = static_cast<std::uint8_t>(len);
      d[3] = 0;
    }
    EXPECT_FALSE(error_of(d, len).empty()) << "wTotalLength cut at " << len;
  }
  EXPECT_NE(error_of(kArduinoZero, 40).find("wTotalLength 75"), std::string::npos) << error_of(kArduinoZero, 40);
}

TEST(UsbCdc, ZeroBLengthIsAnErrorNotAnEndlessLoop) {
  std::vector<std::uint8_t> d = kArduinoZero;
  d[9] = 0;  // IAD bLength 0
  EXPECT_NE(error_of(d, static_cast<int>(d.size())).find("bLength 0 at byte 9"), std::string::npos);
}

// The descriptor ends exactly at a PROT_NONE page: reading one byte past `length` crashes the test.
class GuardedBuffer {
 public:
  GuardedBuffer() : page_(static_cast<std::size_t>(sysconf(_SC_PAGESIZE))) {
    base_ = static_cast<std::uint8_t*>(
        mmap(nullptr, 2 * page_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
    if (base_ != MAP_FAILED) mprotect(base_ + page_, page_, PROT_NONE);
  }
  ~GuardedBuffer() {
    if (base_ != MAP_FAILED) munmap(base_, 2 * page_);
  }
  bool ok() const { return base_ != MAP_FAILED; }
  const std::uint8_t* place(const std::vector<std::uint8_t>& d) {
    std::uint8_t* at = base_ + page_ - d.size();
    if (!d.empty()) std::memcpy(at, d.data(), d.size());
    return at;
  }

 private:
  std::size_t page_;
  std::uint8_t* base_;
};

TEST(UsbCdc, RandomMutationsNeverCrashOrReadOutOfBounds) {
  GuardedBuffer guard;
  ASSERT_TRUE(guard.ok());
  std::mt19937 rng(20261122);
  int parsed = 0, refused = 0;
  for (int i = 0; i < 5000; ++i) {
    std::vector<std::uint8_t> d = kArduinoZero;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < edits; ++k) d[rng() % d.size()] = static_cast<std::uint8_t>(rng());
    if (rng() % 3 == 0) d.resize(rng() % (d.size() + 1));
    const std::uint8_t* p = guard.place(d);
    try {
      const CdcEndpoints e = find_cdc_endpoints(p, static_cast<int>(d.size()));
      ++parsed;
      EXPECT_NE(e.bulk_in & 0x80, 0) << "mutation " << i;
      EXPECT_EQ(e.bulk_out & 0x80, 0) << "mutation " << i;
      EXPECT_GT(e.max_packet_in, 0);
      EXPECT_LE(e.max_packet_in, 2047);
      EXPECT_GE(e.control_interface, 0);
      EXPECT_GE(e.data_interface, 0);
    } catch (const DeviceError&) {
      ++refused;
    }
  }
  EXPECT_GT(parsed, 0) << "some mutations (e.g. of bInterval or iConfiguration) leave a valid descriptor";
  EXPECT_GT(refused, 0);
}

TEST(UsbCdc, NullOrShortInputIsAnError) {
  EXPECT_THROW(find_cdc_endpoints(nullptr, 75), DeviceError);
  EXPECT_THROW(find_cdc_endpoints(kArduinoZero.data(), -3), DeviceError);
}

TEST(UsbCdc, LineCodingBytes) {
  const auto a = line_coding_bytes(115200);
  EXPECT_EQ(a, (std::array<std::uint8_t, 7>{0x00, 0xC2, 0x01, 0x00, 0x00, 0x00, 0x08}));
  const auto b = line_coding_bytes(2000000, 7);
  EXPECT_EQ(b, (std::array<std::uint8_t, 7>{0x80, 0x84, 0x1E, 0x00, 0x00, 0x00, 0x07}));
}

TEST(UsbCdc, LineCodingRefuses1200AndBadValues) {
  try {
    line_coding_bytes(1200);
    FAIL() << "1200 accepted";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("1200"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("bootloader"), std::string::npos);
  }
  EXPECT_THROW(line_coding_bytes(0), DeviceError);
  EXPECT_THROW(line_coding_bytes(-9600), DeviceError);
  EXPECT_THROW(line_coding_bytes(9600, 9), DeviceError);
  EXPECT_NO_THROW(line_coding_bytes(1201));
}

TEST(UsbCdc, RequestConstantsMatchPstn) {
  EXPECT_EQ(kCdcRequestTypeOut, 0x21);
  EXPECT_EQ(kCdcSetLineCoding, 0x20);
  EXPECT_EQ(kCdcSetControlLineState, 0x22);
  EXPECT_EQ(kCdcDtr | kCdcRts, 0x03);
}

}  // namespace
}  // namespace hk::io
