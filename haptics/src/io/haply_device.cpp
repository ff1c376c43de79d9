// The hAPI pantograph driver (haply_device.hpp).
#include "haptics/io/haply_device.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace hk::io {
namespace {

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// Setup-time write of a whole packet: as many calls as the transport needs, within `timeout_us` [µs] in all.
/// Returns n, or what the last call returned (kGone, or fewer bytes than n when time ran out).
int write_whole(ByteTransport& t, const std::uint8_t* data, int n, int timeout_us) {
  const std::int64_t give_up = steady_ns() + static_cast<std::int64_t>(timeout_us) * 1000;
  int at = 0;
  while (at < n) {
    const int left_us = static_cast<int>(std::max<std::int64_t>(0, (give_up - steady_ns()) / 1000));
    const int r = t.write(data + at, n - at, left_us);
    if (r == ByteTransport::kGone) return r;
    at += r;
    if (at < n && left_us == 0) break;
  }
  return at;
}

bool finite_positive(Vec2 v) { return std::isfinite(v.x) && std::isfinite(v.y) && v.x > 0.0 && v.y > 0.0; }

}  // namespace

double workspace_scale(const HaplyDeviceParams& p) noexcept {
  return std::min(p.workspace_size_m.x / p.rect_size_device_m.x, p.workspace_size_m.y / p.rect_size_device_m.y);
}

bool calibrated_offsets(const HaplyDeviceParams& p, Vec2 park_workspace_m, double reported_th1_deg,
                        double reported_th2_deg, double* offset1_deg, double* offset2_deg) noexcept {
  if (!is_finite(park_workspace_m) || !std::isfinite(reported_th1_deg) || !std::isfinite(reported_th2_deg))
    return false;
  const Vec2 park_device = (1.0 / workspace_scale(p)) * park_workspace_m + p.rect_center_device_m;
  JointAngles q;
  if (!inverse_kinematics(hapi::geometry_of(p.mechanism), park_device, &q)) return false;
  double want1 = 0, want2 = 0;
  hapi::haply_deg_from_joints(q, &want1, &want2);
  const auto wrap = [](double a) { return a - 360.0 * std::ceil((a - 180.0) / 360.0); };  // into (−180, 180]
  double o1 = 0, o2 = 0;
  for (int i = 0; i < p.layout.encoder_count; ++i) {
    if (p.layout.encoders[i].index == 1) o1 = p.layout.encoders[i].offset_deg;
    if (p.layout.encoders[i].index == 2) o2 = p.layout.encoders[i].offset_deg;
  }
  *offset1_deg = o1 + wrap(want1 - reported_th1_deg);
  *offset2_deg = o2 + wrap(want2 - reported_th2_deg);
  return true;
}

double min_force_capability_n(const HaplyDeviceParams& p) noexcept {
  return min_force_everywhere_n(hapi::geometry_of(p.mechanism), p.rect_center_device_m, p.rect_size_device_m,
                                p.torque_limit_n_m);
}

std::unique_ptr<HaplyDevice> open_first_board(const HaplyDeviceParams& params,
                                              const std::vector<BoardCandidate>& candidates,
                                              std::vector<BoardProbe>* probes) {
  for (const BoardCandidate& c : candidates) {
    BoardProbe probe{c.name, false, {}};
    try {
      auto device = std::make_unique<HaplyDevice>(params, c.factory);
      const std::int64_t t0 = steady_ns();
      device->open();
      probe.answered = true;
      probe.how = "hAPI reply from device id " + std::to_string(params.layout.device_id) + " after " +
                  std::to_string((steady_ns() - t0) / 1000000) + " ms";
      if (probes) probes->push_back(probe);
      return device;
    } catch (const std::exception& e) {
      probe.how = e.what();
      if (probes) probes->push_back(probe);
    }
  }
  return nullptr;
}

HaplyDevice::HaplyDevice(const HaplyDeviceParams& params, TransportFactory factory)
    : params_(params), factory_(std::move(factory)), geometry_(hapi::geometry_of(params.mechanism)) {
  hapi::validate(params_.layout);
  const auto has_index = [](const auto* specs, int count, int index) {
    for (int i = 0; i < count; ++i)
      if (specs[i].index == index) return true;
    return false;
  };
  for (int index : {1, 2}) {
    if (!has_index(params_.layout.actuators, params_.layout.actuator_count, index))
      throw DeviceError("USB pantograph: the board layout has no actuator " + std::to_string(index) +
                        " (a pantograph needs actuators 1 and 2)");
    if (!has_index(params_.layout.encoders, params_.layout.encoder_count, index))
      throw DeviceError("USB pantograph: the board layout has no encoder " + std::to_string(index) +
                        " (a pantograph needs encoders 1 and 2)");
  }
  if (!finite_positive(params_.rect_size_device_m) || !finite_positive(params_.workspace_size_m) ||
      !is_finite(params_.rect_center_device_m))
    throw DeviceError("USB pantograph: the usable rectangle and the workspace need finite sizes > 0 m");
  if (params_.lost_after_ticks < 1) throw DeviceError("USB pantograph: lost_after_ticks must be >= 1");
  if (!(params_.torque_limit_n_m > 0.0) || !std::isfinite(params_.torque_limit_n_m))
    throw DeviceError("USB pantograph: the torque limit must be a finite number > 0 N·m");
  if (!factory_) throw DeviceError("USB pantograph: no transport to open");
  scale_ = workspace_scale(params_);
}

HaplyDevice::~HaplyDevice() { close(); }

std::string HaplyDevice::name() const {
  return "Haply pantograph" + (transport_ ? " (" + transport_->name() + ")" : std::string{});
}

Vec2 HaplyDevice::to_workspace(Vec2 device_m) const noexcept {
  return scale_ * (device_m - params_.rect_center_device_m);
}
Vec2 HaplyDevice::to_device(Vec2 workspace_m) const noexcept {
  return (1.0 / scale_) * workspace_m + params_.rect_center_device_m;
}

bool HaplyDevice::device_position(double th1_deg, double th2_deg, Vec2* device_m) const noexcept {
  return forward_kinematics(geometry_, hapi::joints_from_haply_deg(th1_deg, th2_deg), device_m);
}

void HaplyDevice::send_setup(ByteTransport& t) {
  std::uint8_t buf[hapi::kMaxPacketBytes];
  int n = hapi::encode_reset(params_.layout.device_id, buf);
  if (write_whole(t, buf, n, 100000) != n) throw DeviceError(t.name() + ": the reset packet could not be written");
  n = hapi::encode_setup(params_.layout, buf, static_cast<int>(sizeof buf));
  if (n < 0 || write_whole(t, buf, n, 100000) != n)
    throw DeviceError(t.name() + ": the setup packet could not be written");
}

void HaplyDevice::open() {
  if (status() != DeviceStatus::Closed) return;
  std::unique_ptr<ByteTransport> t = factory_();
  if (!t) throw DeviceError("USB pantograph: no transport to open");
  t->open();
  t->flush_input();
  send_setup(*t);
  transport_ = std::move(t);
  rx_len_ = 0;
  tx_len_ = tx_at_ = 0;
  outstanding_ = false;
  fresh_ = false;
  have_angles_ = false;
  missing_in_row_ = 0;
  // Zero-torque packets until the first valid reply.
  const std::int64_t give_up = steady_ns() + static_cast<std::int64_t>(params_.open_timeout_ms) * 1000000;
  std::uint8_t pkt[hapi::kMaxPacketBytes];
  const double zero[4] = {0, 0, 0, 0};
  const int n = hapi::encode_torques(params_.layout, zero, params_.torque_limit_n_m, pkt, static_cast<int>(sizeof pkt));
  bool answered = false;
  while (!answered && steady_ns() < give_up) {
    if (write_whole(*transport_, pkt, n, 100000) == ByteTransport::kGone) break;
    answered = take_replies(20000);
  }
  if (!answered) {
    const std::string what = transport_->name();
    const std::int64_t refused = malformed_.exchange(0);
    transport_->close();
    transport_.reset();
    const std::string id = std::to_string(params_.layout.device_id),
                      within = std::to_string(params_.open_timeout_ms) + " ms";
    if (refused > 0)
      throw DeviceError(what + ": answered, but with no well-formed hAPI reply from device id " + id + " within " +
                        within + " (" + std::to_string(refused) +
                        " replies refused: another device, or another firmware)");
    throw DeviceError(what + ": no reply from device id " + id + " within " + within +
                      " (is the board a Haply running hAPI firmware?)");
  }
  t0_ns_ = steady_ns();
  gone_.store(false);
  status_.store(DeviceStatus::Ok, std::memory_order_release);
  {
    std::lock_guard<std::mutex> lock(reopen_mutex_);
    stop_reopen_ = false;
  }
  reopen_thread_ = std::thread([this] { reopen_loop(); });
}

bool HaplyDevice::take_replies(int wait_us) noexcept {
  const int len = hapi::reply_length(params_.layout);
  const std::int64_t deadline = wait_us > 0 ? steady_ns() + static_cast<std::int64_t>(wait_us) * 1000 : 0;
  bool got = false;
  bool dropping = false;
  for (;;) {
    int left_us = 0;
    if (wait_us > 0) left_us = static_cast<int>(std::max<std::int64_t>(0, (deadline - steady_ns()) / 1000));
    const int r = transport_->read(rx_ + rx_len_, static_cast<int>(sizeof rx_) - rx_len_, left_us);
    if (r == ByteTransport::kGone) {
      gone_.store(true, std::memory_order_release);
      return got;
    }
    rx_len_ += r;
    // Take every whole reply; resynchronise byte by byte past anything that is not one.
    int at = 0;
    while (rx_len_ - at >= len) {
      double angle[4] = {0, 0, 0, 0};
      bool ok = hapi::decode_reply(params_.layout, rx_ + at, len, angle) == hapi::ReplyStatus::Ok;
      angle[0] += correction1_deg_.load(std::memory_order_relaxed);
      angle[1] += correction2_deg_.load(std::memory_order_relaxed);
      if (ok && have_angles_) {
        const double allowed = params_.max_step_deg * (1.0 + missing_in_row_);
        ok = std::fabs(angle[0] - th1_deg_.load(std::memory_order_relaxed)) <= allowed &&
             std::fabs(angle[1] - th2_deg_.load(std::memory_order_relaxed)) <= allowed;
      }
      Vec2 dev;
      if (ok) ok = device_position(angle[0], angle[1], &dev);
      if (!ok) {
        if (!dropping) malformed_.fetch_add(1, std::memory_order_relaxed);
        dropping = true;
        ++at;
        continue;
      }
      dropping = false;
      th1_deg_.store(angle[0], std::memory_order_relaxed);
      th2_deg_.store(angle[1], std::memory_order_relaxed);
      q_ = hapi::joints_from_haply_deg(angle[0], angle[1]);
      handle_ws_m_ = to_workspace(dev);
      have_angles_ = true;
      got = true;
      missing_in_row_ = 0;
      replies_.fetch_add(1, std::memory_order_relaxed);
      at += len;
    }
    if (at > 0) {
      std::copy(rx_ + at, rx_ + rx_len_, rx_);
      rx_len_ -= at;
    }
    if (rx_len_ == static_cast<int>(sizeof rx_)) rx_len_ = 0;  // cannot happen with len < sizeof rx_; stay safe
    if (got || wait_us <= 0 || steady_ns() >= deadline) return got;
  }
}

void HaplyDevice::adopt_pending() noexcept {
  if (pending_.load(std::memory_order_acquire) == nullptr || retired_.load(std::memory_order_acquire) != nullptr)
    return;
  ByteTransport* fresh = pending_.exchange(nullptr, std::memory_order_acq_rel);
  retired_.store(transport_.release(), std::memory_order_release);  // closed and freed by the re-open thread
  transport_.reset(fresh);
  rx_len_ = 0;
  tx_len_ = tx_at_ = 0;
  outstanding_ = false;
  fresh_ = false;
  gone_.store(false, std::memory_order_release);
}

DeviceSample HaplyDevice::read() noexcept {
  DeviceSample s;
  const DeviceStatus st = status();
  if (st == DeviceStatus::Closed || !transport_) {
    s.status = DeviceStatus::Closed;
    return s;
  }
  adopt_pending();
  bool got = fresh_;
  fresh_ = false;
  if (!gone_.load(std::memory_order_acquire)) got = take_replies(0) || got;
  if (got) {
    outstanding_ = false;
    if (st == DeviceStatus::Lost) {
      reconnects_.fetch_add(1, std::memory_order_relaxed);
      status_.store(DeviceStatus::Ok, std::memory_order_release);
    }
  } else if (outstanding_ || gone_.load(std::memory_order_relaxed)) {
    ++missing_in_row_;
    missing_.fetch_add(1, std::memory_order_relaxed);
    if (missing_in_row_ >= params_.lost_after_ticks) status_.store(DeviceStatus::Lost, std::memory_order_release);
    if (outstanding_ && ++outstanding_age_ >= kReplyWaitTicks)
      outstanding_ = false;  // given up: the next packet goes out
  }
  s.handle_m = handle_ws_m_;
  s.time_ns = steady_ns() - t0_ns_;
  s.status = status();
  return s;
}

bool HaplyDevice::wait_reply(int timeout_us) noexcept {
  if (!transport_ || !outstanding_ || fresh_ || gone_.load(std::memory_order_acquire)) return !outstanding_ || fresh_;
  fresh_ = take_replies(timeout_us);
  return fresh_;
}

bool HaplyDevice::flush_tx() noexcept {
  if (tx_at_ >= tx_len_) return true;
  const int r = transport_->write(tx_ + tx_at_, tx_len_ - tx_at_, 0);
  if (r == ByteTransport::kGone) {
    gone_.store(true, std::memory_order_release);
    return false;
  }
  tx_at_ += r;
  return tx_at_ >= tx_len_;
}

void HaplyDevice::write_force(Vec2 force_n) noexcept {
  if (!transport_ || status() == DeviceStatus::Closed || gone_.load(std::memory_order_acquire)) return;
  // At most one packet outstanding while the board answers, and never a packet cut by another. A board that
  // stopped answering gets zero torque at once (the first packet after the loss), then a zero-torque probe
  // each tick.
  const bool answering = status() == DeviceStatus::Ok;
  if (!flush_tx() || (answering && outstanding_ && outstanding_age_ < kReplyWaitTicks)) {
    if (!gone_.load(std::memory_order_relaxed)) skipped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  double tau_by_index[4] = {0, 0, 0, 0};
  if (answering && have_angles_ && is_finite(force_n)) {
    // The force is the same vector in the device and workspace frames (no rotation between them).
    const Torques ours = joint_torques(jacobian(geometry_, q_), force_n);
    hapi::haply_torques_from(ours, &tau_by_index[0], &tau_by_index[1]);
  }
  const int n =
      hapi::encode_torques(params_.layout, tau_by_index, params_.torque_limit_n_m, tx_, static_cast<int>(sizeof tx_));
  const double lim = params_.torque_limit_n_m;
  tau1_.store(std::isfinite(tau_by_index[0]) ? std::clamp(tau_by_index[0], -lim, lim) : 0.0, std::memory_order_relaxed);
  tau2_.store(std::isfinite(tau_by_index[1]) ? std::clamp(tau_by_index[1], -lim, lim) : 0.0, std::memory_order_relaxed);
  tx_len_ = n > 0 ? n : 0;
  tx_at_ = 0;
  flush_tx();
  if (gone_.load(std::memory_order_acquire)) return;
  ticks_.fetch_add(1, std::memory_order_relaxed);
  outstanding_ = true;
  outstanding_age_ = 0;
}

void HaplyDevice::reopen_loop() {
  std::unique_lock<std::mutex> lock(reopen_mutex_);
  const auto interval = std::chrono::duration<double>(params_.reopen_interval_s);
  while (!stop_reopen_) {
    reopen_cv_.wait_for(lock, interval, [this] { return stop_reopen_; });
    if (stop_reopen_) break;
    if (ByteTransport* old = retired_.exchange(nullptr, std::memory_order_acq_rel)) {
      old->close();
      delete old;
    }
    if (!gone_.load(std::memory_order_acquire) || pending_.load(std::memory_order_acquire) != nullptr) continue;
    try {
      std::unique_ptr<ByteTransport> t = factory_();
      if (!t) continue;
      t->open();
      t->flush_input();
      send_setup(*t);
      pending_.store(t.release(), std::memory_order_release);
      reopens_.fetch_add(1, std::memory_order_relaxed);
    } catch (const std::exception&) {
      // Not there yet: try again after the interval.
    }
  }
}

void HaplyDevice::close() noexcept {
  {
    std::lock_guard<std::mutex> lock(reopen_mutex_);
    stop_reopen_ = true;
  }
  reopen_cv_.notify_all();
  if (reopen_thread_.joinable()) reopen_thread_.join();
  if (transport_ && !gone_.load()) {
    std::uint8_t pkt[hapi::kMaxPacketBytes];
    const double zero[4] = {0, 0, 0, 0};
    const int n =
        hapi::encode_torques(params_.layout, zero, params_.torque_limit_n_m, pkt, static_cast<int>(sizeof pkt));
    if (tx_at_ >= tx_len_) (void)write_whole(*transport_, pkt, n, 100000);  // not into the middle of a packet
  }
  if (transport_) transport_->close();
  transport_.reset();
  for (auto* slot : {&pending_, &retired_}) {
    if (ByteTransport* t = slot->exchange(nullptr)) {
      t->close();
      delete t;
    }
  }
  tau1_.store(0.0);
  tau2_.store(0.0);
  status_.store(DeviceStatus::Closed, std::memory_order_release);
}

HaplyCounters HaplyDevice::counters() const noexcept {
  HaplyCounters c;
  c.ticks = ticks_.load(std::memory_order_relaxed);
  c.replies = replies_.load(std::memory_order_relaxed);
  c.replies_missing = missing_.load(std::memory_order_relaxed);
  c.malformed = malformed_.load(std::memory_order_relaxed);
  c.reconnects = reconnects_.load(std::memory_order_relaxed);
  c.reopens = reopens_.load(std::memory_order_relaxed);
  c.writes_skipped = skipped_.load(std::memory_order_relaxed);
  return c;
}

void HaplyDevice::apply_offsets(double offset1_deg, double offset2_deg) noexcept {
  double o1 = 0, o2 = 0;
  for (int i = 0; i < params_.layout.encoder_count; ++i) {
    if (params_.layout.encoders[i].index == 1) o1 = params_.layout.encoders[i].offset_deg;
    if (params_.layout.encoders[i].index == 2) o2 = params_.layout.encoders[i].offset_deg;
  }
  if (std::isfinite(offset1_deg) && std::isfinite(offset2_deg)) {
    correction1_deg_.store(offset1_deg - o1, std::memory_order_relaxed);
    correction2_deg_.store(offset2_deg - o2, std::memory_order_relaxed);
  }
}

bool HaplyDevice::calibrate(Vec2 park_workspace_m, double* offset1_deg, double* offset2_deg) noexcept {
  if (replies_.load(std::memory_order_relaxed) == 0) return false;
  const double raw1 = th1_deg_.load(std::memory_order_relaxed) - correction1_deg_.load(std::memory_order_relaxed);
  const double raw2 = th2_deg_.load(std::memory_order_relaxed) - correction2_deg_.load(std::memory_order_relaxed);
  double o1 = 0, o2 = 0;
  if (!calibrated_offsets(params_, park_workspace_m, raw1, raw2, &o1, &o2)) return false;
  apply_offsets(o1, o2);
  *offset1_deg = o1;
  *offset2_deg = o2;
  return true;
}

void HaplyDevice::joint_angles_deg(double* th1_deg, double* th2_deg) const noexcept {
  *th1_deg = th1_deg_.load(std::memory_order_relaxed);
  *th2_deg = th2_deg_.load(std::memory_order_relaxed);
}

void HaplyDevice::last_torques_n_m(double* tau1, double* tau2) const noexcept {
  *tau1 = tau1_.load(std::memory_order_relaxed);
  *tau2 = tau2_.load(std::memory_order_relaxed);
}

}  // namespace hk::io
