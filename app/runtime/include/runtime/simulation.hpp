#pragma once
/// @file simulation.hpp
/// The headless servo run: simulated pantograph (or the emulated Haply board) + model hand + the kiosk's own
/// servo loop (ServoRunner driving ServoStep::step), tick by tick as fast as the machine goes (DESIGN.md
/// "Headless runs"). Shared by `explore`, the integration tests and the benchmarks. A RunScript plays the
/// kiosk's other threads between ticks (a new picture, a tour, new gains, a level), so a headless run
/// feels what the visitor feels.

#include <cstdint>
#include <functional>

#include "audio/cue_event.hpp"
#include "audio/spsc_ring.hpp"
#include "config/settings.hpp"
#include "haptics/explorer_hand.hpp"
#include "haptics/hand_controller.hpp"
#include "haptics/hand_path.hpp"
#include "haptics/scene.hpp"
#include "haptics/servo.hpp"
#include "haptics/sim_pantograph.hpp"
#include "runtime/device_setup.hpp"
#include "runtime/servo_runner.hpp"
#include "runtime/servo_step.hpp"

namespace hk::app {

/// Called after every tick with the tick (servo_runner.hpp ServoTick: its time, the device's sample, the step's
/// time and the motor torques) and the servo's full output (proxy path, events, stats).
using TickObserver = std::function<void(const ServoTick&, const ServoOutput&)>;

/// The owner's side of a headless run, called after tick `index` (after the observer): what the kiosk's
/// other threads do while a visitor explores, e.g. core.publish(bundle) (a new picture, faded in as in the
/// kiosk), core.publish_tour(path), core.set_gains(g), core.request_level(l), core.cancel_tour().
/// ServoStep::display() is the tick's state. Retired bundles and tours are collected after it.
using RunScript = std::function<void(std::int64_t index, ServoStep& core)>;

/// What a headless run may add to the scene and the hand.
struct RunOptions {
  DeviceChoice device;                               ///< the simulated pantograph or the emulated board
  DeviceReport* report = nullptr;                    ///< receives the device's name, status, counters
  RunScript script;                                  ///< the owner's calls between ticks (may be empty)
  audio::SpscRing<audio::CueEvent>* cues = nullptr;  ///< the step's earcons (drain it each tick), or none
  std::vector<Aabb> text_blocks_m;                   ///< the scene's text blocks [m] (TextBlock cues)
  int scene_id = 0;                                  ///< SceneBundle::id of the scene (a tour names it)
};

/// Runs the device `o.device` chose (the simulated pantograph, or the Haply firmware emulator behind a pty
/// reached through the tty transport and the hAPI driver, bytes and all) driven by the model hand `hand` over
/// `scene` for `duration_s` seconds, tick by tick as fast as the machine goes, through the kiosk's servo
/// loop: a ServoRunner on a HeadlessClock driving a ServoStep whose first picture is `scene` (with
/// servo_params_from(s)), taken and started at the handle at tick 0. Each tick the simulated
/// pantograph is pushed by model_hand_force(hand_params_from(s) with max_force_n = the command's max_force_n,
/// command.target_m, ...), the command being hand.command(feel) with feel = {t, true handle position, its
/// velocity, the force the servo wrote to the device at the previous tick (after the guard)}.
/// With the emulator the hand force is computed on the emulator's own thread and the feel carries no device
/// force (zero): only open-loop hands (PathHand) are meaningful there, and `hand` must not be used
/// elsewhere during the run. Between ticks (never inside one) the run waits up to 20 ms for the emulator to
/// have executed every packet sent, Lost or not, until it is disconnected, then up to 10 ms for the reply
/// to the packet, as a real board's would be in by the next tick (so the run does not depend on the
/// machine's speed); a device that comes back restarts the servo at the handle (force ramped in again: ServoStep).
/// `o.script` runs after each tick. Returns the number of ticks run. Throws DeviceError when the emulator
/// cannot be reached. `scene` outlives the call.
long run_simulation(const Scene& scene, const config::Settings& s, HandController& hand, double duration_s,
                    const TickObserver& observe, const RunOptions& o);

/// The same with only a device choice and its report.
long run_simulation(const Scene& scene, const config::Settings& s, HandController& hand, double duration_s,
                    const TickObserver& observe, const DeviceChoice& device = {}, DeviceReport* report = nullptr);

/// The same for an open-loop hand path: a PathHand pushing with at most [hand] max_force_n.
long run_simulation(const Scene& scene, const config::Settings& s, const HandPath& hand, double duration_s,
                    const TickObserver& observe, const DeviceChoice& device = {}, DeviceReport* report = nullptr);

}  // namespace hk::app
