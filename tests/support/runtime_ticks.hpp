#pragma once
/// @file runtime_ticks.hpp
/// A KioskRuntime driven by a test as the kiosk's threads drive it: headless options (no hot-plug, no sound
/// device, no USB probe) and one servo tick on its simulated pantograph, then the window thread's collect.

#include <filesystem>
#include <functional>

#include "haptics/sim_pantograph.hpp"
#include "runtime/servo_runner.hpp"
#include "visit/kiosk_runtime.hpp"

namespace hk::test {

/// Runtime options for a test: the library folder `library`, nothing looked for or opened outside it.
inline app::RuntimeOptions headless_runtime_options(const std::filesystem::path& library) {
  app::RuntimeOptions ro;
  ro.library = library.string();
  ro.hotplug = false;
  ro.open_audio_output = false;
  ro.probe_usb_device = false;
  return ro;
}

/// One servo tick of `dt` [s] as the servo thread does it (ServoRunner::tick: read the simulated pantograph,
/// step, write the force; then publish the display), the handle pushed by `hand_force(sim)` [N] (the model
/// hand), then the window thread's collect.
/// Requires the runtime's device to be the simulated pantograph.
inline void runtime_tick(app::KioskRuntime& rt, double dt,
                         const std::function<Vec2(const SimulatedPantograph&)>& hand_force) {
  auto& sim = dynamic_cast<SimulatedPantograph&>(rt.devices().device());
  app::ServoRunner runner(rt.core(), sim);
  app::ServoTick t;
  runner.tick(t);
  rt.core().publish_display();
  sim.step(dt, hand_force ? hand_force(sim) : Vec2{});
  rt.core().collect_retired();
}

}  // namespace hk::test
