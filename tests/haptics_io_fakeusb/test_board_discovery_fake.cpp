// Finding the board (io::open_first_board) through the fake libusb: every USB id Haply's boards enumerate
// with is taken once the board behind it answers hAPI, a device that answers garbage or nothing is refused
// with the reason, an id that is not on the bus is passed over, and a late reply is taken as it comes.
// The board is the firmware emulator, bridged to the fake's bulk endpoints by a thread.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "fake_libusb.hpp"
#include "haptics/hapi_emulator.hpp"
#include "haptics/io/haply_device.hpp"
#include "haptics/io/usb_transport.hpp"

namespace hk::io {
namespace {

const std::vector<std::uint8_t>& kConfig = fake_usb::arduino_zero_cdc_config();

/// What the board behind the fake USB port does with the host's bytes.
enum class Board { Haply, Garbage, Silent, Late };

/// A thread that hands the host's bytes to the firmware emulator and its answers back through the fake.
class Bridge {
 public:
  explicit Bridge(Board kind)
      : kind_(kind),
        emu_(hapi::EmulatorParams{}, {0.0, -0.088},
             [](double, Vec2, Vec2) {
               return Vec2{0.0, 0.0};
             }),
        thread_([this] { run(); }) {}
  ~Bridge() {
    stop_ = true;
    thread_.join();
  }

 private:
  void run() {
    std::size_t consumed = 0;
    std::vector<std::uint8_t> held;  // Late: the answers of the last round, sent with the next
    while (!stop_) {
      const std::vector<std::uint8_t> host = fake_usb::wait_host_bytes(consumed + 1, 2);
      if (host.size() <= consumed) continue;
      emu_.receive(host.data() + consumed, static_cast<int>(host.size() - consumed));
      consumed = host.size();
      std::vector<std::uint8_t> out(256);
      out.resize(static_cast<std::size_t>(emu_.take_output(out.data(), static_cast<int>(out.size()))));
      if (out.empty() || kind_ == Board::Silent) continue;
      if (kind_ == Board::Garbage)
        for (std::uint8_t& b : out) b = 0xFF;  // as many bytes as a reply, none of them one
      if (kind_ == Board::Late) std::swap(out, held);
      if (!out.empty()) fake_usb::device_send(out);
    }
  }

  Board kind_;
  hapi::FirmwareEmulator emu_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

BoardCandidate usb(std::uint16_t vid, std::uint16_t pid) {
  char name[32];
  std::snprintf(name, sizeof name, "usb %04x:%04x", vid, pid);
  return {name, [vid, pid] { return std::make_unique<UsbCdcTransport>(vid, pid); }};
}

HaplyDeviceParams quick_params() {
  HaplyDeviceParams p;
  p.open_timeout_ms = 300;
  return p;
}

TEST(BoardDiscoveryFake, EveryIdHaplysBoardsEnumerateWithIsFoundAndTakenOnceItAnswers) {
  const std::uint16_t pids[] = {0x003e, 0x804d, 0x004d, 0x824d, 0x024d};
  for (std::uint16_t pid : pids) {
    fake_usb::Options o;
    o.pid = pid;
    o.config_descriptor = kConfig;
    fake_usb::reset(o);
    Bridge board(Board::Haply);
    std::vector<BoardProbe> probes;
    // The whole default list, in order: the ids not on the bus are passed over with the reason.
    std::vector<BoardCandidate> all;
    for (std::uint16_t p : pids) all.push_back(usb(0x2341, p));
    std::unique_ptr<HaplyDevice> dev = open_first_board(quick_params(), all, &probes);
    ASSERT_TRUE(dev) << std::hex << pid;
    ASSERT_FALSE(probes.empty());
    EXPECT_TRUE(probes.back().answered);
    EXPECT_EQ(probes.back().name, usb(0x2341, pid).name);
    EXPECT_EQ(probes.back().how.rfind("hAPI reply from device id 5 after ", 0), 0u) << probes.back().how;
    for (std::size_t i = 0; i + 1 < probes.size(); ++i) {
      EXPECT_FALSE(probes[i].answered);
      EXPECT_NE(probes[i].how.find("no USB device"), std::string::npos) << probes[i].how;
    }
    EXPECT_EQ(dev->status(), DeviceStatus::Ok);
    dev->close();
  }
}

TEST(BoardDiscoveryFake, ADeviceAnsweringGarbageIsRefusedWithTheReason) {
  fake_usb::Options o;
  o.config_descriptor = kConfig;
  fake_usb::reset(o);
  Bridge board(Board::Garbage);
  std::vector<BoardProbe> probes;
  EXPECT_EQ(open_first_board(quick_params(), {usb(0x2341, 0x804d)}, &probes), nullptr);
  ASSERT_EQ(probes.size(), 1u);
  EXPECT_FALSE(probes[0].answered);
  EXPECT_NE(probes[0].how.find("answered, but with no well-formed hAPI reply from device id 5 within 300 ms"),
            std::string::npos)
      << probes[0].how;
  EXPECT_NE(probes[0].how.find("another device, or another firmware"), std::string::npos) << probes[0].how;
}

TEST(BoardDiscoveryFake, ASilentDeviceIsRefusedWithTheReason) {
  fake_usb::Options o;
  o.config_descriptor = kConfig;
  fake_usb::reset(o);
  Bridge board(Board::Silent);
  std::vector<BoardProbe> probes;
  EXPECT_EQ(open_first_board(quick_params(), {usb(0x2341, 0x804d)}, &probes), nullptr);
  ASSERT_EQ(probes.size(), 1u);
  EXPECT_NE(probes[0].how.find("no reply from device id 5 within 300 ms"), std::string::npos) << probes[0].how;
}

TEST(BoardDiscoveryFake, ABoardWhoseRepliesComeOneTickLateIsTakenAndRunsOn) {
  fake_usb::Options o;
  o.config_descriptor = kConfig;
  fake_usb::reset(o);
  Bridge board(Board::Late);
  std::vector<BoardProbe> probes;
  std::unique_ptr<HaplyDevice> dev = open_first_board(quick_params(), {usb(0x2341, 0x804d)}, &probes);
  ASSERT_TRUE(dev) << (probes.empty() ? "" : probes[0].how);
  // Each reply comes only with the next packet's: the driver takes it then, and keeps sending.
  const HaplyCounters before = dev->counters();
  for (int k = 0; k < 200 && dev->counters().replies - before.replies < 20; ++k) {
    dev->read();
    dev->write_force({0.0, 0.0});
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_GE(dev->counters().replies - before.replies, 20);
  EXPECT_EQ(dev->counters().malformed, 0);
  dev->close();
}

}  // namespace
}  // namespace hk::io
