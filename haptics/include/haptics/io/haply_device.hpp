#pragma once
/// @file haply_device.hpp
/// The USB pantograph (DESIGN.md "Devices"): a Haply 2DIY (gen3) board speaking hAPI
/// (hapi_protocol.hpp) over a byte stream (byte_transport.hpp: libusb CDC-ACM, the kernel's tty, or a pty
/// to the firmware emulator), seen through the `Device` interface.
///
/// Per servo tick: `read()` takes the reply to the torque packet sent before, if it has come (it never
/// waits: a headless run that must not depend on the machine's speed calls `wait_reply` first, outside the
/// servo step), decodes the encoder angles, and maps them to the handle position:
/// Haply joint angles → our joint angles (haply_mechanism.hpp) → five-bar forward kinematics
/// (pantograph.hpp) in the device frame → the workspace frame, by the uniform scale and shift that map the
/// device's usable rectangle onto the kiosk's (`workspace_scale`). `write_force(F)` sends one torque
/// packet: τ = Jᵀ·F at the last decoded pose (the force in newtons is the same in both frames: what the
/// visitor feels is what the solver asked for; the stiffness felt per device metre is k·scale), each τ
/// clamped to the board's torque limit, zero for a non-finite force.
///
/// The servo step never waits on the board: while it answers, at most one packet is outstanding. While the
/// reply to the last packet has not come (for fewer than kReplyWaitTicks ticks), or the transport has not
/// taken all of the last packet (it is finished first, without waiting), `write_force` sends nothing and
/// counts a skipped write; a reply one tick late is taken on the next tick. A board counted Lost gets a
/// zero-torque packet every tick the transport takes one. Every transport call in read and write_force
/// has a timeout of 0.
///
/// A reply missing or malformed (wrong id, non-finite or absurd angle, a jump of more than
/// `max_step_deg` since the last good one, bytes out of step) for `lost_after_ticks` ticks in a row makes
/// the status Lost: from that tick on the torques sent are zero (and the servo's force guard sends zero
/// force). Zero-torque packets keep going out, so a board that only stalled answers again: status Ok,
/// `reconnects` counted, and the servo ramps the force back in. A transport that is gone (unplugged) is
/// re-opened in the background every `reopen_interval_s` by a helper thread through the factory; the new
/// transport reaches the servo thread through one atomic exchange.
///
/// Real-time contract (device.hpp): read, write_force, status and counters do not allocate, lock or throw;
/// their only system calls are the transport's read/write with a timeout of 0. open/close may throw DeviceError.
///
/// The board's encoder counters start at the offsets sent in the setup packet (firmware
/// Haply_M0_Firmware_V0_3 `initialize_encoder`), so positions are right when the handle rests at the
/// calibration (park) pose whenever the board is set up; `calibrate_offsets` corrects the residual.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "haptics/device.hpp"
#include "haptics/hapi_protocol.hpp"
#include "haptics/io/byte_transport.hpp"
#include "kinematics/haply_mechanism.hpp"
#include "kinematics/pantograph.hpp"

namespace hk::io {

/// Settings of the USB pantograph. Units in names. Defaults: the gen3 2DIY (config [device] defaults).
struct HaplyDeviceParams {
  hapi::BoardLayout layout = hapi::BoardLayout::haply_gen3();  ///< ports, directions, offsets, device id
  hapi::HaplyMechanism mechanism;                              ///< link lengths and motor spacing [m]
  double torque_limit_n_m = 0.123;         ///< |τ| clamp per motor [N·m] (the firmware's MAX_TORQUE)
  Vec2 rect_center_device_m{0.0, -0.088};  ///< centre of the device's usable rectangle, device frame [m]
  Vec2 rect_size_device_m{0.112, 0.072};   ///< its width and height [m]
  Vec2 workspace_size_m{0.14, 0.09};       ///< the kiosk's usable rectangle ([workspace]) it maps onto [m]
  int lost_after_ticks = 3;                ///< ticks without a valid reply before Lost, ≥ 1
  int open_timeout_ms = 1000;              ///< open() waits this long for the first reply [ms]
  double reopen_interval_s = 0.5;          ///< a gone transport is re-opened this often [s]
  double max_step_deg = 20.0;  ///< a reply whose angle moved more than this since the last good one is refused [deg]
};

/// Makes a new, not yet opened transport to the board (called at open and by the re-open thread).
using TransportFactory = std::function<std::unique_ptr<ByteTransport>()>;

/// Counters of a device's life, readable from any thread.
struct HaplyCounters {
  std::int64_t ticks = 0;            ///< torque packets sent
  std::int64_t replies = 0;          ///< valid replies taken
  std::int64_t replies_missing = 0;  ///< ticks whose reply did not come (or came malformed)
  std::int64_t malformed = 0;        ///< replies refused (wrong id, bad angle, out of step): bytes dropped
  std::int64_t reconnects = 0;       ///< times the status went from Lost back to Ok
  std::int64_t reopens = 0;          ///< transports re-opened in the background
  std::int64_t writes_skipped =
      0;  ///< ticks whose packet was not sent: the last one's reply not yet in, or the transport full
};

/// Ticks a packet's reply is waited for before the next packet goes out anyway (the reply is then missing).
inline constexpr int kReplyWaitTicks = 2;

/// The uniform scale from device metres to workspace metres: min(workspace w / rect w, workspace h / rect h).
double workspace_scale(const HaplyDeviceParams& p) noexcept;

/// Encoder offsets that make the angles read right (calibration): the handle rests at
/// `park_workspace_m` (a known place, config [device] park_x_m/park_y_m) and the board reported
/// `reported_th1_deg`/`reported_th2_deg` with the offsets of `p.layout`; each new offset is the old one plus
/// (the joint angle the park place has, by inverse kinematics, − the angle reported), the difference
/// wrapped into (−180°, 180°]. Returns false (outputs untouched) when the park place is out of the links'
/// reach or an input is not finite.
bool calibrated_offsets(const HaplyDeviceParams& p, Vec2 park_workspace_m, double reported_th1_deg,
                        double reported_th2_deg, double* offset1_deg, double* offset2_deg) noexcept;

/// The force the pantograph can give in every direction everywhere in its usable rectangle [N]: at each
/// point of a 21 × 21 grid over the rectangle and each of 72 directions u, the largest f with
/// |(Jᵀ·f·u)_i| ≤ torque_limit for both motors; the minimum over all. 0 when some grid point is out of reach.
/// Above it, walls saturate somewhere: an operator's max_force_n over this cannot be felt everywhere.
double min_force_capability_n(const HaplyDeviceParams& p) noexcept;

class HaplyDevice;

/// One way to reach a board (a USB id, a tty), tried by open_first_board.
struct BoardCandidate {
  std::string name;          ///< for people and logs: "usb 2341:804d", "tty /dev/serial/by-id/..."
  TransportFactory factory;  ///< makes the transport (the device re-opens through it after an unplug)
};

/// What trying one candidate found.
struct BoardProbe {
  std::string name;       ///< the candidate's name
  bool answered = false;  ///< its board answered the protocol and was taken
  std::string how;        ///< answered: "hAPI reply from device id 5 after 12 ms"; else why not (one line)
};

/// Opens the first candidate whose board answers the protocol — reset, setup, zero-torque packets until a
/// well-formed reply (HaplyDevice::open, within open_timeout_ms) — and returns it open; a later reply, a
/// tick or more behind, is taken as it comes. One BoardProbe per candidate tried is appended to `probes`
/// (may be null). Null when none answered; the probes say why (missing, busy, no permission, garbage, silence).
std::unique_ptr<HaplyDevice> open_first_board(const HaplyDeviceParams& params,
                                              const std::vector<BoardCandidate>& candidates,
                                              std::vector<BoardProbe>* probes);

/// The hAPI pantograph as a `Device`.
class HaplyDevice final : public Device {
 public:
  /// Checks the parameters (hapi::validate, finite positive sizes, lost_after_ticks ≥ 1); throws
  /// DeviceError (one line) when they are wrong. Opens nothing yet.
  HaplyDevice(const HaplyDeviceParams& params, TransportFactory factory);
  /// Stops the re-open thread and closes (zero torque first).
  ~HaplyDevice() override;
  HaplyDevice(const HaplyDevice&) = delete;
  HaplyDevice& operator=(const HaplyDevice&) = delete;

  /// Opens a transport through the factory, sends reset and setup, then zero-torque packets until the
  /// first valid reply (at most open_timeout_ms): status Ok. Starts the re-open thread. Throws DeviceError
  /// naming the transport when it cannot be opened or the board does not answer: silent, or answering only
  /// bytes that are no hAPI reply (another device on the port).
  void open() override;
  /// Real-time, never waits. The handle from the newest valid reply (the last good one when none came), and
  /// the status.
  DeviceSample read() noexcept override;
  /// Real-time, never waits. One torque packet: τ = Jᵀ·F clamped to the torque limit; zero unless the status
  /// is Ok. Skipped (and counted) while the last packet's reply is not in or the last packet not all written.
  void write_force(Vec2 force_n) noexcept override;
  /// Not for the servo step: waits up to `timeout_us` [µs] for the reply to the outstanding packet and keeps
  /// it for the next read(). True when it came (or nothing is outstanding). Headless runs call it before
  /// read() so that they do not depend on how busy the machine is; the kiosk never does.
  bool wait_reply(int timeout_us) noexcept;
  /// Sends zero torque (when it can), stops the re-open thread, closes the transport. Never throws.
  void close() noexcept override;
  /// Closed, Ok or Lost. Real-time.
  DeviceStatus status() const noexcept override { return status_.load(std::memory_order_acquire); }
  /// "Haply pantograph (<transport name>)".
  std::string name() const override;

  /// Counters so far. Any thread.
  HaplyCounters counters() const noexcept;
  /// New encoder offsets [deg] for the running board (the operator panel's Calibrate): the difference to the
  /// offsets the board was set up with is added to every angle read from now on (the board keeps counting
  /// from its setup; a board set up again later gets the same correction). Any thread; a correction of
  /// more than max_step_deg may cost a few refused replies.
  void apply_offsets(double offset1_deg, double offset2_deg) noexcept;
  /// Calibrates the running board with the handle resting at `park_workspace_m`: calibrated_offsets from the
  /// angles last read (as the board reports them, before any correction) and the offsets it was set up
  /// with, then apply_offsets. False (nothing changed) when no reply was read yet or the park place is out
  /// of reach. Any thread.
  bool calibrate(Vec2 park_workspace_m, double* offset1_deg, double* offset2_deg) noexcept;
  /// Haply joint angles of the newest valid reply [deg] (joint 1, joint 2), corrected. Any thread (relaxed reads).
  void joint_angles_deg(double* th1_deg, double* th2_deg) const noexcept;
  /// The torques of the last packet, per actuator index (1, 2) [N·m]. Any thread.
  void last_torques_n_m(double* tau1, double* tau2) const noexcept;
  /// Handle position in the device frame [m] for Haply joint angles [deg]; false when the links cannot meet.
  bool device_position(double th1_deg, double th2_deg, Vec2* device_m) const noexcept;
  /// Device frame [m] → workspace frame [m], and back.
  Vec2 to_workspace(Vec2 device_m) const noexcept;
  Vec2 to_device(Vec2 workspace_m) const noexcept;
  const HaplyDeviceParams& params() const noexcept { return params_; }

 private:
  void send_setup(ByteTransport& t);
  bool take_replies(int wait_us) noexcept;  // true when a valid reply was taken
  bool flush_tx() noexcept;                 // writes what is left of the last packet; true when all of it is out
  void adopt_pending() noexcept;
  void reopen_loop();

  HaplyDeviceParams params_;
  TransportFactory factory_;
  PantographGeometry geometry_;
  double scale_ = 1.0;                            // device → workspace [m/m]
  std::unique_ptr<ByteTransport> transport_;      // servo thread's (after open)
  std::atomic<ByteTransport*> pending_{nullptr};  // re-open thread → servo thread
  std::atomic<ByteTransport*> retired_{nullptr};  // servo thread → re-open thread (to close and free)
  std::atomic<bool> gone_{false};                 // the transport in use reported kGone
  std::atomic<DeviceStatus> status_{DeviceStatus::Closed};
  std::uint8_t rx_[256] = {};
  int rx_len_ = 0;
  bool outstanding_ = false;                     // a torque packet waits for its reply
  int outstanding_age_ = 0;                      // reads since it was sent without its reply
  bool fresh_ = false;                           // a valid reply was taken since the last read()
  std::uint8_t tx_[hapi::kMaxPacketBytes] = {};  // the last packet
  int tx_len_ = 0, tx_at_ = 0;                   // its length and how much of it the transport took
  int missing_in_row_ = 0;
  bool have_angles_ = false;
  std::atomic<double> th1_deg_{0.0}, th2_deg_{0.0};
  std::atomic<double> tau1_{0.0}, tau2_{0.0};
  std::atomic<double> correction1_deg_{0.0}, correction2_deg_{0.0};  // apply_offsets − the layout's offsets
  JointAngles q_;                                                    // our joint angles of the newest valid reply
  Vec2 handle_ws_m_;                                                 // its handle, workspace frame
  std::int64_t t0_ns_ = 0;
  std::atomic<std::int64_t> ticks_{0}, replies_{0}, missing_{0}, malformed_{0}, reconnects_{0}, reopens_{0},
      skipped_{0};
  std::mutex reopen_mutex_;
  std::condition_variable reopen_cv_;
  bool stop_reopen_ = false;
  std::thread reopen_thread_;
};

}  // namespace hk::io
