#pragma once
/// @file runtime_params.hpp
/// The settings (config::Settings, one TOML file) mapped to the servo side's parameters: the audio system,
/// the device (board layout, USB driver, emulator), the servo and its gains, the tour, the earcon tracker,
/// the simulated pantograph and the model hands. With pictures/picture_params.hpp the one place where a
/// setting becomes a parameter: every part's own parameter struct keeps its defaults and units; these
/// functions copy the settings' values into it and derive what a part needs from several settings (the
/// workspace rectangle, the servo period). The servo's stiffness and maximum force have one source,
/// servo_gains_from, which servo_params_from applies to the contact, guard and groove parameters.

#include <cstdint>

#include "audio/system.hpp"
#include "config/settings.hpp"
#include "haptics/explorer_hand.hpp"
#include "haptics/hand_controller.hpp"
#include "haptics/hapi_emulator.hpp"
#include "haptics/io/haply_device.hpp"
#include "haptics/servo.hpp"
#include "haptics/sim_pantograph.hpp"
#include "haptics/tour_guide.hpp"
#include "runtime/cue_tracker.hpp"
#include "runtime/device_setup.hpp"

namespace hk::app {

/// The audio side's parameters from the settings (volume, earcon level, ducking, speech rate, buffer).
audio::AudioSystemParams audio_params_from(const config::Settings& s);

/// The hAPI board layout of [device] (ports, directions, encoder offsets and resolutions, device id).
hapi::BoardLayout board_layout_from(const config::Settings& s);

/// The USB pantograph driver's parameters from [device] and [workspace].
io::HaplyDeviceParams haply_params_from(const config::Settings& s);

/// The firmware emulator's parameters: the board wired as [device] describes it (so a right configuration
/// reads right), the mechanism and handle physics of [device], the stop box = the usable rectangle plus
/// 5 mm, and the choice's faults and calibration errors.
hapi::EmulatorParams emulator_params_from(const config::Settings& s, const DeviceChoice& choice);

/// TourParams from the settings: [haptics] tour_max_force_n and tour_speed_m_per_s; the rest the defaults.
TourParams tour_params_from(const config::Settings& s);

/// The earcon tracker's parameters from the settings: the servo period and the workspace rectangle.
CueTrackerParams cue_params_from(const config::Settings& s);

/// The live-changeable servo gains from the settings ([haptics]: stiffness, damping, max force, friction,
/// level_max_force_step_n, query box budget), as ServoStep::set_gains takes them at Apply.
ServoGains servo_gains_from(const config::Settings& s);

/// Servo parameters from the settings. Its gains part is servo_gains_from(s) (gains_of(servo_params_from(s))
/// == servo_gains_from(s)).
ServoParams servo_params_from(const config::Settings& s);

/// Simulated pantograph parameters from the settings ([device] and the [workspace] rectangle).
SimPantographParams sim_params_from(const config::Settings& s);

/// Model hand parameters from the settings ([hand]).
ModelHandParams hand_params_from(const config::Settings& s);

/// The visitor-like explorer hand's parameters (`--hand explorer`) from the settings: the workspace, the hand's
/// spring and force, the raster's spacing and 1.5x its speed for the sweeps (capped at 5 m/s), the walls'
/// push-through and the rendering mode; `seed` drives its choices.
ExplorerParams explorer_params_from(const config::Settings& s, std::uint64_t seed);

}  // namespace hk::app
