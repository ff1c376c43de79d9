#pragma once
/// @file hapi_protocol.hpp
/// Byte encoding of the Haply hAPI serial protocol spoken by the Haply M0 board (firmware
/// Haply_M0_Firmware_V0_3) over its USB CDC serial stream, host side.
///
/// Wire format (learned from, not copied from, the public sources: firmware
/// HaplyHaptics/Haply-Arduino-Firmware-Versions Haply_M0_Firmware_V0_3/Haply_M0_Firmware_V0_3.h
/// (`setup_device`, `mtr_parameters`, `enc_parameters`, `write_states`, `read_states`,
/// `FloatToBytes`), host HaplyHaptics/Haply-API-Java Device.java (`device_set_parameters`,
/// `device_write_torques`, `device_read_data`) and Board.java (`transmit`, `reset_board`)):
///  - raw bytes, no framing, no checksum; floats are IEEE-754 binary32, little-endian;
///  - reset  `[0x00, id]`, no reply;
///  - setup  `[0x01, id, motor_mask, motor_dir × n_motors, encoder_mask, encoder_dir × n_encoders,
///            sensor_count, sensor_pin × sensor_count, pwm_count, pwm_pin × pwm_count,
///            (offset_deg f32, resolution f32) × n_encoders]`, no reply.
///            Mask bit (port − 1) is set when port 1..4 is used; directions and float pairs are in
///            PORT order (port 1 first);
///  - torques `[0x02, id, pwm_byte × pwm_count, torque_n_m f32 × n_actuators in port order]`,
///            reply `[id, f32 × sensor_count, angle_deg f32 × n_encoders in port order]`.
/// This host never configures sensors or PWM pins (both counts are sent as 0).
///
/// Index vs port: actuator/encoder *indices* are the host's names (Haply's `add_actuator(index, dir,
/// port)`); *ports* are the board connectors. Everything on the wire is in port order; the arrays of
/// this API are by index (element i = index i + 1).

#include <cstdint>

namespace hk::hapi {

/// Rotation direction byte of the protocol (firmware `#define CW 0`, `#define CCW 1`).
enum class Rotation : std::uint8_t { CW = 0, CCW = 1 };

/// One actuator as the host declares it (Haply `add_actuator(index, direction, port)`).
struct ActuatorSpec {
  int index = 1;                      ///< host index, 1..4
  Rotation direction = Rotation::CW;  ///< direction byte sent at setup
  int port = 1;                       ///< board port, 1..4
};

/// One encoder as the host declares it (Haply `add_encoder(index, direction, offset, resolution, port)`).
struct EncoderSpec {
  int index = 1;                       ///< host index, 1..4
  Rotation direction = Rotation::CCW;  ///< direction byte sent at setup
  double offset_deg = 0;               ///< angle the firmware loads into the counter at setup [deg]
  double resolution = 4880;            ///< counts per revolution as the host states it (> 0, finite)
  int port = 1;                        ///< board port, 1..4
};

/// The whole device declaration sent at setup.
struct BoardLayout {
  std::uint8_t device_id = 5;  ///< 1..255 (0 is the firmware's "unassigned" value, see validate)
  int actuator_count = 2;      ///< 0..4
  ActuatorSpec actuators[4];   ///< actuators[0..actuator_count) in any order
  int encoder_count = 2;       ///< 0..4
  EncoderSpec encoders[4];     ///< encoders[0..encoder_count) in any order
  /// The Haply 2DIY gen3 declaration of Haply's own examples (hardwareVersion 3 in Haply-API-Java
  /// examples): device id 5; actuator 1 CW port 2, actuator 2 CW port 1; encoder 1 CCW offset 180°
  /// resolution 4880 port 2, encoder 2 CCW offset 0° resolution 4880 port 1 (ports cross-wired).
  static BoardLayout haply_gen3();
};

/// Upper bound of every packet this module encodes or decodes [bytes] (the largest setup is 46).
constexpr int kMaxPacketBytes = 64;

/// Checks a layout. Throws hk::DeviceError with one line naming the field and its limit when:
/// device_id is 0 (the firmware's reset value: a torque command with id 0 would match unassigned
/// ports), a count is outside 0..4, an index or port is outside 1..4, two actuators (or two encoders)
/// share an index or a port, a direction is not CW/CCW, an offset is not finite, or a resolution is not
/// finite and > 0. Not real-time.
void validate(const BoardLayout& layout);

/// Writes the reset command `[0x00, id]` to out (≥ 2 bytes). Returns 2. Real-time.
int encode_reset(std::uint8_t id, std::uint8_t* out) noexcept;

/// Writes the setup command for `layout` (assumed valid) to out. Returns its length in bytes, or −1
/// (nothing written) when capacity is too small. Real-time.
int encode_setup(const BoardLayout& layout, std::uint8_t* out, int capacity) noexcept;

/// Length of a torque command for `layout` [bytes]: 2 + 4·actuator_count.
int torque_packet_length(const BoardLayout& layout) noexcept;

/// Real-time. Writes the torque command: torque_by_index[i] = torque of actuator index i + 1 [N·m];
/// a non-finite torque is sent as 0; each is clamped to ±limit_n_m (a non-finite or negative limit
/// counts as 0). Floats go out in port order. Returns the length, or −1 (nothing written) when
/// capacity is too small.
int encode_torques(const BoardLayout& layout, const double torque_by_index[4], double limit_n_m, std::uint8_t* out,
                   int capacity) noexcept;

/// Length of the reply to a torque command for `layout` [bytes]: 1 + 4·encoder_count (no sensors).
int reply_length(const BoardLayout& layout) noexcept;

/// Outcome of decode_reply.
enum class ReplyStatus : std::uint8_t {
  Ok,          ///< angles written
  Short,       ///< fewer than reply_length bytes
  WrongId,     ///< first byte is not layout.device_id
  NonFinite,   ///< an angle float is NaN or infinite
  OutOfRange,  ///< an angle exceeds 1e5 deg in magnitude (no real counter gets there: a desync)
};

/// Real-time. Decodes the first reply_length(layout) bytes of `in` (n bytes available):
/// angle_deg_by_index[i] = angle of encoder index i + 1 [deg] (floats arrive in port order).
/// angle_deg_by_index is written only when the result is Ok; entries of unused indices are untouched.
ReplyStatus decode_reply(const BoardLayout& layout, const std::uint8_t* in, int n,
                         double angle_deg_by_index[4]) noexcept;

/// Real-time. Little-endian IEEE-754 binary32 of v (4 bytes to out).
void put_f32_le(float v, std::uint8_t* out) noexcept;
/// Real-time. The binary32 stored little-endian at in (4 bytes).
float get_f32_le(const std::uint8_t* in) noexcept;

}  // namespace hk::hapi
