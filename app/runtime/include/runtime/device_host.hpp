#pragma once
/// @file device_host.hpp
/// The device the kiosk's servo thread drives, and that thread: the USB pantograph when one answers
/// ([device] type "auto" or "haply"), the Haply board's firmware emulator behind a pty (the kiosk's
/// `--device haply-emulator[:...]`), else the simulated pantograph. Without a visitor's hand on a real
/// handle, the model hand pulls the handle towards the cursor (limp while a guided tour leads it: it
/// follows the handle, giving only its damping). It opens and probes boards, watches USB hot-plug, checks a
/// board's home pose, calibrates it, and turns the servo's device status into news for its owner to say
/// (poll: a loss that lasted 0.5 s, the return after it, a board that arrived).
///
/// Threads: construct, call and destroy on one thread (the window thread). The servo thread's after-tick
/// (the simulated pantograph's physics) and the emulator's hand read the cursor through a triple buffer and
/// the limp switch through an atomic; nothing else is shared.

#include <atomic>
#include <memory>
#include <string>

#include "config/settings.hpp"
#include "haptics/hand_path.hpp"
#include "haptics/hapi_emulator.hpp"
#include "haptics/io/haply_device.hpp"
#include "haptics/io/usb_devices.hpp"
#include "haptics/pty_emulator.hpp"
#include "haptics/sim_pantograph.hpp"
#include "haptics/triple_buffer.hpp"
#include "runtime/servo_step.hpp"
#include "runtime/servo_thread.hpp"

namespace hk::app {

/// What DeviceHost::poll saw this frame.
enum class DeviceNews {
  None,     ///< nothing to tell
  Lost,     ///< the USB pantograph has not answered for 0.5 s (said once a loss)
  Back,     ///< it answers again after a loss that was said
  Arrived,  ///< a USB pantograph was found while the simulated one stood in; it is open now
};

/// The kiosk's device and servo thread. Not thread-safe: one thread (see the file comment).
class DeviceHost {
 public:
  /// The simulated pantograph, open, its handle near the visitor's edge of the workspace of `s`; no board
  /// yet (open_emulated_board, try_open_usb).
  explicit DeviceHost(const config::Settings& s);
  /// Stops the servo thread, then zero torque and the transport closed, then the emulator's pty.
  ~DeviceHost();
  DeviceHost(const DeviceHost&) = delete;
  DeviceHost& operator=(const DeviceHost&) = delete;

  /// The settings the board is opened, checked and calibrated with, and the model hand's from them (its
  /// force raised to 1.5 × [haptics] pop_force_n: a cursor held well past a wall pushes through it, as a
  /// visitor at the real handle would). The owner calls it when it adopts a board's profile, before the
  /// servo thread starts on that board; the operator's Apply changes none of what is used here ([device],
  /// [hand], [workspace] and the servo rate take effect at the next start).
  void set_settings(const config::Settings& s);
  /// The firmware emulator behind a pty, driven through the USB pantograph's driver, its handle pulled by
  /// the model hand. `choice` as parse_device_choice takes it ("haply-emulator[:FAULT=V,...]"); a board set
  /// to rest at the park place is checked at once (check_home(true)).
  /// @throws DeviceChoiceError for any other choice.
  void open_emulated_board(const std::string& choice);
  /// The USB pantograph of [device] (open_board); false when none answers (note() says why; logged once a
  /// reason, the kiosk probes every 10 s for months).
  bool try_open_usb();
  /// Watches USB hot-plug for the first of [device] usb_ids' vendor (an arrival starts a probe in poll()).
  /// Without hot-plug (a container), logs why: poll() probes every 10 s anyway.
  void watch_hotplug();
  /// check_home_pose on the board in use: home_note() says how to fix a handle that did not start at home;
  /// `at_start`: take_home_unspoken() will say it once (the staff hear it at start, no visitor later).
  void check_home(bool at_start);

  /// Starts the servo thread at [haptics] servo_rate_hz on the device in use (the simulated pantograph's
  /// plant stepped after each tick). @throws hk::ArgumentError for a bad rate.
  void start_servo(ServoStep& step);
  /// Stops the servo thread (idempotent).
  void stop_servo();
  /// Null before start_servo().
  ServoThread* servo() { return servo_.get(); }

  /// Window thread, every frame (`now_s` the frame clock [s]; `status` the servo's device status of the
  /// display state): a loss of the USB pantograph said after 0.5 s, its return after a loss that was said;
  /// while the simulated pantograph stands in (and probing is `allowed`), a probe at a hot-plug arrival or
  /// every 10 s. On Arrived the new board is open but the servo thread still drives the old device: the
  /// owner adopts the board's profile and restarts the servo (start_servo).
  DeviceNews poll(double now_s, DeviceStatus status, bool allowed);

  /// The device the servo thread drives.
  Device& device() { return usb_ ? static_cast<Device&>(*usb_) : static_cast<Device&>(sim_); }
  /// The USB pantograph (or the emulated board) in use, or null when the simulated pantograph is.
  io::HaplyDevice* usb() { return usb_.get(); }
  const io::HaplyDevice* usb() const { return usb_.get(); }
  /// The operator's Calibrate: with the handle resting at the park place, the encoder offsets that make it
  /// read right, applied to the running board at once. False with `why` when no USB pantograph is in use,
  /// it does not answer, or the park place is out of the links' reach.
  bool calibrate(double* offset1_deg, double* offset2_deg, std::string* why);
  /// Why the simulated pantograph is in use (empty when a USB pantograph is, or none was looked for).
  const std::string& note() const { return note_; }
  /// Empty, or the one line saying that the board's handle did not start at its home pose and how to fix it.
  const std::string& home_note() const { return home_note_; }
  /// Whether check_home(true) found the handle away from home and that has not been said yet; clears it.
  bool take_home_unspoken();

  /// Where the model hand pulls the handle [m] (the mouse or a script stands in for the visitor's hand).
  void set_target(Vec2 target_m);
  /// The model hand goes limp (follows the handle) while a guided tour leads it.
  void set_limp(bool limp) { hand_limp_.store(limp, std::memory_order_relaxed); }
  bool limp() const { return hand_limp_.load(std::memory_order_relaxed); }
  /// The simulated pantograph's handle [m] (where the cursor's hand starts).
  Vec2 simulated_handle_m() const { return sim_.true_position_m(); }

 private:
  config::Settings s_;
  ModelHandParams hand_;
  SimulatedPantograph sim_;                        // stands in when there is no USB pantograph
  std::unique_ptr<hapi::FirmwareEmulator> board_;  // the emulated board...
  std::unique_ptr<hapi::PtyEmulator> board_pty_;   // ...behind its pty
  std::unique_ptr<io::HaplyDevice> usb_;           // the USB pantograph, when one answered
  std::unique_ptr<io::UsbHotplugMonitor> usb_watch_;
  std::atomic<bool> usb_arrived_{false};
  double next_probe_s_ = 10.0;  // poll's clock [s]
  std::string note_;
  std::string home_note_;
  bool home_unspoken_ = false;
  DeviceStatus last_status_ = DeviceStatus::Ok;
  double lost_since_s_ = 0.0;  // when the device stopped answering [s, poll's clock]
  bool lost_spoken_ = false;   // the loss was told (the return will be)
  TripleBuffer<Vec2> target_;  // the model hand's target, read on the servo thread
  std::atomic<bool> hand_limp_{false};
  std::unique_ptr<ServoThread> servo_;  // last: stops first
};

}  // namespace hk::app
