// The settings mapped to the servo side's parameters (runtime_params.hpp).
#include "runtime/runtime_params.hpp"

#include "hk/language.hpp"

#include <algorithm>
#include <string>

namespace hk::app {
namespace {

hapi::Rotation rotation_of(const std::string& dir) { return dir == "ccw" ? hapi::Rotation::CCW : hapi::Rotation::CW; }

}  // namespace

audio::AudioSystemParams audio_params_from(const config::Settings& s) {
  audio::AudioSystemParams p;
  p.mixer.earcons.gain = s.audio.earcon_gain;
  p.mixer.duck_db = s.audio.duck_db;
  p.speech.voice.clear();  // the catalogue's voice
  p.languages = language_list(s.kiosk.languages);
  if (p.languages.empty()) p.languages = {"en"};
  p.language = s.kiosk.language;
  p.english_voice = s.audio.voice == "espeak" ? std::string() : "flite:" + s.audio.voice.substr(6);
  p.speech.rate_wpm = s.audio.speech_rate_wpm;
  p.output.frames_per_buffer = s.audio.buffer_frames;
  p.volume_default_step = s.audio.volume_default_step;
  p.volume_step_db = s.audio.volume_step_db;
  return p;
}

hapi::BoardLayout board_layout_from(const config::Settings& s) {
  const config::DeviceSettings& d = s.device;
  hapi::BoardLayout b;
  b.device_id = static_cast<std::uint8_t>(d.device_id);
  b.actuator_count = 2;
  b.actuators[0] = {1, rotation_of(d.actuator1_dir), d.actuator1_port};
  b.actuators[1] = {2, rotation_of(d.actuator2_dir), d.actuator2_port};
  b.encoder_count = 2;
  b.encoders[0] = {1, rotation_of(d.encoder1_dir), d.encoder1_offset_deg, d.encoder1_resolution, d.encoder1_port};
  b.encoders[1] = {2, rotation_of(d.encoder2_dir), d.encoder2_offset_deg, d.encoder2_resolution, d.encoder2_port};
  return b;
}

io::HaplyDeviceParams haply_params_from(const config::Settings& s) {
  const config::DeviceSettings& d = s.device;
  io::HaplyDeviceParams p;
  p.layout = board_layout_from(s);
  p.mechanism.proximal_m = d.link_proximal_m;
  p.mechanism.distal_m = d.link_distal_m;
  p.mechanism.motor_spacing_m = d.motor_spacing_m;
  p.torque_limit_n_m = d.torque_limit_n_m;
  p.rect_center_device_m = {0.0, d.rect_center_y_m};
  p.rect_size_device_m = {d.rect_width_m, d.rect_height_m};
  p.workspace_size_m = {s.workspace.width_m, s.workspace.height_m};
  p.lost_after_ticks = d.lost_after_ticks;
  return p;
}

hapi::EmulatorParams emulator_params_from(const config::Settings& s, const DeviceChoice& choice) {
  const config::DeviceSettings& d = s.device;
  hapi::EmulatorParams e;
  e.mechanism.proximal_m = d.link_proximal_m;
  e.mechanism.distal_m = d.link_distal_m;
  e.mechanism.motor_spacing_m = d.motor_spacing_m;
  e.handle_mass_kg = d.handle_mass_kg;
  e.handle_damping_n_s_per_m = d.handle_damping_n_s_per_m;
  e.torque_limit_n_m = d.torque_limit_n_m;
  e.period_s = 1.0 / s.haptics.servo_rate_hz;
  // The board wired as configured: port → joint and the true directions per port.
  for (int port = 1; port <= 2; ++port) {
    if (d.actuator1_port == port) e.wired_motor_dir[port - 1] = rotation_of(d.actuator1_dir);
    if (d.actuator2_port == port) e.wired_motor_dir[port - 1] = rotation_of(d.actuator2_dir);
    if (d.encoder1_port == port) {
      e.wired_encoder_dir[port - 1] = rotation_of(d.encoder1_dir);
      e.port_joint[port - 1] = 1;
    }
    if (d.encoder2_port == port) {
      e.wired_encoder_dir[port - 1] = rotation_of(d.encoder2_dir);
      e.port_joint[port - 1] = 2;
    }
  }
  e.reference_deg[0] = d.encoder1_offset_deg;
  e.reference_deg[1] = d.encoder2_offset_deg;
  e.calibration_error_deg[0] = choice.calibration_error_deg[0];
  e.calibration_error_deg[1] = choice.calibration_error_deg[1];
  e.workspace_half_extent_m = {d.rect_width_m / 2, d.rect_height_m / 2};
  e.workspace_center_m = {0.0, d.rect_center_y_m};
  e.stop_margin_m = 0.005;
  e.faults = choice.faults;
  return e;
}

TourParams tour_params_from(const config::Settings& s) {
  TourParams p;
  p.max_force_n = s.haptics.tour_max_force_n;
  p.speed_m_per_s = s.haptics.tour_speed_m_per_s;
  return p;
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
  sp.steps = s.haptics.level_mode == "cut"         ? LevelSteps::Cuts
             : s.haptics.level_mode == "tolerance" ? LevelSteps::Tolerances
                                                   : LevelSteps::Levels;
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

}  // namespace hk::app
