#pragma once
/// @file hapi_emulator.hpp
/// A byte-level emulator of the Haply M0 board running Haply_M0_Firmware_V0_3, attached to a simulated
/// Haply 2DIY gen3 five-bar. Tests and the pty emulator (pty_emulator.hpp) drive it with the exact bytes
/// a host sends (hapi_protocol.hpp) and read back the exact bytes the firmware would answer.
///
/// Firmware behaviour reproduced (source: HaplyHaptics/Haply-Arduino-Firmware-Versions,
/// Haply_M0_Firmware_V0_3/Haply_M0_Firmware_V0_3.ino `loop` and Haply_M0_Firmware_V0_3.h):
///  - two actuator/encoder ports (TOTAL_ACTUATOR_PORTS = 2): mask bits of ports 3 and 4 are ignored,
///    so their direction bytes and float pairs are not read and desync the stream, as on the board;
///  - setup first resets every assignment (`reset_device`), then stores motor and encoder direction
///    bytes BY COUNT INDEX (actuators[i] for i < count, `mtr_parameters`), not by port; a port keeps
///    the direction byte it last got (0 = CW at power-up);
///  - the encoder counter is loaded at setup with (int32)(offset·(res/2)/360) (float arithmetic,
///    truncation; the Encoder library counts at half rate, EncResolution = resolution/2) and read as
///    360·count/(res/2) [deg];
///  - a reply is sent only after a torque command (replyCode 1), never after reset or setup;
///  - a torque command reads one PWM byte per PWM pin assigned to its id and one float per actuator
///    port assigned to its id; when none matches, no float is read (the following bytes are parsed
///    as new commands) and the reply is `[id]` plus one float per sensor/encoder assigned to that id;
///  - torques: |τ| clamped to the limit and quantised to the 10-bit duty, duty = ⌊1023·|τ|/limit⌋;
///  - unknown command bytes are consumed and ignored; analog sensors read 0 (nothing is wired);
///  - ids: 0 is the reset value of every assignment. A torque command with id 0 on unassigned ports
///    would dereference a null encoder on the board; the emulator treats id 0 as matching nothing.
/// Not reproduced: the board's 50 µs loop pacing and the serial read timeouts (commands execute as soon
/// as all their bytes have arrived).
///
/// Physics: SimulatedPantograph (sim_pantograph.hpp) with our geometry of the mechanism
/// (haply_mechanism.hpp), torque limit = the firmware limit, and its stops around the device rectangle.
/// Each executed torque command advances the physics by one period.

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "haptics/hapi_protocol.hpp"
#include "haptics/sim_pantograph.hpp"
#include "hk/vec2.hpp"
#include "kinematics/haply_mechanism.hpp"
#include "kinematics/pantograph.hpp"

namespace hk::hapi {

/// Faults the emulator can inject into its replies. Reply numbers count the replies the firmware
/// produces (1-based), whether or not a fault then hides them.
struct EmulatorFaults {
  double disconnect_at_s = -1;  ///< from this emulated time on [s], no reply ever again, input ignored (< 0: never)
  int drop_every = 0;           ///< every Nth reply is not sent (0: never)
  int garbage_every = 0;        ///< before every Nth reply, 1..8 pseudo-random bytes are sent (0: never)
  int wrong_id_every = 0;       ///< every Nth reply carries id + 1 (0: never)
  double stall_at_s =
      -1;                ///< replies of commands ending in [stall_at_s, stall_at_s + stall_s) are withheld (< 0: never)
  double stall_s = 0.1;  ///< length of the stall [s]; the withheld replies go out with the first reply after it
  std::uint64_t seed = 1;  ///< seed of the garbage bytes (deterministic)
};

/// The emulated board, its wiring and the mechanism behind it. Defaults: a Haply 2DIY gen3.
struct EmulatorParams {
  HaplyMechanism mechanism;               ///< link lengths [m]
  double handle_mass_kg = 0.08;           ///< effective handle mass [kg], > 0
  double handle_damping_n_s_per_m = 2.0;  ///< viscous damping [N·s/m], ≥ 0
  double torque_limit_n_m = 0.123;        ///< firmware MAX_TORQUE [N·m], > 0
  double period_s = 0.001;                ///< physics time per torque command [s], > 0
  /// True wiring per PORT (element 0 = port 1): a host direction byte equal to it gives sign +1, else −1.
  Rotation wired_motor_dir[2] = {Rotation::CW, Rotation::CW};
  Rotation wired_encoder_dir[2] = {Rotation::CCW, Rotation::CCW};
  int port_joint[2] = {2, 1};  ///< Haply joint (1 = θ_h1, 2 = θ_h2) wired to port 1, port 2
  /// Haply angles of joint 1, 2 [deg] at the pose where the counters were zeroed:
  /// reported = offset_sent + sign·(θ_true − reference) + calibration_error (then quantised).
  double reference_deg[2] = {180, 0};
  double calibration_error_deg[2] = {0, 0};  ///< per Haply joint [deg]
  /// Usable rectangle of the device frame [m] (largest 14:9 rectangle with good conditioning, see
  /// hapi_emulator.cpp): 0.112 m × 0.072 m centred at (0, −0.088) m; stops 5 mm outside it.
  Vec2 workspace_half_extent_m{0.056, 0.036};
  Vec2 workspace_center_m{0.0, -0.088};
  double stop_margin_m = 0.005;
  EmulatorFaults faults;
};

/// The hand on the handle: force [N] in the device frame, given emulated time [s], the handle position
/// [m] and velocity [m/s], device frame. Called once per torque command. May be empty (no hand).
using HandForce = std::function<Vec2(double t_s, Vec2 handle_device_m, Vec2 velocity_device_m_per_s)>;

/// The emulated firmware. Single-threaded: guard it with a mutex when shared (PtyEmulator does).
class FirmwareEmulator {
 public:
  /// Builds the board at power-up (nothing assigned, all direction bytes 0) with the handle at rest at
  /// `start_handle_device_m` [m] (clamped into the stop box). Throws hk::ArgumentError (one line)
  /// when a parameter is out of range or not finite, or the stop box is not reachable.
  FirmwareEmulator(const EmulatorParams& params, Vec2 start_handle_device_m, HandForce hand);
  ~FirmwareEmulator();
  FirmwareEmulator(const FirmwareEmulator&) = delete;
  FirmwareEmulator& operator=(const FirmwareEmulator&) = delete;

  /// Host → board bytes (n ≥ 0). Every command completed by them is executed, in order; an incomplete
  /// tail waits for more bytes. Ignored once disconnected.
  void receive(const std::uint8_t* data, int n);
  /// Board → host bytes pending: copies up to `capacity` of them to `out` and removes them. Returns the
  /// number copied.
  int take_output(std::uint8_t* out, int capacity);
  /// Number of board → host bytes pending.
  int output_pending() const noexcept;
  /// Number of host bytes received but not yet executed (an incomplete command).
  int input_pending() const noexcept;

  /// Emulated time = torque commands executed × period [s].
  double time_s() const noexcept;
  /// True handle position, device frame [m].
  Vec2 handle_device_m() const noexcept;
  /// Handle velocity [m/s].
  Vec2 velocity_device_m_per_s() const noexcept;
  /// Motor force applied during the last torque command, device frame [N].
  Vec2 applied_force_device_n() const noexcept;
  /// Torques of the last command on Haply joints 1 and 2 after clamp, duty quantisation and wiring
  /// signs [N·m] (element j − 1 = joint j).
  void applied_haply_torques_n_m(double* tau_h1, double* tau_h2) const noexcept;
  /// True Haply angles θ_h1, θ_h2 of the current pose [deg] (θ_h1 in [0, 360), θ_h2 in [−180, 180)).
  void true_haply_deg(double* th1_deg, double* th2_deg) const noexcept;
  /// Torque commands executed (matching or not).
  long torque_commands() const noexcept;
  /// Replies produced by the firmware so far (before faults hide some).
  long replies_produced() const noexcept;
  /// True once the disconnect fault has fired.
  bool disconnected() const noexcept;
  /// Device rectangle's stop box, device frame [m].
  Vec2 stop_min_device_m() const noexcept;
  Vec2 stop_max_device_m() const noexcept;
  /// The parameters the emulator was built with.
  const EmulatorParams& params() const noexcept { return params_; }
  /// Replaces the hand (empty: no hand).
  void set_hand(HandForce hand);

 private:
  struct PortState {
    std::uint8_t motor_host = 0;  ///< hostAddress of the actuator on this port (0: unassigned)
    std::uint8_t motor_dir = 0;   ///< direction byte stored for actuators[port]
    std::uint8_t encoder_host = 0;
    std::uint8_t encoder_dir = 0;
    float enc_resolution_half = 1;  ///< EncResolution = resolution / 2
    std::int32_t count_at_setup = 0;
    int encoder_sign = 1;  ///< counting direction fixed at setup (pins swapped or not)
  };

  /// Tries to execute one command at the front of in_; returns the bytes consumed, 0 when incomplete.
  int execute_front();
  void do_setup(const std::uint8_t* p, int sensors_at, int sensor_count, int pwm_count, int float_at);
  void do_torques(std::uint8_t id, const std::uint8_t* floats, int n_floats);
  std::int32_t encoder_count(int port) const noexcept;
  void emit_reply(std::vector<std::uint8_t> reply);
  std::uint64_t next_random() noexcept;

  EmulatorParams params_;
  Vec2 center_m_;
  std::unique_ptr<SimulatedPantograph> sim_;
  PantographGeometry geom_;  ///< device-frame geometry
  HandForce hand_;
  std::vector<std::uint8_t> in_;
  std::vector<std::uint8_t> out_;
  std::vector<std::uint8_t> stalled_;
  PortState ports_[2];
  std::uint8_t sensor_host_[5] = {0, 0, 0, 0, 0};
  std::uint8_t pwm_host_[14] = {};
  double tau_h_[2] = {0, 0};
  long commands_ = 0;
  long replies_ = 0;
  bool disconnected_ = false;
  std::uint64_t rng_;
};

}  // namespace hk::hapi
