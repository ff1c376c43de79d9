#include "simulation.hpp"

#include <chrono>
#include <cmath>

#include "haptics/sim_pantograph.hpp"

namespace hk::app {
namespace {

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

ServoGains servo_gains_from(const config::Settings& s) {
  ServoGains g;
  g.stiffness_n_per_m = s.haptics.stiffness_n_per_m;
  g.damping_n_s_per_m = s.haptics.damping_n_s_per_m;
  g.max_force_n = s.haptics.max_force_n;
  g.static_friction = s.haptics.static_friction;
  g.dynamic_friction = s.haptics.dynamic_friction;
  g.max_force_step_n = s.haptics.level_max_force_step_n;
  g.query_box_budget = s.haptics.query_box_budget;
  return g;
}

ServoParams servo_params_from(const config::Settings& s) {
  ServoParams sp;
  sp.period_s = 1.0 / s.haptics.servo_rate_hz;
  sp.level = s.haptics.level;
  sp.auto_level = s.haptics.level_mode == "auto";
  sp.policy.error_at_rest_m = s.haptics.level_error_at_rest_m;
  sp.policy.blur_time_s = s.haptics.level_blur_time_s;
  sp.policy.hysteresis = s.haptics.level_hysteresis;
  sp.policy.min_dwell_s = s.haptics.level_min_dwell_s;
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

long run_simulation(const Scene& scene, const config::Settings& s, const HandPath& hand, double duration_s,
                    const TickObserver& observe) {
  SimulatedPantograph device(sim_params_from(s), hand.at(0.0));
  device.open();
  const ModelHandParams hp = hand_params_from(s);

  const ServoParams sp = servo_params_from(s);
  ServoLoop servo(scene, sp);
  servo.start(device.read().handle_m);
  const long n_ticks = static_cast<long>(std::ceil(duration_s / sp.period_s - 1e-9));
  ServoOutput so;
  TickRecord rec;
  for (long k = 0; k < n_ticks; ++k) {
    rec.index = k;
    rec.t_s = static_cast<double>(k) * sp.period_s;
    ServoInput in;
    in.sample = device.read();
    const std::int64_t t0 = steady_ns();  // timing only: the step reads no clock
    servo.update(in, so);
    rec.tick_ns = steady_ns() - t0;
    rec.handle_m = in.sample.handle_m;
    device.write_force(so.force_n);
    device.step(sp.period_s, model_hand_force(hp, hand.at(rec.t_s), device.true_position_m(), device.velocity_m_per_s()));
    if (observe) observe(rec, so);
  }
  device.close();
  return n_ticks;
}

}  // namespace hk::app
