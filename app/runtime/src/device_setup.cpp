#include "runtime/device_setup.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "config/device_profile.hpp"
#include "haptics/io/tty_transport.hpp"
#include "haptics/io/usb_devices.hpp"
#include "haptics/io/usb_transport.hpp"
#include "runtime/runtime_params.hpp"

namespace hk::app {
namespace {

double number_of(const std::string& key, const std::string& value, double lo, double hi, bool integer) {
  double v = 0.0;
  const char* first = value.data();
  const char* last = value.data() + value.size();
  auto [p, ec] = std::from_chars(first, last, v);
  const bool ok =
      ec == std::errc{} && p == last && std::isfinite(v) && v >= lo && v <= hi && (!integer || v == std::floor(v));
  if (!ok) {
    char range[96];
    std::snprintf(range, sizeof range, "%s in [%g, %g]", integer ? "an integer" : "a number", lo, hi);
    throw DeviceChoiceError("--device haply-emulator: " + key + "=" + value + " must be " + range);
  }
  return v;
}

}  // namespace

DeviceChoice parse_device_choice(const std::string& text) {
  DeviceChoice c;
  if (text == "sim" || text == "simulated") return c;
  const std::string kEmu = "haply-emulator";
  if (text.rfind(kEmu, 0) != 0 || (text.size() > kEmu.size() && text[kEmu.size()] != ':'))
    throw DeviceChoiceError("--device '" + text + "': must be 'sim' or 'haply-emulator[:FAULT=VALUE,...]'");
  c.kind = DeviceChoice::Kind::HaplyEmulator;
  std::string rest = text.size() > kEmu.size() ? text.substr(kEmu.size() + 1) : std::string{};
  std::size_t at = 0;
  while (at < rest.size()) {
    std::size_t comma = rest.find(',', at);
    if (comma == std::string::npos) comma = rest.size();
    const std::string item = rest.substr(at, comma - at);
    at = comma + 1;
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw DeviceChoiceError("--device haply-emulator: '" + item + "' must be KEY=VALUE");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    constexpr double kDay = 86400.0, kMaxEvery = 1e6;
    if (key == "disconnect_at_s")
      c.faults.disconnect_at_s = number_of(key, value, 0, kDay, false);
    else if (key == "stall_at_s")
      c.faults.stall_at_s = number_of(key, value, 0, kDay, false);
    else if (key == "stall_s")
      c.faults.stall_s = number_of(key, value, 0, 60, false);
    else if (key == "drop_every")
      c.faults.drop_every = static_cast<int>(number_of(key, value, 0, kMaxEvery, true));
    else if (key == "garbage_every")
      c.faults.garbage_every = static_cast<int>(number_of(key, value, 0, kMaxEvery, true));
    else if (key == "wrong_id_every")
      c.faults.wrong_id_every = static_cast<int>(number_of(key, value, 0, kMaxEvery, true));
    else if (key == "seed")
      c.faults.seed = static_cast<std::uint64_t>(number_of(key, value, 0, 9007199254740992.0, true));
    else if (key == "calib_error1_deg")
      c.calibration_error_deg[0] = number_of(key, value, -90, 90, false);
    else if (key == "calib_error2_deg")
      c.calibration_error_deg[1] = number_of(key, value, -90, 90, false);
    else if (key == "rest_at_park")
      c.rest_at_park = number_of(key, value, 0, 1, true) == 1.0;
    else
      throw DeviceChoiceError(
          "--device haply-emulator: unknown fault '" + key +
          "'; known: disconnect_at_s, drop_every, garbage_every, wrong_id_every, stall_at_s, stall_s, seed, "
          "calib_error1_deg, calib_error2_deg, rest_at_park");
  }
  return c;
}

hapi::EmulatorParams emulator_resting_at_park(const config::Settings& s, const DeviceChoice& choice,
                                              Vec2* start_device_m) {
  const io::HaplyDeviceParams dp = haply_params_from(s);
  hapi::EmulatorParams ep = emulator_params_from(s, choice);
  *start_device_m =
      (1.0 / io::workspace_scale(dp)) * Vec2{s.device.park_x_m, s.device.park_y_m} + dp.rect_center_device_m;
  ep.workspace_center_m = *start_device_m;
  ep.workspace_half_extent_m = {0.0005, 0.0005};
  ep.stop_margin_m = 0.0;
  return ep;
}

HomeCheck check_home_pose(const io::HaplyDevice& device, const config::Settings& s) {
  HomeCheck c;
  c.park_m = {s.device.park_x_m, s.device.park_y_m};
  if (device.counters().replies == 0) return c;
  double th1 = 0, th2 = 0;
  device.joint_angles_deg(&th1, &th2);
  Vec2 at_device;
  if (!device.device_position(th1, th2, &at_device)) return c;
  c.read_m = device.to_workspace(at_device);
  c.off_m = distance(c.read_m, c.park_m);
  c.at_home = c.off_m <= kHomeTolerance_m;
  return c;
}

std::string home_check_line(const HomeCheck& c) {
  char b[320];
  std::snprintf(b, sizeof b,
                "the handle reads (%.1f, %.1f) mm at start, %.1f mm from its home pose at the park place (%.1f, %.1f) "
                "mm: positions read wrong "
                "until it is calibrated; rest the handle at home (both arms stretched out sideways) and press "
                "Calibrate in the operator's "
                "panel, or run 'haptic-kiosk calibrate'",
                1000 * c.read_m.x, 1000 * c.read_m.y, 1000 * c.off_m, 1000 * c.park_m.x, 1000 * c.park_m.y);
  return b;
}

std::vector<io::BoardCandidate> board_candidates(const config::Settings& s) {
  std::vector<io::BoardCandidate> out;
  const config::DeviceSettings& d = s.device;
  if (d.transport != "tty") {
    std::string reason;
    const std::vector<io::UsbDeviceInfo> bus = io::list_usb_devices(&reason);
    const bool listed = reason.empty();
    for (const config::UsbId& id : config::parse_usb_ids(d.usb_ids)) {
      const bool present = std::any_of(bus.begin(), bus.end(),
                                       [&](const io::UsbDeviceInfo& u) { return u.vid == id.vid && u.pid == id.pid; });
      if (listed && !present) continue;
      char name[32];
      std::snprintf(name, sizeof name, "usb %04x:%04x", id.vid, id.pid);
      out.push_back({name, [id] { return std::make_unique<io::UsbCdcTransport>(id.vid, id.pid); }});
    }
  }
  if (d.transport != "usb") {
    const std::vector<std::string> ttys =
        d.serial_path.empty() ? io::list_serial_by_id() : std::vector<std::string>{d.serial_path};
    for (const std::string& path : ttys)
      out.push_back({"tty " + path, [path] { return std::make_unique<io::TtyTransport>(path); }});
  }
  return out;
}

std::unique_ptr<io::HaplyDevice> open_board(const config::Settings& s, std::vector<io::BoardProbe>* probes) {
  const std::vector<io::BoardCandidate> candidates = board_candidates(s);
  if (candidates.empty())
    throw DeviceError(s.device.transport == "tty"
                          ? std::string("no serial device in /dev/serial/by-id (set [device] serial_path)")
                          : "no USB device with an id of [device] usb_ids" +
                                std::string(s.device.transport == "auto" ? " and no serial device" : ""));
  std::vector<io::BoardProbe> tried;
  std::unique_ptr<io::HaplyDevice> device = io::open_first_board(haply_params_from(s), candidates, &tried);
  if (probes) probes->insert(probes->end(), tried.begin(), tried.end());
  if (device) return device;
  std::string why = "no board answered";
  for (const io::BoardProbe& p : tried) why += (&p == &tried.front() ? ": " : "; ") + p.how;
  throw DeviceError(why);
}

std::string board_profile_type(const config::Settings& s) {
  return config::is_usb_type(s.device.type) ? s.device.type : std::string("haply");
}

config::Settings settings_for_board(const config::Settings& s, std::vector<std::string>* notes) {
  if (config::is_usb_type(s.device.type)) return s;
  return config::fit_to_profile(s, board_profile_type(s), notes);
}

const char* device_status_name(DeviceStatus status) noexcept {
  switch (status) {
    case DeviceStatus::Closed:
      return "closed";
    case DeviceStatus::Ok:
      return "ok";
    case DeviceStatus::Lost:
      return "lost";
    case DeviceStatus::Fault:
      return "fault";
  }
  return "unknown";
}

}  // namespace hk::app
