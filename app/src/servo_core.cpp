#include "servo_core.hpp"

#include <algorithm>

namespace hk::app {

ServoCore::ServoCore(const CueTrackerParams& cue_params, audio::SpscRing<audio::CueEvent>* cues)
    : tracker_(cue_params), cues_(cues) {}

ServoCore::~ServoCore() {
  delete pending_.exchange(nullptr);
  delete current_;
  delete to_retire_;
  collect_retired();
}

void ServoCore::publish(std::unique_ptr<SceneBundle> bundle) {
  delete pending_.exchange(bundle.release(), std::memory_order_acq_rel);
}

int ServoCore::collect_retired() {
  int n = 0;
  SceneBundle* b = nullptr;
  while (retired_.try_pop(b)) {
    delete b;
    ++n;
  }
  return n;
}

void ServoCore::set_gains(const ServoGains& g) noexcept {
  GainsSlot& slot = gains_in_.back();
  slot.gains = g;
  slot.seq = ++gains_written_;
  gains_in_.publish();
}

TickResult ServoCore::step(const DeviceSample& sample, bool deadline_missed, ServoCommand& cmd) noexcept {
  ServoInput in;
  in.sample = sample;
  in.deadline_missed = deadline_missed;
  // A device back after Lost/Fault/Closed: the picture in use starts again at the handle, force ramped in.
  const bool device_returned = sample.status == DeviceStatus::Ok && last_status_ != DeviceStatus::Ok;
  last_status_ = sample.status;

  // New gains (set_gains): kept for every picture taken from now on, applied below to the one in use.
  const GainsSlot& g = gains_in_.read();
  if (g.seq != gains_.seq) gains_ = g;

  // Hand back a bundle that found no room in the ring last time.
  if (to_retire_ && retired_.try_push(to_retire_)) to_retire_ = nullptr;
  // A new picture waits while the old one's force fades out over the force ramp time (a wall must not
  // vanish under a pressing hand in one tick); then it is taken and started at the handle (proxy there,
  // force ramped in from zero by the guard), and the old one is retired.
  if (!fading_ && current_ && pending_.load(std::memory_order_acquire) != nullptr) {
    const ServoParams& p = current_->loop.params();
    fade_total_ = p.guard.ramp_s > 0.0 ? static_cast<long>(p.guard.ramp_s / p.period_s + 0.5) : 0;
    fade_left_ = fade_total_;
    fading_ = fade_total_ > 0;
  }
  if (fading_ && fade_left_ > 0) --fade_left_;
  if (!to_retire_ && (!fading_ || fade_left_ == 0)) {
    if (SceneBundle* next = pending_.exchange(nullptr, std::memory_order_acq_rel)) {
      fading_ = false;
      if (current_ && !retired_.try_push(current_)) to_retire_ = current_;
      current_ = next;
      if (gains_.seq != 0) current_->loop.set_gains(gains_.gains);  // before start: no fade, the ramp brings it in
      current_->loop.start(in.sample.handle_m);
      tracker_.reset();
      tracker_.set_text_blocks(current_->text_blocks_m.data(), static_cast<int>(current_->text_blocks_m.size()));
    }
  }

  const int want_level = requested_level_.exchange(-1, std::memory_order_relaxed);
  if (current_ && want_level == kAutoLevel) current_->loop.set_auto_level(true);
  if (current_ && want_level >= 0) current_->loop.set_level(want_level);
  if (current_ && gains_.seq != 0) current_->loop.set_gains(gains_.gains);  // no-op unless they changed
  if (current_ && device_returned && is_finite(sample.handle_m)) current_->loop.start(sample.handle_m);

  TickResult r = TickResult::Ok;
  if (current_) {
    in.press_counts = !fading_;  // a hand sinking into a fading wall is not pushing through it
    r = current_->loop.update(in, out_);
  } else {
    out_ = ServoOutput{};
    out_.contact.proxy_m = in.sample.handle_m;
  }
  if (fading_ && fade_total_ > 0) out_.force_n = (static_cast<double>(fade_left_) / static_cast<double>(fade_total_)) * out_.force_n;
  cmd.force_n = out_.force_n;

  if (current_) {
    audio::CueEvent c[CueTracker::kMaxCuesPerTick];
    const int n = tracker_.update(tick_, out_, in.sample.handle_m, out_.level, c);
    for (int i = 0; cues_ && i < n; ++i) cues_->try_push(c[i]);  // a full ring drops and counts
  }

  ServoDisplayState& d = display_.back();
  d.tick = tick_;
  d.handle_m = in.sample.handle_m;
  d.proxy_m = out_.contact.proxy_m;
  d.force_n = out_.force_n;
  d.state = out_.contact.state;
  d.curve = out_.contact.state == ContactState::Free ? -1 : out_.contact.constraint[0].curve;
  d.level = current_ ? current_->loop.level() : 0;
  d.auto_level = current_ && current_->loop.params().auto_level;
  d.scene_id = current_ ? current_->id : -1;
  d.device_status = sample.status;
  d.penetration_m = out_.contact.state == ContactState::Free ? 0.0 : length(in.sample.handle_m - out_.contact.proxy_m);
  d.stiffness_n_per_m = current_ ? current_->loop.gains().stiffness_n_per_m : 0.0;
  d.gains_transition = current_ && current_->loop.transition_active();
  d.section_count = 0;
  if (current_) {
    const auto& sec = current_->loop.section().section();
    d.section_count = static_cast<std::int32_t>(sec.size());
    const std::size_t n = std::min<std::size_t>(sec.size(), ServoDisplayState::kMaxSection);
    std::copy_n(sec.data(), n, d.section);
  }
  ++tick_;
  return r;
}

}  // namespace hk::app
