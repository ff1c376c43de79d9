// The libusb side without hardware: the CDC transport's setup errors and closed behaviour, the device
// list against sysfs, and the hotplug monitor's lifetime.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <set>
#include <utility>

#include "haptics/io/usb_devices.hpp"
#include "haptics/io/usb_transport.hpp"

namespace hk::io {
namespace {

bool attached(std::uint16_t vid, std::uint16_t pid) {
  const auto list = list_usb_devices();
  return std::any_of(list.begin(), list.end(), [&](const UsbDeviceInfo& d) { return d.vid == vid && d.pid == pid; });
}

TEST(UsbCdcTransport, OpenWithoutTheDeviceNamesVidPid) {
  constexpr std::uint16_t vid = 0x2341, pid = 0x804d;  // Arduino Zero native port
  if (attached(vid, pid)) GTEST_SKIP() << "a 2341:804d device is attached here; this test needs it absent";
  UsbCdcTransport t(vid, pid);
  EXPECT_EQ(t.name(), "usb 2341:804d");
  try {
    t.open();
    FAIL() << "opened an absent device";
  } catch (const DeviceError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("no USB device 2341:804d found", 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << "one line: " << m;
  }
  EXPECT_FALSE(t.is_open());
}

TEST(UsbCdcTransport, SerialIsNamedWhenAbsent) {
  if (attached(0x2341, 0x804d)) GTEST_SKIP() << "a 2341:804d device is attached here";
  UsbCdcTransport t(0x2341, 0x804d, 115200, "HAPLY-0042");
  try {
    t.open();
    FAIL();
  } catch (const DeviceError& e) {
    // without any USB (libusb_init fails) the serial is not reached; with USB it must be named
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("no USB device 2341:804d", 0), 0u) << m;
    if (m.find("libusb_init") == std::string::npos) {
      EXPECT_NE(m.find("HAPLY-0042"), std::string::npos) << m;
    }
  }
}

TEST(UsbCdcTransport, ClosedTransportReadsAndWritesAsGone) {
  UsbCdcTransport t(0x2341, 0x804d);
  std::uint8_t buf[4] = {};
  EXPECT_EQ(t.read(buf, 4, 1000), ByteTransport::kGone);
  EXPECT_EQ(t.write(buf, 4, 1000), ByteTransport::kGone);
  EXPECT_EQ(t.dropped_in_bytes(), 0u);
  t.flush_input();
  t.close();
  t.close();
  EXPECT_FALSE(t.is_open());
}

TEST(UsbCdcTransport, Baud1200IsRefused) {
  try {
    UsbCdcTransport t(0x2341, 0x804d, 1200);
    FAIL() << "1200 accepted";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("usb 2341:804d"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1200"), std::string::npos) << e.what();
  }
  EXPECT_THROW(UsbCdcTransport(0x2341, 0x804d, 0), DeviceError);
}

TEST(UsbDevices, ListNeverThrowsAndGivesAReasonWhenEmpty) {
  std::string reason = "stale";
  std::vector<UsbDeviceInfo> list;
  ASSERT_NO_THROW(list = list_usb_devices(&reason));
  if (list.empty()) {
    // either libusb could not start (then it says why) or the bus is really empty (no reason)
    EXPECT_NE(reason, "stale");
  } else {
    EXPECT_TRUE(reason.empty()) << reason;
  }
  for (const auto& d : list) {
    EXPECT_GT(d.bus, 0);
    EXPECT_GT(d.address, 0);
  }
}

// Reads a hex sysfs attribute like idVendor ("2341\n"); -1 when absent.
long read_hex(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::string s;
  if (!(f >> s)) return -1;
  return std::stol(s, nullptr, 16);
}

TEST(UsbDevices, VidPidMatchSysfs) {
  const std::filesystem::path sys = "/sys/bus/usb/devices";
  std::error_code ec;
  if (!std::filesystem::is_directory(sys, ec)) {
    GTEST_SKIP() << sys << " does not exist (no USB bus in this container), nothing to compare with";
  }
  std::multiset<std::pair<long, long>> from_sysfs;
  for (const auto& e : std::filesystem::directory_iterator(sys, ec)) {
    const long v = read_hex(e.path() / "idVendor"), p = read_hex(e.path() / "idProduct");
    if (v >= 0 && p >= 0) from_sysfs.insert({v, p});  // interfaces (1-1:1.0) have no idVendor
  }
  std::string reason;
  const auto list = list_usb_devices(&reason);
  if (list.empty() && !reason.empty() && !from_sysfs.empty()) {
    GTEST_SKIP() << "sysfs lists " << from_sysfs.size() << " devices but libusb cannot start: " << reason;
  }
  std::multiset<std::pair<long, long>> from_libusb;
  for (const auto& d : list) from_libusb.insert({d.vid, d.pid});
  EXPECT_EQ(from_libusb, from_sysfs);
}

TEST(UsbHotplugMonitor, ConstructsAndDestructsCleanly) {
  std::atomic<int> calls{0};
  {
    // ffff:fffe is not a real device: nothing should arrive
    UsbHotplugMonitor m(0xffff, 0xfffe, [&](bool) { calls.fetch_add(1); });
    if (m.supported()) {
      EXPECT_TRUE(m.reason().empty());
    } else {
      EXPECT_FALSE(m.reason().empty()) << "unsupported must say why";
    }
  }
  EXPECT_EQ(calls.load(), 0);
  // twice in a row, and two at once: each has its own context and thread
  UsbHotplugMonitor a(0x2341, 0x804d, [](bool) {});
  UsbHotplugMonitor b(0x2341, 0x804d, nullptr);
  EXPECT_EQ(a.supported(), b.supported());
}

}  // namespace
}  // namespace hk::io
