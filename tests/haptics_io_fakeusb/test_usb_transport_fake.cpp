// UsbCdcTransport against a fake libusb (fake_libusb.hpp): the open sequence (auto-detach, claims, the
// CDC class requests and their bytes), bytes both ways through the event thread, unplug → kGone, and a
// close that releases and frees everything. What it cannot show: real kernel/USB timing and errors.
#include <gtest/gtest.h>
#include <libusb.h>

#include <chrono>
#include <string>
#include <vector>

#include "fake_libusb.hpp"
#include "haptics/io/usb_cdc.hpp"
#include "haptics/io/usb_transport.hpp"

namespace hk::io {
namespace {

const std::vector<std::uint8_t>& kConfig = fake_usb::arduino_zero_cdc_config();

fake_usb::Options device() {
  fake_usb::Options o;
  o.config_descriptor = kConfig;
  return o;
}

void expect_all_released() {
  EXPECT_TRUE(fake_usb::claimed().empty());
  EXPECT_EQ(fake_usb::live_transfers(), 0);
  EXPECT_EQ(fake_usb::live_handles(), 0);
  EXPECT_EQ(fake_usb::live_contexts(), 0);
}

std::string open_error(UsbCdcTransport& t) {
  try {
    t.open();
  } catch (const DeviceError& e) {
    return e.what();
  }
  return "";
}

TEST(UsbCdcTransportFake, OpenClaimsAndConfiguresTheCdcFunction) {
  fake_usb::reset(device());
  UsbCdcTransport t(0x2341, 0x804d, 115200);
  t.open();
  EXPECT_TRUE(t.is_open());
  EXPECT_EQ(t.name(), "usb 2341:804d bus 1 addr 5");
  EXPECT_TRUE(fake_usb::auto_detach());
  EXPECT_EQ(fake_usb::claimed(), (std::vector<int>{0, 1}));
  const auto req = fake_usb::class_requests();
  ASSERT_EQ(req.size(), 2u);
  EXPECT_EQ(req[0].request_type, 0x21);
  EXPECT_EQ(req[0].request, kCdcSetLineCoding);
  EXPECT_EQ(req[0].index, 0) << "to the control interface";
  EXPECT_EQ(req[0].data, (std::vector<std::uint8_t>{0x00, 0xC2, 0x01, 0x00, 0x00, 0x00, 0x08}));
  EXPECT_EQ(req[1].request, kCdcSetControlLineState);
  EXPECT_EQ(req[1].value, kCdcDtr | kCdcRts);
  EXPECT_EQ(fake_usb::live_transfers(), UsbCdcTransport::kInTransfers + 1);
  t.close();
  EXPECT_FALSE(t.is_open());
  const auto after = fake_usb::class_requests();
  ASSERT_EQ(after.size(), 3u);
  EXPECT_EQ(after[2].request, kCdcSetControlLineState);
  EXPECT_EQ(after[2].value, 0) << "close drops DTR/RTS";
  expect_all_released();
}

TEST(UsbCdcTransportFake, BytesBothWays) {
  fake_usb::reset(device());
  UsbCdcTransport t(0x2341, 0x804d);
  t.open();
  const std::vector<std::uint8_t> cmd = {0x02, 0xAA, 0x00, 0x55};
  ASSERT_EQ(t.write(cmd.data(), 4, 0), 4) << "fits in the out ring at once";
  EXPECT_EQ(fake_usb::wait_host_bytes(4, 5000), cmd);

  std::vector<std::uint8_t> reply(1000);
  for (std::size_t i = 0; i < reply.size(); ++i) reply[i] = static_cast<std::uint8_t>(i * 7);
  fake_usb::device_send(reply);  // more than one 512-byte IN transfer
  std::vector<std::uint8_t> got;
  std::uint8_t buf[300];
  while (got.size() < reply.size()) {
    const int n = t.read(buf, sizeof buf, 2000000);
    ASSERT_GT(n, 0) << "nothing within 2 s after " << got.size() << " bytes";
    got.insert(got.end(), buf, buf + n);
  }
  EXPECT_EQ(got, reply);
  EXPECT_EQ(t.read(buf, sizeof buf, 0), 0);
  EXPECT_EQ(t.dropped_in_bytes(), 0u);

  std::vector<std::uint8_t> big(40000);  // larger than the 16 KiB out ring: write waits for room
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<std::uint8_t>(i % 253);
  int sent = 0;
  while (sent < static_cast<int>(big.size())) {
    const int n = t.write(big.data() + sent, static_cast<int>(big.size()) - sent, 2000000);
    ASSERT_GT(n, 0);
    sent += n;
  }
  const auto host = fake_usb::wait_host_bytes(4 + big.size(), 5000);
  ASSERT_EQ(host.size(), 4 + big.size());
  EXPECT_TRUE(std::equal(big.begin(), big.end(), host.begin() + 4));
  t.close();
  expect_all_released();
}

TEST(UsbCdcTransportFake, UnplugIsGoneAfterTheBytesAlreadyReceived) {
  fake_usb::reset(device());
  UsbCdcTransport t(0x2341, 0x804d);
  t.open();
  fake_usb::device_send({1, 2, 3});
  std::uint8_t buf[8];
  ASSERT_EQ(t.read(buf, 1, 2000000), 1);  // the three bytes are in the in ring now
  fake_usb::unplug();
  EXPECT_EQ(t.read(buf, 8, 2000000), 2) << "bytes received before the unplug come first";
  // A read that waits up to 60 s returns kGone, not the time-out's 0: the unplug was signalled.
  EXPECT_EQ(t.read(buf, 8, 60000000), ByteTransport::kGone) << "gone was not signalled";
  EXPECT_EQ(t.write(buf, 2, 0), ByteTransport::kGone);
  EXPECT_TRUE(t.is_open());
  t.close();
  EXPECT_EQ(fake_usb::class_requests().size(), 2u) << "no DTR drop sent to a gone device";
  expect_all_released();
}

TEST(UsbCdcTransportFake, SerialMustMatch) {
  fake_usb::reset(device());
  UsbCdcTransport t(0x2341, 0x804d, 115200, "OTHER");
  EXPECT_EQ(open_error(t), "no USB device 2341:804d serial OTHER found");
  expect_all_released();
  UsbCdcTransport u(0x2341, 0x804d, 115200, "FAKE0001");
  u.open();
  EXPECT_TRUE(u.is_open());
}

TEST(UsbCdcTransportFake, AbsentDeniedAndNotCdcAreOneLineErrors) {
  fake_usb::Options absent = device();
  absent.present = false;
  fake_usb::reset(absent);
  UsbCdcTransport t(0x2341, 0x804d);
  EXPECT_EQ(open_error(t), "no USB device 2341:804d found");
  expect_all_released();

  fake_usb::Options denied = device();
  denied.open_error = LIBUSB_ERROR_ACCESS;
  fake_usb::reset(denied);
  EXPECT_EQ(open_error(t).rfind("usb 2341:804d: libusb_open: LIBUSB_ERROR_ACCESS", 0), 0u);
  expect_all_released();

  fake_usb::Options hid = device();
  hid.config_descriptor = {0x09, 0x02, 0x19, 0x00, 0x01, 0x01, 0x00, 0x80, 0x32, 0x09, 0x04, 0x00, 0x00,
                           0x01, 0x03, 0x01, 0x02, 0x00, 0x07, 0x05, 0x81, 0x03, 0x08, 0x00, 0x0A};
  fake_usb::reset(hid);
  const std::string e = open_error(t);
  EXPECT_EQ(e.rfind("usb 2341:804d bus 1 addr 5: USB configuration descriptor: no CDC-ACM function", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos);
  EXPECT_FALSE(t.is_open());
  expect_all_released();
}

}  // namespace
}  // namespace hk::io
