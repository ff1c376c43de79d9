/// @file hapi_protocol.cpp
/// hAPI packet encoding and decoding. See hapi_protocol.hpp for the wire format and its sources.

#include "haptics/hapi_protocol.hpp"

#include <bit>
#include <cmath>
#include <string>

#include "haptics/device.hpp"

namespace hk::hapi {

namespace {

[[noreturn]] void bad_layout(const std::string& what) { throw hk::DeviceError("hAPI board layout: " + what); }

/// For each port 1..4 (element port − 1): position in layout.actuators of the actuator on that port,
/// or −1. Assumes a valid layout.
void actuators_by_port(const BoardLayout& l, int out[4]) noexcept {
  for (int p = 0; p < 4; ++p) out[p] = -1;
  for (int i = 0; i < l.actuator_count && i < 4; ++i) {
    const int port = l.actuators[i].port;
    if (port >= 1 && port <= 4) out[port - 1] = i;
  }
}

void encoders_by_port(const BoardLayout& l, int out[4]) noexcept {
  for (int p = 0; p < 4; ++p) out[p] = -1;
  for (int i = 0; i < l.encoder_count && i < 4; ++i) {
    const int port = l.encoders[i].port;
    if (port >= 1 && port <= 4) out[port - 1] = i;
  }
}

int clamp_count(int c) noexcept { return c < 0 ? 0 : (c > 4 ? 4 : c); }

}  // namespace

BoardLayout BoardLayout::haply_gen3() {
  BoardLayout l;
  l.device_id = 5;
  l.actuator_count = 2;
  l.actuators[0] = {1, Rotation::CW, 2};
  l.actuators[1] = {2, Rotation::CW, 1};
  l.encoder_count = 2;
  l.encoders[0] = {1, Rotation::CCW, 180.0, 4880.0, 2};
  l.encoders[1] = {2, Rotation::CCW, 0.0, 4880.0, 1};
  return l;
}

void validate(const BoardLayout& l) {
  if (l.device_id == 0) bad_layout("device_id must be in 1..255 (0 means unassigned to the firmware)");
  if (l.actuator_count < 0 || l.actuator_count > 4) bad_layout("actuator_count must be in 0..4");
  if (l.encoder_count < 0 || l.encoder_count > 4) bad_layout("encoder_count must be in 0..4");
  for (int i = 0; i < l.actuator_count; ++i) {
    const ActuatorSpec& a = l.actuators[i];
    const std::string name = "actuators[" + std::to_string(i) + "]";
    if (a.index < 1 || a.index > 4) bad_layout(name + ".index must be in 1..4");
    if (a.port < 1 || a.port > 4) bad_layout(name + ".port must be in 1..4");
    if (a.direction != Rotation::CW && a.direction != Rotation::CCW) bad_layout(name + ".direction must be CW or CCW");
    for (int j = 0; j < i; ++j) {
      if (l.actuators[j].index == a.index) bad_layout(name + ".index duplicates actuators[" + std::to_string(j) + "]");
      if (l.actuators[j].port == a.port) bad_layout(name + ".port duplicates actuators[" + std::to_string(j) + "]");
    }
  }
  for (int i = 0; i < l.encoder_count; ++i) {
    const EncoderSpec& e = l.encoders[i];
    const std::string name = "encoders[" + std::to_string(i) + "]";
    if (e.index < 1 || e.index > 4) bad_layout(name + ".index must be in 1..4");
    if (e.port < 1 || e.port > 4) bad_layout(name + ".port must be in 1..4");
    if (e.direction != Rotation::CW && e.direction != Rotation::CCW) bad_layout(name + ".direction must be CW or CCW");
    if (!std::isfinite(e.offset_deg)) bad_layout(name + ".offset_deg must be finite");
    if (!(std::isfinite(e.resolution) && e.resolution > 0.0)) bad_layout(name + ".resolution must be finite and > 0");
    for (int j = 0; j < i; ++j) {
      if (l.encoders[j].index == e.index) bad_layout(name + ".index duplicates encoders[" + std::to_string(j) + "]");
      if (l.encoders[j].port == e.port) bad_layout(name + ".port duplicates encoders[" + std::to_string(j) + "]");
    }
  }
}

void put_f32_le(float v, std::uint8_t* out) noexcept {
  const auto bits = std::bit_cast<std::uint32_t>(v);
  out[0] = static_cast<std::uint8_t>(bits & 0xFFu);
  out[1] = static_cast<std::uint8_t>((bits >> 8) & 0xFFu);
  out[2] = static_cast<std::uint8_t>((bits >> 16) & 0xFFu);
  out[3] = static_cast<std::uint8_t>((bits >> 24) & 0xFFu);
}

float get_f32_le(const std::uint8_t* in) noexcept {
  const std::uint32_t bits = static_cast<std::uint32_t>(in[0]) | (static_cast<std::uint32_t>(in[1]) << 8) |
                             (static_cast<std::uint32_t>(in[2]) << 16) | (static_cast<std::uint32_t>(in[3]) << 24);
  return std::bit_cast<float>(bits);
}

int encode_reset(std::uint8_t id, std::uint8_t* out) noexcept {
  out[0] = 0x00;
  out[1] = id;
  return 2;
}

int encode_setup(const BoardLayout& l, std::uint8_t* out, int capacity) noexcept {
  int act[4];
  int enc[4];
  actuators_by_port(l, act);
  encoders_by_port(l, enc);
  const int na = clamp_count(l.actuator_count);
  const int ne = clamp_count(l.encoder_count);
  const int len = 2 + (1 + na) + (1 + ne) + 1 + 1 + 8 * ne;
  if (out == nullptr || capacity < len) return -1;
  int k = 0;
  out[k++] = 0x01;
  out[k++] = l.device_id;
  std::uint8_t mask = 0;
  for (int p = 0; p < 4; ++p) {
    if (act[p] >= 0) mask = static_cast<std::uint8_t>(mask | (1u << p));
  }
  out[k++] = mask;
  for (int p = 0; p < 4; ++p) {
    if (act[p] >= 0) out[k++] = static_cast<std::uint8_t>(l.actuators[act[p]].direction);
  }
  mask = 0;
  for (int p = 0; p < 4; ++p) {
    if (enc[p] >= 0) mask = static_cast<std::uint8_t>(mask | (1u << p));
  }
  out[k++] = mask;
  for (int p = 0; p < 4; ++p) {
    if (enc[p] >= 0) out[k++] = static_cast<std::uint8_t>(l.encoders[enc[p]].direction);
  }
  out[k++] = 0;  // sensor count
  out[k++] = 0;  // pwm count
  for (int p = 0; p < 4; ++p) {
    if (enc[p] < 0) continue;
    put_f32_le(static_cast<float>(l.encoders[enc[p]].offset_deg), out + k);
    put_f32_le(static_cast<float>(l.encoders[enc[p]].resolution), out + k + 4);
    k += 8;
  }
  return k;
}

int torque_packet_length(const BoardLayout& l) noexcept { return 2 + 4 * clamp_count(l.actuator_count); }

int encode_torques(const BoardLayout& l, const double torque_by_index[4], double limit_n_m, std::uint8_t* out,
                   int capacity) noexcept {
  const int len = torque_packet_length(l);
  if (out == nullptr || torque_by_index == nullptr || capacity < len) return -1;
  const double lim = (std::isfinite(limit_n_m) && limit_n_m > 0.0) ? limit_n_m : 0.0;
  int act[4];
  actuators_by_port(l, act);
  int k = 0;
  out[k++] = 0x02;
  out[k++] = l.device_id;
  for (int p = 0; p < 4; ++p) {
    if (act[p] < 0) continue;
    const int idx = l.actuators[act[p]].index;
    double t = (idx >= 1 && idx <= 4) ? torque_by_index[idx - 1] : 0.0;
    if (!std::isfinite(t)) t = 0.0;
    t = t > lim ? lim : (t < -lim ? -lim : t);
    put_f32_le(static_cast<float>(t), out + k);
    k += 4;
  }
  return k;
}

int reply_length(const BoardLayout& l) noexcept { return 1 + 4 * clamp_count(l.encoder_count); }

ReplyStatus decode_reply(const BoardLayout& l, const std::uint8_t* in, int n, double angle_deg_by_index[4]) noexcept {
  const int len = reply_length(l);
  if (in == nullptr || n < len) return ReplyStatus::Short;
  if (in[0] != l.device_id) return ReplyStatus::WrongId;
  int enc[4];
  encoders_by_port(l, enc);
  double tmp[4] = {0, 0, 0, 0};
  int slot[4] = {-1, -1, -1, -1};
  int k = 1;
  int m = 0;
  for (int p = 0; p < 4; ++p) {
    if (enc[p] < 0) continue;
    const double a = static_cast<double>(get_f32_le(in + k));
    k += 4;
    if (!std::isfinite(a)) return ReplyStatus::NonFinite;
    if (std::abs(a) > 1e5) return ReplyStatus::OutOfRange;
    tmp[m] = a;
    slot[m] = l.encoders[enc[p]].index - 1;
    ++m;
  }
  if (angle_deg_by_index == nullptr) return ReplyStatus::Ok;
  for (int i = 0; i < m; ++i) {
    if (slot[i] >= 0 && slot[i] < 4) angle_deg_by_index[slot[i]] = tmp[i];
  }
  return ReplyStatus::Ok;
}

}  // namespace hk::hapi
