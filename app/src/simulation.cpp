#include "simulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "haptics/hapi_emulator.hpp"
#include "haptics/io/haply_device.hpp"
#include "haptics/io/tty_transport.hpp"
#include "haptics/pty_emulator.hpp"
#include "haptics/sim_pantograph.hpp"
#include "servo_runner.hpp"

namespace hk::app {

ExplorerParams explorer_params_from(const config::Settings& s, std::uint64_t seed) {
  ExplorerParams ep;
  ep.workspace_width_m = s.workspace.width_m;
  ep.workspace_height_m = s.workspace.height_m;
  ep.sweep_spacing_m = s.hand.raster_spacing_m;
  // 1.5 x the raster's speed: the raster runs into walls blind, the explorer's plans keep it off the walls it
  // remembers and it slows to the trace speed at every wall it meets.
  ep.sweep_speed_m_per_s = std::min(5.0, 1.5 * s.hand.raster_speed_m_per_s);
  ep.max_force_n = s.hand.max_force_n;
  ep.press_force_n = std::min(ep.press_force_n, 0.5 * s.hand.max_force_n);
  ep.contact_force_n = std::min(ep.contact_force_n, 0.25 * s.hand.max_force_n);
  ep.hand_stiffness_n_per_m = s.hand.stiffness_n_per_m;
  ep.pop_force_n = s.haptics.pop_force_n;
  ep.pop_hold_s = s.haptics.pop_hold_s;
  ep.grooves = s.haptics.render == "grooves";
  ep.seed = seed;
  return ep;
}

CueTrackerParams cue_params_from(const config::Settings& s) {
  CueTrackerParams p;
  p.period_s = 1.0 / s.haptics.servo_rate_hz;
  p.workspace_half_extent_m = {s.workspace.width_m / 2, s.workspace.height_m / 2};
  return p;
}

ServoGains servo_gains_from(const config::Settings& s) {
  ServoGains g;
  g.stiffness_n_per_m = s.haptics.stiffness_n_per_m;
  g.damping_n_s_per_m = s.haptics.damping_n_s_per_m;
  g.max_force_n = s.haptics.max_force_n;
  g.static_friction = s.haptics.static_friction;
  g.dynamic_friction = s.haptics.dynamic_friction;
  g.max_force_step_n = s.haptics.level_max_force_step_n;
  g.query_box_budget = s.haptics.query_box_budget;
  g.pop_force_n = s.haptics.pop_force_n;
  g.pop_hold_s = s.haptics.pop_hold_s;
  g.pop_release_s = s.haptics.pop_release_s;
  return g;
}

ServoParams servo_params_from(const config::Settings& s) {
  ServoParams sp;
  sp.period_s = 1.0 / s.haptics.servo_rate_hz;
  sp.level = s.haptics.level;
  sp.auto_level = s.haptics.level_mode != "fixed";
  sp.tolerance_steps = s.haptics.level_mode == "tolerance";
  sp.cut_steps = s.haptics.level_mode == "cut";
  sp.policy.error_at_rest_m = s.haptics.level_error_at_rest_m;
  sp.policy.blur_time_s = s.haptics.level_blur_time_s;
  sp.policy.hysteresis = s.haptics.level_hysteresis;
  sp.policy.min_dwell_s = s.haptics.level_min_dwell_s;
  // Walls or grooves. The groove's stiffness, max force and per-tick jump limit come from
  // the gains below (stiffness_n_per_m, max_force_n, level_max_force_step_n) through apply_gains.
  sp.render = s.haptics.render == "grooves" ? RenderMode::Grooves : RenderMode::Walls;
  sp.groove.capture_radius_m = s.haptics.groove_capture_radius_m;
  sp.groove.depth_n = s.haptics.groove_depth_n;
  apply_gains(sp, servo_gains_from(s));
  sp.guard.ramp_s = s.haptics.force_ramp_s;
  return sp;
}

SimPantographParams sim_params_from(const config::Settings& s) {
  SimPantographParams dp;
  dp.handle_mass_kg = s.device.handle_mass_kg;
  dp.handle_damping_n_s_per_m = s.device.handle_damping_n_s_per_m;
  dp.encoder_counts_per_rev = s.device.encoder_counts_per_rev;
  dp.max_torque_n_m = s.device.max_torque_n_m;
  dp.workspace_half_extent_m = {s.workspace.width_m / 2, s.workspace.height_m / 2};
  return dp;
}

ModelHandParams hand_params_from(const config::Settings& s) {
  ModelHandParams hp;
  hp.stiffness_n_per_m = s.hand.stiffness_n_per_m;
  hp.damping_n_s_per_m = s.hand.damping_n_s_per_m;
  hp.max_force_n = s.hand.max_force_n;
  return hp;
}

namespace {

// The headless servo loop over any device: the kiosk's ServoRunner on a HeadlessClock, `scene` the first
// picture of a ServoCore. After each tick's write: `after_write(rec, servo output)` (the simulated pantograph's
// physics and torques, or the driver's torques), the observer, the script, and the owner's collection of
// what the servo let go of.
template <class AfterWrite>
long run_ticks(const Scene& scene, const config::Settings& s, Device& device, double duration_s, const TickObserver& observe,
               const RunOptions& o, AfterWrite after_write) {
  const ServoParams sp = servo_params_from(s);
  ServoCore core(cue_params_from(s), o.cues);
  auto bundle = std::make_unique<SceneBundle>(std::shared_ptr<const Scene>(std::shared_ptr<const Scene>(), &scene), sp);
  bundle->id = o.scene_id;
  bundle->text_blocks_m = o.text_blocks_m;
  core.publish(std::move(bundle));
  const auto n_ticks = static_cast<std::int64_t>(std::ceil(duration_s / sp.period_s - 1e-9));
  HeadlessClock clock(n_ticks, sp.period_s);
  ServoRunner runner(core, device);
  TickRecord rec;
  runner.run(clock, [&](ServoTick& t) {
    core.publish_display();
    rec.index = static_cast<long>(t.index);
    rec.t_s = t.t_s;
    rec.tick_ns = t.step_ns;
    rec.handle_m = t.sample.handle_m;
    rec.device_status = t.sample.status;
    const ServoOutput& so = core.last_output();
    after_write(rec, so);
    if (observe) observe(rec, so);
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
  const long n_ticks = run_ticks(scene, s, device, duration_s, observe, o, [&](TickRecord& rec, const ServoOutput& so) {
    // What the hand feels: where the handle is and the force the device was told to put on it (last write);
    // what it hears: the push-through earcon of this tick.
    const bool heard_pop = (so.contact.events & kEventPopThrough) != 0;
    const HandFeel feel{rec.t_s, device.true_position_m(), device.velocity_m_per_s(), device.commanded_force_n(), heard_pop};
    const HandCommand cmd = hand.command(feel);
    ModelHandParams tick_hp = hp;
    tick_hp.max_force_n = cmd.max_force_n;
    device.step(sp.period_s, model_hand_force(tick_hp, cmd.target_m, device.true_position_m(), device.velocity_m_per_s()));
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
  hapi::HandForce hand_force = [&hand, hp, scale, centre](double t_s, Vec2 handle_device_m, Vec2 velocity_device_m_per_s) {
    const Vec2 handle = scale * (handle_device_m - centre), velocity = scale * velocity_device_m_per_s;
    const HandCommand cmd = hand.command(HandFeel{t_s, handle, velocity, Vec2{}});
    ModelHandParams tick_hp = hp;
    tick_hp.max_force_n = cmd.max_force_n;
    return model_hand_force(tick_hp, cmd.target_m, handle, velocity);
  };
  hapi::FirmwareEmulator emulator(emulator_params_from(s, o.device), (1.0 / scale) * hand.start_m() + centre, hand_force);
  hapi::PtyEmulator pty(emulator);
  const std::string tty_path = pty.device_path();
  io::HaplyDevice device(dp, [tty_path] { return std::make_unique<io::TtyTransport>(tty_path); });
  device.open();
  const long n_ticks = run_ticks(scene, s, device, duration_s, observe, o, [&](TickRecord& rec, const ServoOutput&) {
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
