#pragma once
/// @file device_setup.hpp
/// Which device a run or the kiosk uses, built from the settings: the
/// `--device` choice of headless runs (`sim`, or `haply-emulator[:FAULT=VALUE,...]`: the firmware emulator
/// behind a pty, reached through the same tty transport and driver as a real board), the USB pantograph's
/// driver parameters from [device] and [workspace], and the transport to a real board ([device] transport:
/// libusb CDC-ACM by VID:PID, or the kernel's tty).

#include <stdexcept>
#include <string>
#include <vector>
#include "hk/error.hpp"

#include "config/settings.hpp"
#include "haptics/device.hpp"
#include "haptics/hapi_emulator.hpp"
#include "haptics/hapi_protocol.hpp"
#include "haptics/io/haply_device.hpp"

namespace hk::app {

/// A `--device` value that cannot be used; the message names the value and the limit.
class DeviceChoiceError : public hk::Error {
 public:
  using hk::Error::Error;
};

/// What `--device` asked for.
struct DeviceChoice {
  enum class Kind { Simulated, HaplyEmulator };
  Kind kind = Kind::Simulated;
  hapi::EmulatorFaults faults;  ///< haply-emulator faults (disconnect_at_s, drop_every, garbage_every, wrong_id_every,
                                ///< stall_at_s, stall_s, seed)
  double calibration_error_deg[2] = {
      0, 0};  ///< haply-emulator: encoder zero errors of joints 1 and 2 (calib_error1_deg, calib_error2_deg) [deg]
  bool rest_at_park = false;  ///< haply-emulator: the handle rests at the park place, its stops hugging it
                              ///< (rest_at_park=1), as a board waits at its home pose for a kiosk to start
};

/// Parses `sim` (or `simulated`) and `haply-emulator[:KEY=VALUE,...]` with keys disconnect_at_s, stall_at_s,
/// stall_s (seconds ≥ 0), drop_every, garbage_every, wrong_id_every (integers in [0, 1000000]; 0 = never),
/// seed (integer ≥ 0), calib_error1_deg, calib_error2_deg ([-90, 90]), rest_at_park (0 or 1). Throws DeviceChoiceError
/// naming the key or value and its limit.
DeviceChoice parse_device_choice(const std::string& text);

/// The firmware emulator with its handle resting at the park place ([device] park_x_m, park_y_m: by default
/// the board's home pose, beyond the usable rectangle at the edge of the links' reach): emulator_params_from
/// with stops hugging the park place (0.5 mm each way). `*start_device_m` is the place, device frame [m].
hapi::EmulatorParams emulator_resting_at_park(const config::Settings& s, const DeviceChoice& choice,
                                              Vec2* start_device_m);

/// Where the handle read at start against where it should rest (the park place), workspace frame.
struct HomeCheck {
  bool at_home = true;  ///< within kHomeTolerance_m of the park place (or nothing read yet)
  Vec2 read_m;          ///< where the first reply puts the handle [m]
  Vec2 park_m;          ///< [device] park_x_m, park_y_m [m]
  double off_m = 0.0;   ///< the distance between them [m]
};

/// How far from the park place a handle may read at start and still count as resting there [m]: a few
/// encoder counts at the home pose, far less than a handle put down elsewhere.
inline constexpr double kHomeTolerance_m = 0.003;

/// The check a kiosk makes right after it takes a board: a board's encoder counters start at the offsets
/// of its setup, so the first reply reads the home pose they name wherever the handle really is; read
/// anywhere else (offsets and park place disagree, or an encoder zero is off), the handle did not start
/// at its home pose and every position reads wrong until it is calibrated.
HomeCheck check_home_pose(const io::HaplyDevice& device, const config::Settings& s);

/// The one line that tells the operator (log, panel): where the handle read, how far from the park place,
/// and how to fix it (rest the handle there, then Calibrate in the panel or `haptic-kiosk calibrate`).
std::string home_check_line(const HomeCheck& c);

/// The ways to reach a real board, in the order they are tried, as [device] transport says: "usb" → libusb
/// CDC-ACM at each id of usb_ids that is on the bus (every id when the bus cannot be listed); "tty" →
/// serial_path, or every /dev/serial/by-id entry; "auto" → the USB ones, then the ttys.
std::vector<io::BoardCandidate> board_candidates(const config::Settings& s);

/// The first board of board_candidates(s) that answers the protocol (io::open_first_board), opened; the
/// probes of every candidate tried are appended to `probes` (may be null). Throws DeviceError (one line)
/// when none answered, naming each candidate and why, or saying that there was none.
std::unique_ptr<io::HaplyDevice> open_board(const config::Settings& s, std::vector<io::BoardProbe>* probes);

/// The device profile a USB board runs under: [device] type when it names a board ("haply", "haply-gen2"),
/// else "haply" (an "auto" kiosk, or the firmware emulator, drives a gen3 board).
std::string board_profile_type(const config::Settings& s);

/// The settings a run on a USB board uses: `s` itself when [device] type names the board, else
/// config::fit_to_profile(s, board_profile_type(s)): untouched force-budget defaults become the board's,
/// values the board's profile refuses take its own (one line each in `notes`, naming the limit).
config::Settings settings_for_board(const config::Settings& s, std::vector<std::string>* notes);

/// Lower-case name of a device status for summary.json and logs: "closed", "ok", "lost", "fault".
const char* device_status_name(DeviceStatus status) noexcept;

/// The device part of summary.json: {name, status, replies_missing, reconnects}.
struct DeviceReport {
  std::string name = "simulated pantograph";
  std::string status = "ok";      ///< status at the end of the run (before closing)
  long long replies_missing = 0;  ///< ticks whose reply did not come or came malformed (0 for the simulation)
  long long reconnects = 0;       ///< times the device came back after being lost
  long long malformed = 0;        ///< replies refused (wrong id, bad angles, bytes out of step)
};

}  // namespace hk::app
