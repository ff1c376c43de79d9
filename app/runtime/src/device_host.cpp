// The kiosk's device and servo thread (device_host.hpp).
#include "runtime/device_host.hpp"

#include "runtime/event_log.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <vector>

#include "config/device_profile.hpp"
#include "haptics/io/tty_transport.hpp"
#include "runtime/device_setup.hpp"
#include "runtime/runtime_params.hpp"

namespace hk::app {

DeviceHost::DeviceHost(const config::Settings& s)
    : s_(s), sim_(sim_params_from(s), {0.0, -0.9 * s.workspace.height_m / 2}) {
  sim_.open();
  set_settings(s);
  target_.back() = sim_.true_position_m();
  target_.publish();
}

DeviceHost::~DeviceHost() {
  stop_servo();
  usb_watch_.reset();
  if (usb_) usb_->close();  // zero torque, then the transport closes
  if (board_pty_) board_pty_->stop();
}

void DeviceHost::set_settings(const config::Settings& s) {
  s_ = s;
  hand_ = hand_params_from(s);
  hand_.max_force_n = std::max(hand_.max_force_n, 1.5 * s.haptics.pop_force_n);
}

void DeviceHost::open_emulated_board(const std::string& text) {
  const DeviceChoice choice = parse_device_choice(text);
  if (choice.kind != DeviceChoice::Kind::HaplyEmulator)
    throw DeviceChoiceError("--device '" + text +
                            "': the kiosk takes 'haply-emulator[:FAULT=VALUE,...]' (or nothing: [device])");
  const io::HaplyDeviceParams dp = haply_params_from(s_);
  const double scale = io::workspace_scale(dp);
  const Vec2 centre = dp.rect_center_device_m;
  // The board's handle follows the cursor through the model hand (workspace frame ↔ device frame).
  Vec2 start_device = (1.0 / scale) * target_.read() + centre;
  const hapi::EmulatorParams ep =
      choice.rest_at_park ? emulator_resting_at_park(s_, choice, &start_device) : emulator_params_from(s_, choice);
  board_ = std::make_unique<hapi::FirmwareEmulator>(
      ep, start_device, [this, scale, centre](double, Vec2 handle_device_m, Vec2 velocity_device_m_per_s) {
        const Vec2 handle = scale * (handle_device_m - centre);
        const Vec2 target = limp() ? handle : target_.read();
        return model_hand_force(hand_, target, handle, scale * velocity_device_m_per_s);
      });
  board_pty_ = std::make_unique<hapi::PtyEmulator>(*board_);
  const std::string path = board_pty_->device_path();
  usb_ = std::make_unique<io::HaplyDevice>(dp, [path] { return std::make_unique<io::TtyTransport>(path); });
  usb_->open();
  spdlog::info("device: {} on the firmware emulator", usb_->name());
  if (choice.rest_at_park) check_home(true);  // a board at rest, as a real one waits for the kiosk to start
}

bool DeviceHost::try_open_usb() {
  try {
    std::unique_ptr<io::HaplyDevice> dev = open_board(s_, nullptr);
    log_event(
        KioskEvent::device_connected, spdlog::level::info,
        fmt::format("device: {} ({} profile: {:.2f} N everywhere)", dev->name(),
                    config::device_profile(board_profile_type(s_)).name, io::min_force_capability_n(dev->params())));
    usb_ = std::move(dev);
    note_.clear();
    return true;
  } catch (const std::exception& e) {
    // Said once per reason: a kiosk without its handle probes every 10 s for months, and the journal
    // should not fill with the same line (the boot of the package showed 360 an hour).
    const bool news = note_ != e.what();
    note_ = e.what();
    spdlog::log(news ? spdlog::level::warn : spdlog::level::debug,
                "device: no USB pantograph ({}); the simulated pantograph stands in", e.what());
    return false;
  }
}

void DeviceHost::watch_hotplug() {
  try {
    // Any product of the first id's vendor (Arduino's, for every Haply board): an arrival only starts a probe,
    // and the probe takes the ids of [device] usb_ids alone.
    const std::vector<config::UsbId> ids = config::parse_usb_ids(s_.device.usb_ids);
    if (!ids.empty())
      usb_watch_ = std::make_unique<io::UsbHotplugMonitor>(ids.front().vid, -1, [this](bool arrived) {
        if (arrived) usb_arrived_.store(true);
      });
  } catch (const std::exception& e) {
    spdlog::warn("device: no USB hot-plug ({}); the kiosk probes for the handle every 10 s", e.what());
  }
}

void DeviceHost::check_home(bool at_start) {
  const HomeCheck c = check_home_pose(*usb_, s_);
  home_note_ = c.at_home ? std::string{} : home_check_line(c);
  home_unspoken_ = at_start && !c.at_home;
  if (!c.at_home) spdlog::warn("device: {}", home_note_);
}

bool DeviceHost::take_home_unspoken() {
  const bool unspoken = home_unspoken_;
  home_unspoken_ = false;
  return unspoken;
}

void DeviceHost::start_servo(ServoStep& step) {
  stop_servo();
  servo_.reset();
  ServoThreadParams tp;
  tp.rate_hz = s_.haptics.servo_rate_hz;
  if (usb_) {
    servo_ = std::make_unique<ServoThread>(step, *usb_, tp);
    return;
  }
  servo_ = std::make_unique<ServoThread>(step, sim_, tp, [this](double dt) {
    // The simulated pantograph: the model hand pulls the handle towards the target (limp during a tour:
    // it follows the handle, giving only its damping).
    const Vec2 target = limp() ? sim_.true_position_m() : target_.read();
    sim_.step(dt, model_hand_force(hand_, target, sim_.true_position_m(), sim_.velocity_m_per_s()));
  });
}

void DeviceHost::stop_servo() {
  if (servo_) servo_->stop();
}

DeviceNews DeviceHost::poll(double now_s, DeviceStatus st, bool allowed) {
  // A loss is told once it has lasted kLostSpeech_s (a board that misses a few replies and comes back
  // within it is not worth interrupting the visitor for: the force was off for those ticks and ramped
  // back in), and the return only after a loss that was told.
  constexpr double kLostSpeech_s = 0.5;
  DeviceNews news = DeviceNews::None;
  if (usb_) {
    if (st != DeviceStatus::Ok && last_status_ == DeviceStatus::Ok) lost_since_s_ = now_s;
    if (st != DeviceStatus::Ok && !lost_spoken_ && now_s - lost_since_s_ >= kLostSpeech_s) {
      log_event(KioskEvent::device_lost, spdlog::level::warn, "device: " + usb_->name() + " lost");
      lost_spoken_ = true;
      news = DeviceNews::Lost;
    } else if (st == DeviceStatus::Ok && lost_spoken_) {
      log_event(KioskEvent::device_connected, spdlog::level::info, "device: " + usb_->name() + " back");
      lost_spoken_ = false;
      news = DeviceNews::Back;
    }
  }
  last_status_ = st;
  // The simulated pantograph stands in: take a USB pantograph that arrives.
  if (usb_ || !allowed) return news;
  const bool arrived = usb_arrived_.exchange(false);
  if (!arrived && now_s < next_probe_s_) return news;
  next_probe_s_ = now_s + 10.0;
  if (!try_open_usb()) return news;
  last_status_ = DeviceStatus::Ok;
  return DeviceNews::Arrived;
}

bool DeviceHost::calibrate(double* offset1_deg, double* offset2_deg, std::string* why) {
  if (!usb_) {
    *why = "no USB pantograph is in use" + (note_.empty() ? std::string{} : " (" + note_ + ")");
    return false;
  }
  if (usb_->status() != DeviceStatus::Ok) {
    *why = "the handle does not answer";
    return false;
  }
  if (!usb_->calibrate({s_.device.park_x_m, s_.device.park_y_m}, offset1_deg, offset2_deg)) {
    *why = "the park place is out of the links' reach";
    return false;
  }
  home_note_.clear();  // the handle rests at home, and now reads there
  return true;
}

void DeviceHost::set_target(Vec2 target_m) {
  target_.back() = target_m;
  target_.publish();
}

}  // namespace hk::app
