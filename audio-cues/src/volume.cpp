#include "audio/volume.hpp"

#include <algorithm>
#include <cmath>

namespace hk::audio {

Volume::Volume(int default_step, int max_step, double step_db)
    : default_step_(0), max_step_(std::clamp(max_step, 1, 30)), step_db_(std::clamp(step_db, 0.1, 12.0)) {
  set_default(default_step);
}

void Volume::set(int s) noexcept {
  s = std::clamp(s, 1, max_step_);
  step_.store(s, std::memory_order_relaxed);
  gain_.store(static_cast<float>(std::pow(10.0, -(max_step_ - s) * step_db_ / 20.0)), std::memory_order_relaxed);
}

bool Volume::up() noexcept {
  if (step() >= max_step_) return false;
  set(step() + 1);
  return true;
}

bool Volume::down() noexcept {
  if (step() <= 1) return false;
  set(step() - 1);
  return true;
}

void Volume::reset() noexcept { set(default_step_); }

void Volume::set_default(int s) noexcept {
  default_step_ = std::clamp(s, 1, max_step_);
  reset();
}

}  // namespace hk::audio
