#include "cli/device_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/load.hpp"
#include "formats/app_error.hpp"
#include "haptics/hapi_emulator.hpp"
#include "haptics/io/haply_device.hpp"
#include "haptics/io/tty_transport.hpp"
#include "haptics/io/usb_devices.hpp"
#include "haptics/pty_emulator.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/device_setup.hpp"
#include "runtime/runtime_params.hpp"

namespace hk::app {

int run_devices(const DevicesOptions& o) {
  const config::Settings s = o.config_path.empty() ? config::Settings{} : config::load_settings(o.config_path);
  const std::vector<config::UsbId> ids = config::parse_usb_ids(s.device.usb_ids);
  std::string reason;
  const std::vector<io::UsbDeviceInfo> usb = io::list_usb_devices(&reason);
  std::printf("USB devices:\n");
  if (usb.empty()) std::printf("  no USB device found%s%s\n", reason.empty() ? "" : ": ", reason.c_str());
  for (const io::UsbDeviceInfo& d : usb) {
    const bool listed = std::any_of(ids.begin(), ids.end(),
                                    [&](const config::UsbId& id) { return id.vid == d.vid && id.pid == d.pid; });
    std::string label = d.manufacturer;
    if (!d.product.empty()) label += (label.empty() ? "" : " ") + d.product;
    if (label.empty()) label = "(no name readable)";
    std::printf("  %04x:%04x bus %d address %d  %s  %s\n", d.vid, d.pid, d.bus, d.address, label.c_str(),
                listed ? "an id of [device] usb_ids: asked below" : "not a pantograph id");
  }
  std::printf("Serial devices (/dev/serial/by-id):\n");
  const std::vector<std::string> ttys = io::list_serial_by_id();
  if (ttys.empty()) std::printf("  none\n");
  for (const std::string& t : ttys) std::printf("  %s\n", t.c_str());
  // Each way to a board asked on its own: reset, setup, zero-torque packets, a well-formed reply in time.
  std::printf("Boards ([device] transport = \"%s\"; each asked for an hAPI reply):\n", s.device.transport.c_str());
  const std::vector<io::BoardCandidate> candidates = board_candidates(s);
  if (candidates.empty()) std::printf("  none to ask\n");
  for (const io::BoardCandidate& c : candidates) {
    std::vector<io::BoardProbe> probe;
    if (std::unique_ptr<io::HaplyDevice> board = io::open_first_board(haply_params_from(s), {c}, &probe))
      board->close();
    for (const io::BoardProbe& p : probe)
      std::printf("  %s  %s: %s\n", p.name.c_str(), p.answered ? "answered" : "refused", p.how.c_str());
  }
  return 0;
}

int run_calibrate(const CalibrateOptions& o) {
  config::Settings s = config::load_settings(o.config_path);
  const io::HaplyDeviceParams dp = haply_params_from(s);
  const Vec2 park{s.device.park_x_m, s.device.park_y_m};
  std::unique_ptr<hapi::FirmwareEmulator> emulator;
  std::unique_ptr<hapi::PtyEmulator> pty;
  io::TransportFactory factory;
  std::unique_ptr<io::HaplyDevice> board;
  if (o.device == "haply") {
    board = open_board(s, nullptr);
  } else {
    const DeviceChoice choice = parse_device_choice(o.device);
    if (choice.kind != DeviceChoice::Kind::HaplyEmulator)
      throw DeviceChoiceError("--device '" + o.device + "': calibrate needs 'haply' or 'haply-emulator[:...]'");
    // The emulated handle rests at the park place, untouched.
    Vec2 park_device;
    const hapi::EmulatorParams ep = emulator_resting_at_park(s, choice, &park_device);
    emulator = std::make_unique<hapi::FirmwareEmulator>(ep, park_device, [](double, Vec2, Vec2) {
      return Vec2{0.0, 0.0};
    });
    pty = std::make_unique<hapi::PtyEmulator>(*emulator);
    const std::string path = pty->device_path();
    factory = [path] { return std::make_unique<io::TtyTransport>(path); };
  }
  if (!board) {
    board = std::make_unique<io::HaplyDevice>(dp, factory);
    board->open();
  }
  io::HaplyDevice& device = *board;
  double sum1 = 0, sum2 = 0;
  constexpr int kTicks = 50;
  for (int k = 0; k < kTicks; ++k) {
    device.write_force({0.0, 0.0});
    device.wait_reply(20000);
    const DeviceSample smp = device.read();
    if (smp.status != DeviceStatus::Ok) throw DeviceError(device.name() + ": stopped answering during calibration");
    double a1 = 0, a2 = 0;
    device.joint_angles_deg(&a1, &a2);
    sum1 += a1;
    sum2 += a2;
  }
  device.close();
  if (pty) pty->stop();
  double o1 = 0, o2 = 0;
  if (!io::calibrated_offsets(dp, park, sum1 / kTicks, sum2 / kTicks, &o1, &o2))
    throw AppError("calibrate: the park place (" + std::to_string(park.x) + ", " + std::to_string(park.y) +
                   ") m is out of the links' reach; check [device] park_x_m, park_y_m and the rectangle");
  const double old1 = s.device.encoder1_offset_deg, old2 = s.device.encoder2_offset_deg;
  s.device.encoder1_offset_deg = std::round(o1 * 1000.0) / 1000.0;
  s.device.encoder2_offset_deg = std::round(o2 * 1000.0) / 1000.0;
  config::save_settings_atomic(s, o.config_path);
  std::printf("calibrate: encoder 1 offset %.3f -> %.3f deg, encoder 2 offset %.3f -> %.3f deg; written to %s\n", old1,
              s.device.encoder1_offset_deg, old2, s.device.encoder2_offset_deg, o.config_path.c_str());
  return 0;
}

}  // namespace hk::app
