/// @file hapi_emulator.cpp
/// Byte-level emulator of Haply_M0_Firmware_V0_3 on a simulated gen3 five-bar. See hapi_emulator.hpp.
///
/// Device rectangle (EmulatorParams defaults): with l = 0.07, L = 0.09, d = 0.038 m on the
/// elbows-outward branch, a scan of 14:9 rectangles centred on x = 0 (centre y from −0.04 to −0.14 m,
/// stop box 5 mm outside, 25 × 25 grid, requiring 30°…150° between the distal links, 20°…160° between
/// each proximal and distal link and σ_min(J) ≥ 0.02 m/rad on the stop box) found the largest at
/// 0.126 m × 0.081 m centred at y = −0.086 m, where the stop box grazes the 20° limit. The default keeps
/// a margin below that: 0.112 m × 0.072 m centred at (0, −0.088) m. On its stop box (0.122 × 0.082 m,
/// 61 × 61 grid) the distal links meet at 58°…146°, proximal/distal at 37°…149°, σ(J) ∈
/// [0.029, 0.094] m/rad, |det J| ≥ 0.00265 m²/rad²; so 0.123 N·m gives at least 1.3 N in every
/// direction. tests/haptics/test_hapi_emulator.cpp re-checks these bounds with our IK and Jacobian.

#include "haptics/hapi_emulator.hpp"
#include "hk/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace hk::hapi {

namespace {

[[noreturn]] void bad_param(const std::string& what) { throw hk::ArgumentError("hAPI emulator: " + what); }

bool finite_pos(double v) { return std::isfinite(v) && v > 0.0; }

/// Firmware: only ports 1 and 2 exist (TOTAL_ACTUATOR_PORTS = 2).
constexpr int kPorts = 2;

int bits_in_ports(std::uint8_t mask) { return (mask & 1u ? 1 : 0) + (mask & 2u ? 1 : 0); }

double wrap180(double deg) {
  double r = std::fmod(deg + 180.0, 360.0);
  if (r < 0.0) r += 360.0;
  return r - 180.0;
}

}  // namespace

FirmwareEmulator::FirmwareEmulator(const EmulatorParams& params, Vec2 start_handle_device_m, HandForce hand)
    : params_(params), hand_(std::move(hand)), rng_(params.faults.seed) {
  const EmulatorParams& p = params_;
  if (!finite_pos(p.mechanism.proximal_m) || !finite_pos(p.mechanism.distal_m) ||
      !std::isfinite(p.mechanism.motor_spacing_m) || p.mechanism.motor_spacing_m < 0.0) {
    bad_param(
        "link lengths must be finite and > 0, the motor spacing finite and >= 0 (0: coaxial motors, the original "
        "2DIY)");
  }
  if (!finite_pos(p.torque_limit_n_m)) bad_param("torque_limit_n_m must be finite and > 0");
  if (!finite_pos(p.period_s)) bad_param("period_s must be finite and > 0");
  for (int i = 0; i < kPorts; ++i) {
    if (p.port_joint[i] != 1 && p.port_joint[i] != 2) bad_param("port_joint entries must be 1 or 2");
    if (!std::isfinite(p.reference_deg[i]) || !std::isfinite(p.calibration_error_deg[i])) {
      bad_param("reference_deg and calibration_error_deg must be finite");
    }
  }
  if (p.port_joint[0] == p.port_joint[1]) bad_param("port_joint must wire each joint to one port");
  if (!is_finite(p.workspace_center_m)) bad_param("workspace_center_m must be finite");
  if (!std::isfinite(p.faults.stall_s) || p.faults.stall_s < 0.0) bad_param("faults.stall_s must be finite and >= 0");
  if (p.faults.drop_every < 0 || p.faults.garbage_every < 0 || p.faults.wrong_id_every < 0) {
    bad_param("faults.*_every must be >= 0");
  }
  if (!is_finite(start_handle_device_m)) bad_param("start handle position must be finite");

  geom_ = geometry_of(p.mechanism);
  center_m_ = p.workspace_center_m;
  SimPantographParams sp;
  sp.geometry = geom_;
  sp.geometry.base_m = geom_.base_m - center_m_;  // the simulator's frame is centred on the rectangle
  sp.handle_mass_kg = p.handle_mass_kg;
  sp.handle_damping_n_s_per_m = p.handle_damping_n_s_per_m;
  sp.max_torque_n_m = p.torque_limit_n_m;
  sp.workspace_half_extent_m = p.workspace_half_extent_m;
  sp.stop_margin_m = p.stop_margin_m;
  sim_ = std::make_unique<SimulatedPantograph>(sp, start_handle_device_m - center_m_);
  sim_->open();
  disconnected_ = p.faults.disconnect_at_s >= 0.0 && p.faults.disconnect_at_s <= 0.0;
}

FirmwareEmulator::~FirmwareEmulator() = default;

void FirmwareEmulator::set_hand(HandForce hand) { hand_ = std::move(hand); }

void FirmwareEmulator::receive(const std::uint8_t* data, int n) {
  if (disconnected_ || data == nullptr || n <= 0) return;
  in_.insert(in_.end(), data, data + n);
  while (!disconnected_ && !in_.empty()) {
    const int used = execute_front();
    if (used == 0) break;  // incomplete command: wait for more bytes
    in_.erase(in_.begin(), in_.begin() + used);
  }
  if (disconnected_) in_.clear();
}

int FirmwareEmulator::execute_front() {
  const std::uint8_t* b = in_.data();
  const int n = static_cast<int>(in_.size());
  if (n == 0) return 0;
  switch (b[0]) {
    case 0x00: {  // reset_haply: reads the id, clears every assignment, no reply
      if (n < 2) return 0;
      for (PortState& ps : ports_) {
        ps.motor_host = 0;
        ps.encoder_host = 0;
      }
      std::memset(sensor_host_, 0, sizeof sensor_host_);
      std::memset(pwm_host_, 0, sizeof pwm_host_);
      return 2;
    }
    case 0x01: {  // setup_device
      int k = 2;  // after command and id
      if (n < k + 1) return 0;
      const int motors = bits_in_ports(b[k]);
      k += 1 + motors;
      if (n < k + 1) return 0;
      const int encoders = bits_in_ports(b[k]);
      k += 1 + encoders;
      if (n < k + 1) return 0;
      const int sensors = b[k];
      const int sensors_at = k + 1;
      k += 1 + sensors;
      if (n < k + 1) return 0;
      const int pwms = b[k];
      k += 1 + pwms;
      const int float_at = k;
      k += 8 * encoders;
      if (n < k) return 0;
      do_setup(b, sensors_at, sensors, pwms, float_at);
      return k;
    }
    case 0x02: {  // write_states, then read_states
      if (n < 2) return 0;
      const std::uint8_t id = b[1];
      int pwm_bytes = 0;
      int floats = 0;
      if (id != 0) {
        for (const std::uint8_t h : pwm_host_) pwm_bytes += (h == id) ? 1 : 0;
        for (const PortState& ps : ports_) floats += (ps.motor_host == id) ? 1 : 0;
      }
      const int len = 2 + pwm_bytes + 4 * floats;
      if (n < len) return 0;
      do_torques(id, b + 2 + pwm_bytes, floats);
      return len;
    }
    default:
      return 1;  // unknown command byte: consumed, nothing done
  }
}

void FirmwareEmulator::do_setup(const std::uint8_t* b, int sensors_at, int sensor_count, int pwm_count, int float_at) {
  // reset_device first.
  for (PortState& ps : ports_) {
    ps.motor_host = 0;
    ps.encoder_host = 0;
  }
  std::memset(sensor_host_, 0, sizeof sensor_host_);
  std::memset(pwm_host_, 0, sizeof pwm_host_);

  const std::uint8_t id = b[1];
  int k = 2;
  const std::uint8_t motor_mask = b[k++];
  const int motors = bits_in_ports(motor_mask);
  for (int i = 0; i < motors; ++i) ports_[i].motor_dir = b[k++];  // by count index, not by port
  const std::uint8_t encoder_mask = b[k++];
  const int encoders = bits_in_ports(encoder_mask);
  for (int i = 0; i < encoders; ++i) ports_[i].encoder_dir = b[k++];

  for (int i = 0; i < sensor_count; ++i) {
    const int pin = static_cast<int>(b[sensors_at + i]) - 40;  // host pin 54.. → M0 analog 14..
    if (pin >= 14 && pin <= 18) sensor_host_[pin - 14] = id;   // 19 would overrun the board's array
  }
  const int pwm_at = sensors_at + sensor_count + 1;
  for (int i = 0; i < pwm_count; ++i) {
    const int pin = b[pwm_at + i];
    if (pin <= 13) pwm_host_[pin] = id;
  }

  int j = float_at;
  for (int port = 0; port < kPorts; ++port) {
    if (!(encoder_mask & (1u << port))) continue;
    PortState& ps = ports_[port];
    const float offset = get_f32_le(b + j);
    const float half_res = get_f32_le(b + j + 4) / 2;
    j += 8;
    ps.encoder_host = id;
    ps.enc_resolution_half = half_res;
    ps.encoder_sign = (ps.encoder_dir == static_cast<std::uint8_t>(params_.wired_encoder_dir[port])) ? 1 : -1;
    const float loaded = offset * half_res / 360;  // float arithmetic, as on the board
    ps.count_at_setup = std::isfinite(loaded) && std::abs(loaded) < 2.0e9f ? static_cast<std::int32_t>(loaded) : 0;
  }
  for (int port = 0; port < kPorts; ++port) {
    if (motor_mask & (1u << port)) ports_[port].motor_host = id;
  }
}

void FirmwareEmulator::do_torques(std::uint8_t id, const std::uint8_t* floats, int n_floats) {
  // create_torque per matching port, in port order; other ports keep their last duty.
  int f = 0;
  for (int port = 0; port < kPorts && f < n_floats; ++port) {
    const PortState& ps = ports_[port];
    if (id == 0 || ps.motor_host != id) continue;
    const float t = get_f32_le(floats + 4 * f);
    ++f;
    double mag = std::abs(static_cast<double>(t));
    if (!std::isfinite(mag)) mag = 0.0;  // int(NaN) is undefined on the board; taken as zero duty
    const double lim = params_.torque_limit_n_m;
    if (mag > lim) mag = lim;
    const int duty = static_cast<int>(1023.0 * mag / lim);
    const double applied = duty * lim / 1023.0;
    const int wiring = (ps.motor_dir == static_cast<std::uint8_t>(params_.wired_motor_dir[port])) ? 1 : -1;
    const double sgn = t > 0.0f ? 1.0 : -1.0;
    tau_h_[params_.port_joint[port] - 1] = wiring * sgn * applied;
  }

  // Physics: one period under the port torques and the hand.
  const double t_s = time_s();
  const Vec2 pos = handle_device_m();
  JointAngles q;
  Vec2 motor_force{};
  if (inverse_kinematics(geom_, pos, &q)) {
    const Mat2 J = jacobian(geom_, q);
    motor_force = handle_force(J, torques_from_haply(tau_h_[0], tau_h_[1]));
  }
  sim_->write_force(motor_force);
  const Vec2 hand = hand_ ? hand_(t_s, pos, sim_->velocity_m_per_s()) : Vec2{};
  sim_->step(params_.period_s, hand);
  ++commands_;

  const EmulatorFaults& fl = params_.faults;
  if (fl.disconnect_at_s >= 0.0 && time_s() >= fl.disconnect_at_s - 1e-6 * params_.period_s) {
    disconnected_ = true;
    stalled_.clear();
    return;
  }

  // read_states: [id, sensor floats, encoder floats in port order].
  std::vector<std::uint8_t> reply;
  reply.push_back(id);
  // Byte by byte: GCC 12's -Wstringop-overflow misreads vector::insert of a 4-byte range here (a false positive in
  // the package's -O2 build).
  const auto put_f32 = [&reply](float v) {
    std::uint8_t seg[4];
    put_f32_le(v, seg);
    for (const std::uint8_t byte : seg) reply.push_back(byte);
  };
  if (id != 0) {
    for (const std::uint8_t h : sensor_host_) {
      if (h == id) put_f32(0.0f);  // nothing is wired to the analog inputs
    }
    for (int port = 0; port < kPorts; ++port) {
      const PortState& ps = ports_[port];
      if (ps.encoder_host != id) continue;
      const double deg = 360.0 * encoder_count(port) / static_cast<double>(ps.enc_resolution_half);
      put_f32(static_cast<float>(deg));
    }
  }
  emit_reply(std::move(reply));
}

std::int32_t FirmwareEmulator::encoder_count(int port) const noexcept {
  const PortState& ps = ports_[port];
  double th[2];
  true_haply_deg(&th[0], &th[1]);
  const int joint = params_.port_joint[port] - 1;
  const double moved_deg =
      ps.encoder_sign * wrap180(th[joint] - params_.reference_deg[joint]) + params_.calibration_error_deg[joint];
  const double ticks = std::floor(moved_deg * static_cast<double>(ps.enc_resolution_half) / 360.0 + 1e-9);
  const double total = static_cast<double>(ps.count_at_setup) + (std::isfinite(ticks) ? ticks : 0.0);
  return static_cast<std::int32_t>(std::clamp(total, -2.0e9, 2.0e9));
}

void FirmwareEmulator::emit_reply(std::vector<std::uint8_t> reply) {
  const EmulatorFaults& fl = params_.faults;
  const long n = ++replies_;
  if (fl.wrong_id_every > 0 && n % fl.wrong_id_every == 0) reply[0] = static_cast<std::uint8_t>(reply[0] + 1);
  if (fl.drop_every > 0 && n % fl.drop_every == 0) return;
  std::vector<std::uint8_t> bytes;
  if (fl.garbage_every > 0 && n % fl.garbage_every == 0) {
    const int len = 1 + static_cast<int>(next_random() % 8);
    for (int i = 0; i < len; ++i) bytes.push_back(static_cast<std::uint8_t>(next_random() & 0xFFu));
  }
  bytes.insert(bytes.end(), reply.begin(), reply.end());
  const double t = time_s();
  const double eps = 1e-6 * params_.period_s;
  if (fl.stall_at_s >= 0.0 && t >= fl.stall_at_s - eps && t < fl.stall_at_s + fl.stall_s - eps) {
    stalled_.insert(stalled_.end(), bytes.begin(), bytes.end());
    return;
  }
  out_.insert(out_.end(), stalled_.begin(), stalled_.end());
  stalled_.clear();
  out_.insert(out_.end(), bytes.begin(), bytes.end());
}

std::uint64_t FirmwareEmulator::next_random() noexcept {
  // splitmix64
  std::uint64_t z = (rng_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

int FirmwareEmulator::take_output(std::uint8_t* out, int capacity) {
  if (out == nullptr || capacity <= 0 || out_.empty()) return 0;
  const int n = std::min(capacity, static_cast<int>(out_.size()));
  std::memcpy(out, out_.data(), static_cast<std::size_t>(n));
  out_.erase(out_.begin(), out_.begin() + n);
  return n;
}

int FirmwareEmulator::output_pending() const noexcept { return static_cast<int>(out_.size()); }
int FirmwareEmulator::input_pending() const noexcept { return static_cast<int>(in_.size()); }
double FirmwareEmulator::time_s() const noexcept { return static_cast<double>(commands_) * params_.period_s; }
Vec2 FirmwareEmulator::handle_device_m() const noexcept { return sim_->true_position_m() + center_m_; }
Vec2 FirmwareEmulator::velocity_device_m_per_s() const noexcept { return sim_->velocity_m_per_s(); }
Vec2 FirmwareEmulator::applied_force_device_n() const noexcept { return sim_->applied_force_n(); }
void FirmwareEmulator::applied_haply_torques_n_m(double* tau_h1, double* tau_h2) const noexcept {
  *tau_h1 = tau_h_[0];
  *tau_h2 = tau_h_[1];
}
void FirmwareEmulator::true_haply_deg(double* th1_deg, double* th2_deg) const noexcept {
  JointAngles q;
  if (!inverse_kinematics(geom_, handle_device_m(), &q)) q = {};
  haply_deg_from_joints(q, th1_deg, th2_deg);
}
long FirmwareEmulator::torque_commands() const noexcept { return commands_; }
long FirmwareEmulator::replies_produced() const noexcept { return replies_; }
bool FirmwareEmulator::disconnected() const noexcept { return disconnected_; }
Vec2 FirmwareEmulator::stop_min_device_m() const noexcept { return sim_->stop_min_m() + center_m_; }
Vec2 FirmwareEmulator::stop_max_device_m() const noexcept { return sim_->stop_max_m() + center_m_; }

}  // namespace hk::hapi
