#include "runtime/simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "haptics/hapi_emulator.hpp"
#include "haptics/io/haply_device.hpp"
#include "haptics/io/tty_transport.hpp"
#include "haptics/pty_emulator.hpp"
#include "haptics/sim_pantograph.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/servo_runner.hpp"

namespace hk::app {

namespace {

// The headless servo loop over any device: the kiosk's ServoRunner on a HeadlessClock, `scene` the first
// picture of a ServoStep. After each tick's write: `after_write(tick, servo output)` (the simulated pantograph's
// physics and torques, or the driver's torques), the observer, the script, and the owner's collection of
// what the servo let go of.
template <class AfterWrite>
long run_ticks(const Scene& scene, const config::Settings& s, Device& device, double duration_s,
               const TickObserver& observe, const RunOptions& o, AfterWrite after_write) {
  const ServoParams sp = servo_params_from(s);
  ServoStep core(cue_params_from(s), o.cues);
  auto bundle = std::make_unique<SceneBundle>(std::shared_ptr<const Scene>(std::shared_ptr<const Scene>(), &scene), sp);
  bundle->id = o.scene_id;
  bundle->text_blocks_m = o.text_blocks_m;
  core.publish(std::move(bundle));
  const auto n_ticks = static_cast<std::int64_t>(std::ceil(duration_s / sp.period_s - 1e-9));
  HeadlessClock clock(n_ticks, sp.period_s);
  ServoRunner runner(core, device);
  runner.run(clock, [&](ServoTick& t) {
    core.publish_display();
    const ServoOutput& so = core.last_output();
    after_write(t, so);
    if (observe) observe(t, so);
    if (o.script) o.script(t.index, core);
    core.collect_retired();
  });
  return static_cast<long>(n_ticks);
}

long run_simulated(const Scene& scene, const config::Settings& s, HandController& hand, double duration_s,
                   const TickObserver& observe, const RunOptions& o) {
  SimulatedPantograph device(sim_params_from(s), hand.start_m());
  device.open();
  const ModelHandParams hp = hand_params_from(s);
  const ServoParams sp = servo_params_from(s);
  const long n_ticks = run_ticks(scene, s, device, duration_s, observe, o, [&](ServoTick& rec, const ServoOutput& so) {
    // What the hand feels: where the handle is and the force the device was told to put on it (last write);
    // what it hears: the push-through earcon of this tick.
    const bool heard_pop = (so.contact.events & kEventPopThrough) != 0;
    const HandFeel feel{rec.t_s, device.true_position_m(), device.velocity_m_per_s(), device.commanded_force_n(),
                        heard_pop};
    const HandCommand cmd = hand.command(feel);
    ModelHandParams tick_hp = hp;
    tick_hp.max_force_n = cmd.max_force_n;
    device.step(sp.period_s,
                model_hand_force(tick_hp, cmd.target_m, device.true_position_m(), device.velocity_m_per_s()));
    const Torques tau = device.applied_torques_n_m();
    rec.motor_torque_n_m[0] = tau.tau1_n_m;
    rec.motor_torque_n_m[1] = tau.tau2_n_m;
  });
  if (o.report) {
    *o.report = DeviceReport{};
    o.report->name = device.name();
    o.report->status = device_status_name(device.status());
  }
  device.close();
  return n_ticks;
}

long run_emulated(const Scene& scene, const config::Settings& s, HandController& hand, double duration_s,
                  const TickObserver& observe, const RunOptions& o) {
  const io::HaplyDeviceParams dp = haply_params_from(s);
  const double scale = io::workspace_scale(dp);
  const Vec2 centre = dp.rect_center_device_m;
  const ModelHandParams hp = hand_params_from(s);
  // The model hand lives in the workspace frame; the emulator's handle in the device frame.
  // Called on the emulator's thread only (the controller is not touched by this thread during the run); no
  // device force is fed back (see run_simulation).
  hapi::HandForce hand_force = [&hand, hp, scale, centre](double t_s, Vec2 handle_device_m,
                                                          Vec2 velocity_device_m_per_s) {
    const Vec2 handle = scale * (handle_device_m - centre), velocity = scale * velocity_device_m_per_s;
    const HandCommand cmd = hand.command(HandFeel{t_s, handle, velocity, Vec2{}});
    ModelHandParams tick_hp = hp;
    tick_hp.max_force_n = cmd.max_force_n;
    return model_hand_force(tick_hp, cmd.target_m, handle, velocity);
  };
  hapi::FirmwareEmulator emulator(emulator_params_from(s, o.device), (1.0 / scale) * hand.start_m() + centre,
                                  hand_force);
  hapi::PtyEmulator pty(emulator);
  const std::string tty_path = pty.device_path();
  io::HaplyDevice device(dp, [tty_path] { return std::make_unique<io::TtyTransport>(tty_path); });
  device.open();
  const long n_ticks = run_ticks(scene, s, device, duration_s, observe, o, [&](ServoTick& rec, const ServoOutput&) {
    device.last_torques_n_m(&rec.motor_torque_n_m[0], &rec.motor_torque_n_m[1]);
    // Keep the emulated board in step with the run, Lost or not: wait (up to 20 ms) until it has executed
    // every torque packet sent, so the emulated time, and what a fault does, never depends on how busy the
    // machine is (a loaded machine once let the run end while a stalled board still had a backlog).
    const std::int64_t sent = device.counters().ticks;
    const std::int64_t give_up = monotonic_ns() + 20'000'000;
    for (;;) {
      long done = 0;
      bool unplugged = false;
      pty.with_emulator([&](hapi::FirmwareEmulator& e) {
        done = e.torque_commands();
        unplugged = e.disconnected();  // a disconnected board executes nothing more
      });
      if (unplugged || done >= sent || monotonic_ns() >= give_up) break;
      std::this_thread::sleep_for(std::chrono::microseconds(20));
    }
    // And its reply in, as a real board's would be by the next tick: the servo step itself never waits.
    device.wait_reply(10000);
  });
  if (o.report) {
    const io::HaplyCounters c = device.counters();
    o.report->name = "haply-emulator (" + device.name() + ")";
    o.report->status = device_status_name(device.status());
    o.report->replies_missing = c.replies_missing;
    o.report->reconnects = c.reconnects;
    o.report->malformed = c.malformed;
  }
  device.close();
  pty.stop();
  return n_ticks;
}

}  // namespace

long run_simulation(const Scene& scene, const config::Settings& s, HandController& hand, double duration_s,
                    const TickObserver& observe, const RunOptions& o) {
  if (o.device.kind == DeviceChoice::Kind::HaplyEmulator) return run_emulated(scene, s, hand, duration_s, observe, o);
  return run_simulated(scene, s, hand, duration_s, observe, o);
}

long run_simulation(const Scene& scene, const config::Settings& s, HandController& hand, double duration_s,
                    const TickObserver& observe, const DeviceChoice& device, DeviceReport* report) {
  RunOptions o;
  o.device = device;
  o.report = report;
  return run_simulation(scene, s, hand, duration_s, observe, o);
}

long run_simulation(const Scene& scene, const config::Settings& s, const HandPath& hand, double duration_s,
                    const TickObserver& observe, const DeviceChoice& device, DeviceReport* report) {
  PathHand path_hand(hand, s.hand.max_force_n);
  return run_simulation(scene, s, path_hand, duration_s, observe, device, report);
}

}  // namespace hk::app
