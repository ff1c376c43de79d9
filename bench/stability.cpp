// Stability where methods fail: how stiff a wall the servo loop can render at each
// servo rate before the sampled-data loop goes unstable, and how fast a hand can move before the
// god-object proxy tunnels through a wall or misses a contact. An analysis, not a timing benchmark:
// plain main(), one JSON file with every raw number, charts by bench/plot_stability.py.
//
// Usage: bench_stability [--out docs/bench/stability.json] [--quick] [--profiles]
//   --quick: 3 rates, 10 stiffnesses, 5 + 3 speeds (~10 s on 2 cores); the full run takes ~40 s.
//   --profiles: part 3 alone.
//
// ── Part 1: largest stable wall stiffness per servo rate ─────────────────────────────────────────────
// One long straight open polyline (y = 0, x in [−0.06, 0.06] m, 241 points, Scene::build, level 1) is
// the wall. The simulated pantograph (default geometry, mass m = 0.08 kg, device damping b = 2 N·s/m,
// 16384-count encoders) is driven by the model hand, wired as app/runtime/src/simulation.cpp does it (read →
// SceneStep::update → write_force → step), with these changes, each so that the loop under test and
// not a limiter decides the outcome:
//   * the force clamps (contact and guard max_force_n) are 1e6 N and the per-motor torque limit
//     1e4 N·m: a clamp bounds the energy a wall can inject and would hide instability;
//   * the guard's start-up ramp is 0 (the ramp is a clamp too) and the query's box-test budget is off
//     (every query exact);
//   * the plant is integrated finely at every servo rate: the servo period is split into chunks of at
//     most 25 µs (the model hand's force is recomputed per chunk, so the hand is a continuous
//     spring-damper, not a second sampled-data loop) and each chunk into device substeps of ≤ 1 µs.
//     The motor force stays held over the whole servo period (zero-order hold): with the torque limit
//     out of the way, re-mapping τ = Jᵀ·F at each chunk returns the same F.
// Contact damping is 0 (the default), so the servo's velocity filter plays no part.
// Each case runs 2 s of simulated time, for servo rates {250, 500, 1000, 2000, 4000} Hz and 25
// stiffnesses from 100 N/m to 50 kN/m (log grid), under two hand behaviours:
//   push    — the hand's target sits 5 mm behind the wall (default hand: 200 N/m, 4 N·s/m, 2 N max):
//             the handle comes to rest on the wall, as a visitor leaning on an edge. Rules, after a
//             0.5 s transient (a stable loop's transient decays as exp(−(b + b_hand)/(2m)·t) =
//             exp(−37.5 t), gone by then):
//               oscillating — peak-to-peak of the true handle position normal to the wall over the last
//                 0.5 s > max(2 encoder steps normal to the wall at the contact point, 1 µm), and not at
//                 least halved from the 0.5 s before;
//               growing — E = ½·m·|v|² + ½·K·depth², taken about its mean over the last window, peaks
//                 in the last of six 0.25 s windows at more than twice the first one, and above the
//                 energy of the oscillation threshold.
//             unstable = growing, or oscillating with the proxy free at some tick of the last 0.5 s (the
//             handle bounces off the wall); limit_cycle = oscillating in permanent contact (a bounded
//             buzz, which quantisation makes); stable = neither. Only "stable" counts as stable.
//             Worst of 4 runs with start and target shifted along the wall by 0.37 mm steps, so that
//             the rest point falls at different places in the encoder lattice (whether a quantisation
//             limit cycle starts depends on that).
//   let-go  — the same push, but the hand lets go 1 mm in front of the wall: the free handle bounces
//             off, the classic wall-bounce test. A free handle can only leave a one-sided wall, so
//             instability shows as energy the wall creates: unstable when the kinetic energy at the
//             moment the wall force has ended exceeds the kinetic energy at the wall crossing. Worst of
//             4 bounces started 0.37 mm apart in height (different servo phases at the crossing). This
//             is the device alone, the setting of Colgate & Schenkel's bound.
// The limit at each rate is the first grid value that is not stable (every smaller one was), bisected
// 7 times (to 0.2 %) against the last stable one. Runs are repeated with an ideal encoder (2^24
// counts) to separate quantisation from sampling. The limits are compared with
//   * the passivity bound K < 2b/T (Colgate & Schenkel 1997, "Passivity of a class of sampled-data
//     systems: application to haptic interfaces", J. Robotic Systems 14(1); b the device damping, T the
//     servo period): sufficient for passivity of device + wall, hence for stability with any passive
//     hand, not necessary for stability with a particular hand;
//   * the exact stability limit of the linearised loop (mass m, continuous damping, continuous hand
//     spring, wall spring sampled and held), from the Jury test on the 2×2 discrete-time closed loop;
//     for small b·T/m it tends to 2·b_total/T (Gil, Avello, Rubio & Flórez 2004, "Stability analysis of
//     a 1-DOF haptic interface using the Routh–Hurwitz criterion", IEEE TCST 12(4)), so with the hand's
//     4 N·s/m added it is about three times the bound.
// Two effects the linear analysis leaves out show in the measurements: encoder quantisation, which
// makes limit cycles below the linear limit (Diolaiti, Niemeyer, Barbagli & Salisbury 2006, "Stability
// of haptic rendering: discretization, quantization, time delay, and Coulomb effects", IEEE T-RO
// 22(2)), and the one-sided wall switching on and off between samples, which leaks energy at contact
// and release (Gillespie & Cutkosky 1996, "Stable user-specific haptic rendering of the virtual wall",
// ASME IMECE DSC 58).
//
// ── Part 3: each device profile (config/device_profile.hpp) ──
// Part 1's push and let-go runs at the profile's servo rate on the profile's model (profile_device: its
// five-bar in the workspace frame, mass, damping, encoder quantisation, and one tick of delay for a USB
// board), stiffness on a log grid 100 N/m – 20 kN/m, bisected. The smaller of the two limits is what the
// profile's stiffness limit and default are chosen under; JSON "profiles".
//
// ── Part 2: tunnelling and missed contacts against hand speed ───────────────────────────────────────
// Strokes straight across a thin closed curve (an ellipse 0.2 mm wide, 60 mm long), an open straight
// wall, and into acute corners (10° and 30° wedges, polylines whose apex is a level-0 vertex), at hand
// speeds on a log grid from 0.05 to 5 m/s, rendered at level 0 (the sharpest geometry) with the
// shipped servo settings (800 N/m, 3.5 N, 1 kHz, the default box-test budget per tick, friction) but for
// two that are off here (stroke_servo_params: the level fixed at 0, and no push-through):
//   kinematic — the SceneStep alone, the handle put exactly on the stroke every 1 ms tick (no device),
//               so 5 m/s is a 5 mm jump per tick, 25 times the thin curve's width;
//   device    — the simulated pantograph (shipped parameters, substeps ≤ 1 µs), the servo run 0.6 s
//               first so the start-up force ramp is over, then a firm hand (400 N/m, 4 N·s/m relative to
//               the target's motion, 3 N max, below the wall's 3.5 N) pulls the handle after a target
//               moving along the stroke; target speeds up to 1 m/s (a 0.08 kg handle under 3 N gets no
//               faster within the workspace), measured impact speeds recorded.
// Failures, checked every tick against the level-0 polyline with an orientation predicate written here
// (independent of the library's parametric sweep intersection):
//   tunnelling — any proxy sub-move of the tick (ContactOutput::path_m[0..path_count)) crosses a
//                polyline segment, or the proxy ends the stroke on the far side (the straight line from
//                the stroke's start to the final proxy crosses the polyline an odd number of times);
//   missed contact — the handle is clearly past the wall (the line from the stroke's start to the handle
//                crosses the polyline, the handle is > 0.25 mm from it and inside the shape's "behind"
//                region, where the proxy has no way round the shape) and yet the state is Free.
// A control run with a proxy glued to the handle (a renderer blind to walls) must be counted as failing
// on every stroke, or the program stops: a checker that never fires proves nothing.
// Part 2b (JSON "auto_levels"): the kinematic strokes again with the shipped auto levels (the level from
// hand speed), push-through still off, each sub-move checked against the polylines of the level
// ids the proxy rendered that tick (auto_level_stroke).
// The god-object keeps its proxy on its side of every polyline by construction (Zilles & Salisbury
// 1995, "A constraint-based god-object method for haptic display", IROS); part 2 measures that at speeds
// where a penalty method, which pushes the handle towards the nearest wall, pops through thin walls.

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/device_profile.hpp"
#include "config/settings.hpp"
#include "haptics/scene.hpp"
#include "haptics/servo.hpp"
#include "haptics/sim_pantograph.hpp"
#include "kinematics/pantograph.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/simulation.hpp"

using namespace hk;
using json = nlohmann::ordered_json;

namespace {

// ───────────────────────────── shared: driving the simulated device finely ─────────────────────────────

constexpr double kMaxChunkS = 25e-6;   // hand force recomputed at least this often [s]
constexpr double kMaxSubstepS = 1e-6;  // device integration step at most this long [s]

/// Splits one servo period into hand chunks and device substeps no longer than the limits above.
struct Chunking {
  int chunks = 1;    // hand-force updates per servo period
  int substeps = 1;  // device substeps per chunk
  double chunk_s = 0.0;
};
Chunking chunking_for(double period_s) {
  Chunking c;
  c.chunks = static_cast<int>(std::ceil(period_s / kMaxChunkS - 1e-9));
  c.chunk_s = period_s / c.chunks;
  c.substeps = static_cast<int>(std::ceil(c.chunk_s / kMaxSubstepS - 1e-9));
  return c;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Log-spaced grid of n values from lo to hi inclusive.
std::vector<double> log_grid(double lo, double hi, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(lo * std::pow(hi / lo, n == 1 ? 0.0 : static_cast<double>(i) / (n - 1)));
  return v;
}

/// Rounds to 4 significant digits for the JSON (raw numbers stay readable; nothing here is that exact).
double sig4(double v) {
  if (v == 0.0 || !std::isfinite(v)) return v;
  const double s = std::pow(10.0, 3 - static_cast<int>(std::floor(std::log10(std::abs(v)))));
  return std::round(v * s) / s;
}

// ──────────────────────────────────────── Part 1: stiffness ────────────────────────────────────────

enum class HandMode { Push, LetGo };
const char* mode_name(HandMode m) { return m == HandMode::Push ? "push" : "let_go"; }

constexpr double kRunS = 2.0;                 // simulated time per case [s]
constexpr double kTransientS = 0.5;           // ignored by the push rules [s]
constexpr double kWindowS = 0.25;             // energy windows after the transient [s]
constexpr double kTailS = 0.5;                // oscillation window at the end [s]
constexpr double kLetGoHeightM = 0.001;       // let-go: the hand lets go this far in front of the wall [m]
constexpr int kLetGoPhases = 4;               // let-go: bounces per case, at different servo phases
constexpr int kPushPhases = 4;                // push: runs per case, rest point at different encoder phases
constexpr double kMinOscillationM = 1e-6;     // oscillation floor when the encoder is finer than this [m]
constexpr int kIdealEncoderCounts = 1 << 24;  // "ideal" encoder: 0.06 µm steps, quantisation out of the way
const Vec2 kWallStart{0.0, 0.003};            // handle starts 3 mm in front of the wall [m]
const Vec2 kHandTarget{0.0, -0.005};          // hand target 5 mm behind the wall [m]

/// What one (rate, stiffness, mode, encoder) run measured and how it was classified.
struct WallRun {
  double rate_hz = 0, stiffness_n_per_m = 0;
  HandMode mode = HandMode::Push;
  int encoder_counts = 0;
  bool stable = true;
  std::string cls = "stable";           // push: stable / limit_cycle / unstable; let-go: stable / unstable
  std::string reason;                   // which rule fired ("" when stable)
  double p2p_tail_m = 0;                // peak-to-peak normal displacement over the last 0.5 s [m]
  double p2p_before_m = 0;              // the same over the 0.5 s before [m]
  std::vector<double> window_energy_j;  // push: peak |E − E_rest| per 0.25 s window after the transient [J]
  double energy_in_j = 0;               // let-go: kinetic energy arriving at the wall [J]
  double energy_out_j = 0;              // let-go: kinetic energy when the wall force ended [J]
  int bounce_ticks = 0;                 // let-go: servo ticks from the wall crossing to the end of the wall force
  double max_depth_m = 0;               // deepest penetration behind the wall over the run [m] (let-go: the bounce)
  double max_force_n = 0;               // largest commanded force [N]
  double free_fraction_tail = 0;        // push: fraction of ticks in the last 0.5 s with the proxy free (bouncing)
  double final_depth_m = 0;             // penetration at the end [m] (negative: in front of the wall)
  std::vector<double> phase_scores;     // per phase: push p2p_tail_m [m], let-go energy out / in
};

/// Encoder resolution normal to the wall at a point: the larger y-step of one count of either motor [m].
double normal_encoder_step_m(const SimPantographParams& dp, Vec2 at_m) {
  JointAngles q;
  if (!inverse_kinematics(dp.geometry, at_m, &q)) return 0.0;
  const Mat2 J = jacobian(dp.geometry, q);
  const double step_rad = 2.0 * std::numbers::pi / dp.encoder_counts_per_rev;
  return std::max(std::abs(J.a21), std::abs(J.a22)) * step_rad;
}

/// The device a wall run drives: the simulated pantograph's parameters, and whether the servo sees the
/// handle one tick late (a USB board's reply to the previous tick's packet, as io::HaplyDevice reads it).
struct WallDevice {
  SimPantographParams params;
  int delay_ticks = 0;  ///< 0 or 1
};

/// The straight-wall scene, shared read-only by every run (and thread).
class WallBench {
 public:
  WallBench() {
    Polyline wall;
    for (int i = 0; i <= 240; ++i) wall.points_m.push_back({-0.06 + 0.12 * i / 240.0, 0.0});  // 0.5 mm spacing
    scene_ = Scene::build({wall}, config::Settings{}.haptics.max_levels);
  }

  /// The simulated pantograph of parts 1 and 2: shipped parameters, torque limit out of the way.
  static WallDevice shipped_device(int encoder_counts) {
    WallDevice d;
    d.params.max_torque_n_m = 1e4;  // far above what any stable wall asks for: the clamp must not hide instability
    d.params.encoder_counts_per_rev = encoder_counts;
    return d;
  }

  /// One classified case: the worst of several runs that differ only in phase, because a quantised,
  /// sampled loop's fate can hang on it.
  ///   push with a quantising encoder: kPushPhases runs with start and target shifted along the wall by
  ///     0.37 mm steps, so that the rest point falls at a different place in the encoder lattice (whether
  ///     a quantisation limit cycle starts depends on that); with the ideal encoder one run suffices;
  ///   let-go: kLetGoPhases bounces started 0.37 mm apart in height, so that the wall crossing falls at
  ///     a different point of the servo period (the energy a sampled one-sided wall leaks at its on and
  ///     off switching depends on that phase).
  /// Worst = unstable before limit cycle before stable, then the larger energy ratio (let-go) or
  /// peak-to-peak (push).
  WallRun run(double rate_hz, double k_n_per_m, HandMode mode, const WallDevice& device) const {
    const bool push = mode == HandMode::Push;
    const int phases =
        push ? (device.params.encoder_counts_per_rev >= kIdealEncoderCounts ? 1 : kPushPhases) : kLetGoPhases;
    auto severity = [](const WallRun& r) { return r.cls == "unstable" ? 2 : (r.cls == "limit_cycle" ? 1 : 0); };
    auto score = [push](const WallRun& r) {
      return push ? r.p2p_tail_m : (r.energy_in_j > 0.0 ? r.energy_out_j / r.energy_in_j : 0.0);
    };
    WallRun worst;
    std::vector<double> scores;
    for (int i = 0; i < phases; ++i) {
      const Vec2 shift = push ? Vec2{0.00037 * i, 0.0} : Vec2{0.0, 0.00037 * i};
      const WallRun r = run_one(rate_hz, k_n_per_m, mode, device, kWallStart + shift, kHandTarget + Vec2{shift.x, 0.0});
      scores.push_back(score(r));
      if (i == 0 || severity(r) > severity(worst) || (severity(r) == severity(worst) && score(r) > score(worst)))
        worst = r;
    }
    worst.phase_scores = scores;
    return worst;
  }

 private:
  WallRun run_one(double rate_hz, double k_n_per_m, HandMode mode, const WallDevice& device, Vec2 start_m,
                  Vec2 target_m) const {
    WallRun r;
    r.rate_hz = rate_hz;
    r.stiffness_n_per_m = k_n_per_m;
    r.mode = mode;
    r.encoder_counts = device.params.encoder_counts_per_rev;
    const double period_s = 1.0 / rate_hz;
    const Chunking ch = chunking_for(period_s);
    SimPantographParams dp = device.params;
    dp.substeps = ch.substeps;
    const double step_normal_m = normal_encoder_step_m(dp, {0.0, 0.0});
    SimulatedPantograph dev(dp, start_m);
    dev.open();
    const ModelHandParams hand;  // defaults: 200 N/m, 4 N·s/m, 2 N
    ServoParams sp;
    sp.period_s = period_s;
    sp.level = config::Settings{}.haptics.level;
    sp.query_box_budget = 0;  // no box-test limit: every query exact
    sp.contact.stiffness_n_per_m = k_n_per_m;
    sp.contact.damping_n_s_per_m = 0.0;
    sp.contact.max_force_n = 1e6;
    sp.guard.max_force_n = 1e6;
    sp.guard.ramp_s = 0.0;
    SceneStep servo(scene_, sp);
    servo.start(dev.read().handle_m);

    const long n_ticks = std::lround(kRunS / period_s);
    // Samples at every chunk end: time, normal position, energy.
    std::vector<double> t_s, y_m, e_j;
    t_s.reserve(static_cast<std::size_t>(n_ticks * ch.chunks));
    y_m.reserve(t_s.capacity());
    e_j.reserve(t_s.capacity());
    const double mass_kg = dp.handle_mass_kg;
    auto kinetic = [&]() { return 0.5 * mass_kg * length_sq(dev.velocity_m_per_s()); };
    auto energy = [&]() {
      const double depth = std::max(0.0, -dev.true_position_m().y);
      return kinetic() + 0.5 * k_n_per_m * depth * depth;
    };
    bool let_go = false, entered = false, bounce_done = false, touched = false;
    long entry_tick = 0, done_tick = 0;
    long tail_ticks = 0, tail_free = 0;
    const long tail_start_tick = n_ticks - std::lround(kTailS / period_s);
    ServoOutput so;
    DeviceSample older = dev.read();  // the sample of the tick before, for a device one tick late
    for (long k = 0; k < n_ticks; ++k) {
      ServoInput in;
      const DeviceSample now = dev.read();
      in.sample = device.delay_ticks > 0 ? older : now;
      older = now;
      servo.update(in, so);
      dev.write_force(so.force_n);
      r.max_force_n = std::max(r.max_force_n, length(so.force_n));
      const bool in_contact = so.contact.state != ContactState::Free;
      if (k >= tail_start_tick) {
        ++tail_ticks;
        tail_free += !in_contact;
      }
      if (mode == HandMode::LetGo && entered && !bounce_done) {
        touched = touched || in_contact;
        // The bounce is over when the servo has seen the contact and now commands no force: from here
        // on only the device's damping acts, so this kinetic energy is all the wall gave back.
        if (touched && !in_contact && so.force_n == Vec2{} && dev.true_position_m().y > 0.0) {
          bounce_done = true;
          r.energy_out_j = kinetic();
          r.bounce_ticks = static_cast<int>(k - entry_tick);
          done_tick = k;
        }
      }
      // Nothing more can happen to a free handle drifting away from a one-sided wall.
      if (bounce_done && static_cast<double>(k - done_tick) * period_s > 0.02) break;
      for (int c = 0; c < ch.chunks; ++c) {
        if (mode == HandMode::LetGo && !let_go && dev.true_position_m().y < kLetGoHeightM) let_go = true;
        const Vec2 f_hand =
            let_go ? Vec2{} : model_hand_force(hand, target_m, dev.true_position_m(), dev.velocity_m_per_s());
        const double ke_before = kinetic();
        const bool outside_before = dev.true_position_m().y > 0.0;
        dev.step(ch.chunk_s, f_hand);
        if (mode == HandMode::LetGo && !entered && outside_before && dev.true_position_m().y <= 0.0) {
          entered = true;  // free flight up to here: the energy brought to the wall is kinetic
          entry_tick = k;
          r.energy_in_j = ke_before;
        }
        t_s.push_back(static_cast<double>(k) * period_s + (c + 1) * ch.chunk_s);
        y_m.push_back(dev.true_position_m().y);
        e_j.push_back(energy());
        r.max_depth_m = std::max(r.max_depth_m, -y_m.back());
      }
    }
    r.final_depth_m = -dev.true_position_m().y;
    r.free_fraction_tail = tail_ticks ? static_cast<double>(tail_free) / tail_ticks : 0.0;

    // Peak-to-peak of the normal position in [a, b].
    auto p2p = [&](double a, double b) {
      double lo = 1e300, hi = -1e300;
      for (std::size_t i = 0; i < t_s.size(); ++i) {
        if (t_s[i] >= a && t_s[i] <= b + 1e-12) {
          lo = std::min(lo, y_m[i]);
          hi = std::max(hi, y_m[i]);
        }
      }
      return hi >= lo ? hi - lo : 0.0;
    };
    r.p2p_tail_m = p2p(kRunS - kTailS, kRunS);
    r.p2p_before_m = p2p(kRunS - 2 * kTailS, kRunS - kTailS);

    if (mode == HandMode::Push) {
      // Oscillation energy: E about its mean over the last window (the resting handle stores ½·K·depth²
      // in the wall; that is not oscillation). Peak per window.
      double mean_tail = 0;
      int n_tail = 0;
      for (std::size_t i = 0; i < t_s.size(); ++i) {
        if (t_s[i] >= kRunS - kWindowS) {
          mean_tail += e_j[i];
          ++n_tail;
        }
      }
      mean_tail = n_tail ? mean_tail / n_tail : 0.0;
      const int windows = static_cast<int>(std::lround((kRunS - kTransientS) / kWindowS));
      r.window_energy_j.assign(static_cast<std::size_t>(windows), 0.0);
      for (std::size_t i = 0; i < t_s.size(); ++i) {
        if (t_s[i] < kTransientS) continue;
        const auto w =
            static_cast<std::size_t>(std::min(windows - 1, static_cast<int>((t_s[i] - kTransientS) / kWindowS)));
        r.window_energy_j[w] = std::max(r.window_energy_j[w], std::abs(e_j[i] - mean_tail));
      }
      const double threshold_m = std::max(2.0 * step_normal_m, kMinOscillationM);
      // The energy of an oscillation of that peak-to-peak on the wall and hand springs.
      const double amp_m = 0.5 * threshold_m;
      const double threshold_j = 0.5 * (k_n_per_m + hand.stiffness_n_per_m) * amp_m * amp_m;
      const bool oscillating = r.p2p_tail_m > threshold_m && r.p2p_tail_m > 0.5 * r.p2p_before_m;
      const bool growing =
          r.window_energy_j.back() > 2.0 * r.window_energy_j.front() && r.window_energy_j.back() > threshold_j;
      if (growing) {
        r.cls = "unstable";
        r.reason = "energy growth";
      } else if (oscillating && r.free_fraction_tail > 0.0) {
        r.cls = "unstable";
        r.reason = "sustained oscillation, bouncing off the wall";
      } else if (oscillating) {
        r.cls = "limit_cycle";
        r.reason = "sustained oscillation in contact";
      }
    } else {
      if (!entered || !bounce_done) {
        r.cls = "unstable";
        r.reason = entered ? "did not leave the wall" : "never reached the wall";
      } else if (r.energy_out_j > r.energy_in_j) {
        r.cls = "unstable";
        r.reason = "energy created by the wall";
      }
    }
    r.stable = r.cls == "stable";
    return r;
  }

  Scene scene_;
};

// ── Linearised sampled-data loop: exact stability limit by the Jury test ──
// Plant: m·ẍ = −b·ẋ − k_h·x + u, u held over each period at −K·x(t_k) (x = position normal to the wall,
// about the resting point). Discretised exactly (here by RK4 with 4000 steps per period, exact to
// rounding for this linear plant): [x; v]_{k+1} = Φ·[x; v]_k + Γ·u_k. The closed loop M = Φ − Γ·K·[1 0]
// is stable iff |det M| < 1 and |tr M| < 1 + det M (Jury's conditions for a second-order polynomial).
struct Discrete2 {
  double phi[2][2];
  double gam[2];
};
Discrete2 discretise(double m_kg, double b_n_s_per_m, double kh_n_per_m, double period_s) {
  auto deriv = [&](const std::array<double, 2>& s, double u) {
    return std::array<double, 2>{s[1], (-b_n_s_per_m * s[1] - kh_n_per_m * s[0] + u) / m_kg};
  };
  auto integrate = [&](std::array<double, 2> s, double u) {
    const int n = 4000;
    const double h = period_s / n;
    for (int i = 0; i < n; ++i) {
      const auto k1 = deriv(s, u);
      const auto k2 = deriv({s[0] + 0.5 * h * k1[0], s[1] + 0.5 * h * k1[1]}, u);
      const auto k3 = deriv({s[0] + 0.5 * h * k2[0], s[1] + 0.5 * h * k2[1]}, u);
      const auto k4 = deriv({s[0] + h * k3[0], s[1] + h * k3[1]}, u);
      s[0] += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]);
      s[1] += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]);
    }
    return s;
  };
  Discrete2 d;
  const auto c0 = integrate({1, 0}, 0), c1 = integrate({0, 1}, 0), g = integrate({0, 0}, 1);
  d.phi[0][0] = c0[0];
  d.phi[1][0] = c0[1];
  d.phi[0][1] = c1[0];
  d.phi[1][1] = c1[1];
  d.gam[0] = g[0];
  d.gam[1] = g[1];
  return d;
}
bool jury_stable(const Discrete2& d, double k_n_per_m) {
  const double m00 = d.phi[0][0] - d.gam[0] * k_n_per_m, m01 = d.phi[0][1];
  const double m10 = d.phi[1][0] - d.gam[1] * k_n_per_m, m11 = d.phi[1][1];
  const double tr = m00 + m11, det = m00 * m11 - m01 * m10;
  return std::abs(det) < 1.0 && std::abs(tr) < 1.0 + det;
}
/// Largest K [N/m] for which the linearised loop is stable (bisection in log K between 1 and 1e8).
double linear_limit_n_per_m(double m_kg, double b_n_s_per_m, double kh_n_per_m, double period_s) {
  const Discrete2 d = discretise(m_kg, b_n_s_per_m, kh_n_per_m, period_s);
  double lo = 1.0, hi = 1e8;
  if (!jury_stable(d, lo)) return 0.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = std::sqrt(lo * hi);
    (jury_stable(d, mid) ? lo : hi) = mid;
  }
  return lo;
}

json wall_run_json(const WallRun& r) {
  json j;
  j["stiffness_n_per_m"] = sig4(r.stiffness_n_per_m);
  j["stable"] = r.stable;
  j["class"] = r.cls;
  j["reason"] = r.reason;
  j["max_depth_m"] = sig4(r.max_depth_m);
  j["max_force_n"] = sig4(r.max_force_n);
  if (r.mode == HandMode::Push) {
    j["p2p_tail_m"] = sig4(r.p2p_tail_m);
    j["p2p_before_m"] = sig4(r.p2p_before_m);
    j["final_depth_m"] = sig4(r.final_depth_m);
    j["free_fraction_tail"] = sig4(r.free_fraction_tail);
    json ph = json::array();
    for (double x : r.phase_scores) ph.push_back(sig4(x));
    j["phase_p2p_tail_m"] = ph;
    json w = json::array();
    for (double e : r.window_energy_j) w.push_back(sig4(e));
    j["window_energy_j"] = w;
  } else {
    j["energy_in_j"] = sig4(r.energy_in_j);
    j["energy_out_j"] = sig4(r.energy_out_j);
    j["energy_ratio"] = r.energy_in_j > 0 ? sig4(r.energy_out_j / r.energy_in_j) : 0.0;
    j["bounce_ticks"] = r.bounce_ticks;
    json ph = json::array();
    for (double x : r.phase_scores) ph.push_back(sig4(x));
    j["phase_energy_ratios"] = ph;
  }
  return j;
}

/// Runs f(i) for i in [0, n) on all hardware threads. The runs are independent and deterministic.
void parallel_for(std::size_t n, const std::function<void(std::size_t)>& f) {
  const unsigned threads =
      std::max(1u, std::min<unsigned>(std::thread::hardware_concurrency(), static_cast<unsigned>(n)));
  std::atomic<std::size_t> next{0};
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      for (std::size_t i = next++; i < n; i = next++) f(i);
    });
  }
  for (auto& th : pool) th.join();
}

/// One stiffness sweep: a (rate, hand mode, encoder) on the grid, then bisection at the boundary.
struct Series {
  double rate_hz = 0;
  HandMode mode = HandMode::Push;
  WallDevice device;
  json result;
};

void run_series(const WallBench& bench, const std::vector<double>& grid, int refine_steps, Series& s) {
  // "Stable from below": the boundary is the first grid value that is not stable; every smaller one was.
  // Quantisation can make the map ragged (a stable value above a limit-cycle one); those are reported
  // as non_monotonic, never taken as the limit.
  json cases = json::array();
  double stable_below = 0.0, first_not_stable = 0.0, largest_stable_anywhere = 0.0;
  double no_divergence_below = 0.0;  // the same, counting limit cycles as acceptable
  bool seen_not_stable = false, seen_divergent = false, islands = false;
  for (double k : grid) {
    const WallRun r = bench.run(s.rate_hz, k, s.mode, s.device);
    cases.push_back(wall_run_json(r));
    if (r.stable) {
      largest_stable_anywhere = k;
      if (seen_not_stable)
        islands = true;
      else
        stable_below = k;
    } else if (!seen_not_stable) {
      seen_not_stable = true;
      first_not_stable = k;
    }
    if (r.cls == "unstable")
      seen_divergent = true;
    else if (!seen_divergent)
      no_divergence_below = k;
  }
  // Bisection (in log K) between the last value of the stable run and the first value that is not.
  double lo = stable_below, hi = first_not_stable;
  json refine = json::array();
  if (lo > 0.0 && hi > 0.0) {
    for (int i = 0; i < refine_steps; ++i) {
      const double mid = std::sqrt(lo * hi);
      const WallRun r = bench.run(s.rate_hz, mid, s.mode, s.device);
      refine.push_back(wall_run_json(r));
      (r.stable ? lo : hi) = mid;
    }
  }
  const double bound = 2.0 * s.device.params.handle_damping_n_s_per_m * s.rate_hz;
  json& j = s.result;
  j["rate_hz"] = s.rate_hz;
  j["mode"] = mode_name(s.mode);
  j["encoder_counts_per_rev"] = s.device.params.encoder_counts_per_rev;
  j["delay_ticks"] = s.device.delay_ticks;
  j["largest_stable_grid_n_per_m"] = sig4(stable_below);      // every grid value up to it stable
  j["first_unstable_grid_n_per_m"] = sig4(first_not_stable);  // first grid value not stable
  j["largest_stable_n_per_m"] = sig4(lo);                     // after bisection
  j["smallest_unstable_n_per_m"] = hi > 0 ? json(sig4(hi)) : json(nullptr);
  j["largest_stable_anywhere_grid_n_per_m"] = sig4(largest_stable_anywhere);
  j["largest_without_divergence_grid_n_per_m"] = sig4(no_divergence_below);  // push: limit cycles accepted
  j["non_monotonic"] = islands;
  j["ratio_to_passivity_bound"] = sig4(lo / bound);
  j["grid"] = cases;
  j["refinement"] = refine;
}

json run_part1(bool quick) {
  const std::vector<double> rates_hz =
      quick ? std::vector<double>{250, 1000, 4000} : std::vector<double>{250, 500, 1000, 2000, 4000};
  const std::vector<double> grid = log_grid(100.0, 50000.0, quick ? 10 : 25);
  const int refine_steps = quick ? 3 : 7;
  const int default_counts = SimPantographParams{}.encoder_counts_per_rev;
  const WallBench bench;
  const SimPantographParams dp = WallBench::shipped_device(default_counts).params;
  const ModelHandParams hand;
  json out;
  out["wall"] = "open straight polyline y = 0, x in [-0.06, 0.06] m, 241 points, rendered at level " +
                std::to_string(config::Settings{}.haptics.level);
  out["device"] = {{"handle_mass_kg", dp.handle_mass_kg},
                   {"handle_damping_n_s_per_m", dp.handle_damping_n_s_per_m},
                   {"encoder_counts_per_rev", default_counts},
                   {"ideal_encoder_counts_per_rev", kIdealEncoderCounts},
                   {"encoder_step_normal_m", sig4(normal_encoder_step_m(dp, {0.0, 0.0}))},
                   {"max_torque_n_m", dp.max_torque_n_m},
                   {"max_chunk_s", kMaxChunkS},
                   {"max_substep_s", kMaxSubstepS}};
  out["hand"] = {{"stiffness_n_per_m", hand.stiffness_n_per_m},
                 {"damping_n_s_per_m", hand.damping_n_s_per_m},
                 {"max_force_n", hand.max_force_n},
                 {"start_m", {kWallStart.x, kWallStart.y}},
                 {"target_m", {kHandTarget.x, kHandTarget.y}},
                 {"let_go_height_m", kLetGoHeightM}};
  out["servo"] = {
      {"contact_damping_n_s_per_m", 0.0}, {"max_force_n", 1e6}, {"force_ramp_s", 0.0}, {"query_box_budget", 0}};
  out["run_s"] = kRunS;
  out["transient_s"] = kTransientS;
  out["rules"] = {
      {"push",
       "oscillating: p2p normal displacement over the last 0.5 s > max(2 encoder steps, 1 um) and > half the p2p of "
       "the 0.5 s "
       "before; growing: peak |E - E_rest| in the last 0.25 s window > 2x that of the first window after 0.5 s and > "
       "the "
       "energy of the oscillation threshold; E = 0.5 m |v|^2 + 0.5 K depth^2. unstable = growing, or oscillating with "
       "the "
       "proxy free at some tick of the last 0.5 s (bouncing); limit_cycle = oscillating in permanent contact; stable = "
       "neither. Only stable counts as stable. Worst of 4 runs shifted 0.37 mm along the wall (encoder phases; 1 run "
       "with the "
       "ideal encoder). Limit: first grid value not stable (all below stable), bisected against the last stable one."},
      {"let_go",
       "the hand lets go 1 mm in front of the wall; unstable if, in any of 4 bounces started 0.37 mm apart (different "
       "servo "
       "phases at the crossing), the kinetic energy when the wall force has ended exceeds the kinetic energy at the "
       "wall "
       "crossing (the wall created energy); the worst bounce is recorded"}};
  out["stiffness_grid_n_per_m"] = json::array();
  for (double k : grid) out["stiffness_grid_n_per_m"].push_back(sig4(k));

  json rates = json::array();
  for (double rate : rates_hz) {
    const double period_s = 1.0 / rate;
    json jr;
    jr["rate_hz"] = rate;
    jr["period_s"] = period_s;
    jr["passivity_bound_n_per_m"] = sig4(2.0 * dp.handle_damping_n_s_per_m / period_s);
    // Linear predictions: push = device + hand (continuous damping b + b_hand, hand spring);
    // let-go = the device alone.
    jr["linear_limit_push_n_per_m"] = sig4(linear_limit_n_per_m(
        dp.handle_mass_kg, dp.handle_damping_n_s_per_m + hand.damping_n_s_per_m, hand.stiffness_n_per_m, period_s));
    jr["linear_limit_let_go_n_per_m"] =
        sig4(linear_limit_n_per_m(dp.handle_mass_kg, dp.handle_damping_n_s_per_m, 0.0, period_s));
    rates.push_back(jr);
  }
  out["rates"] = rates;

  std::vector<Series> series;
  for (int counts : {default_counts, kIdealEncoderCounts}) {
    for (double rate : rates_hz) {
      for (HandMode mode : {HandMode::Push, HandMode::LetGo})
        series.push_back(Series{rate, mode, WallBench::shipped_device(counts), json()});
    }
  }
  parallel_for(series.size(), [&](std::size_t i) { run_series(bench, grid, refine_steps, series[i]); });
  json js = json::array();
  for (const Series& s : series) {
    js.push_back(s.result);
    std::fprintf(stderr, "  %5.0f Hz %-6s encoder %8d: largest stable %7.0f N/m (2b/T %6.0f)%s\n", s.rate_hz,
                 mode_name(s.mode), s.device.params.encoder_counts_per_rev,
                 s.result["largest_stable_n_per_m"].get<double>(), 2.0 * dp.handle_damping_n_s_per_m * s.rate_hz,
                 s.result["non_monotonic"].get<bool>() ? "  [non-monotonic]" : "");
  }
  out["series"] = js;
  return out;
}

// ──────────────────────────────────────── Part 2: tunnelling ────────────────────────────────────────

/// Sign of the turn a → b → c: +1 left, −1 right, 0 collinear. Plain doubles suffice: the proxy keeps a
/// 1 µm skin from every wall, so the values that matter are ~1e-10 m², far above rounding (~1e-20 m²).
int orient(Vec2 a, Vec2 b, Vec2 c) {
  const double v = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  return v > 0.0 ? 1 : (v < 0.0 ? -1 : 0);
}

/// True when the move p → q crosses segment a–b: p and q strictly on opposite sides of the segment's
/// line, and the crossing point within the closed segment (a move through a vertex crosses). A move that
/// starts or ends exactly on the line does not count (a proxy resting on a wall is not across it); a
/// crossing made in two such steps would still show as the proxy ending on the far side.
bool crosses(Vec2 p, Vec2 q, Vec2 a, Vec2 b) {
  const int sp = orient(a, b, p), sq = orient(a, b, q);
  if (sp == 0 || sq == 0 || sp == sq) return false;
  const int sa = orient(p, q, a), sb = orient(p, q, b);
  return sa * sb <= 0;
}

/// The level-0 segments of a scene, flat, for the brute-force predicate.
struct Segments {
  std::vector<std::pair<Vec2, Vec2>> segs;
  int crossings(Vec2 p, Vec2 q) const {
    int n = 0;
    // Quick reject on the move's bounding box; the scenes are small, brute force is fine.
    const double x0 = std::min(p.x, q.x), x1 = std::max(p.x, q.x), y0 = std::min(p.y, q.y), y1 = std::max(p.y, q.y);
    for (const auto& [a, b] : segs) {
      if (std::max(a.x, b.x) < x0 || std::min(a.x, b.x) > x1 || std::max(a.y, b.y) < y0 || std::min(a.y, b.y) > y1)
        continue;
      n += crosses(p, q, a, b);
    }
    return n;
  }
  double distance(Vec2 p) const {
    double d = 1e300;
    for (const auto& [a, b] : segs) d = std::min(d, distance_to_segment(p, a, b));
    return d;
  }
};

Segments level_segments(const Scene& sc, int level) {
  Segments s;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    const int l = sc.clamp_level(c, level);
    for (std::uint32_t k = 0; k < ci.segment_count[l]; ++k) {
      Vec2 a, b;
      sc.segment(SegmentRef{static_cast<std::int32_t>(c), l, static_cast<std::int32_t>(k)}, &a, &b);
      s.segs.push_back({a, b});
    }
  }
  return s;
}

struct Stroke {
  Vec2 start_m, end_m;
};

/// One test shape with the strokes across or into it.
struct StrokeScene {
  std::string name;
  std::string description;
  double thickness_m = 0.0;          // thin curve: its width [m]
  double wedge_deg = 0.0;            // wedge: its opening angle [deg]
  double apex_gap_m = -1.0;          // wedge: distance from the apex to the nearest level-0 point [m]
  std::function<bool(Vec2)> behind;  // where a handle is unambiguously behind the shape (see make_stroke_scenes)
  Scene scene;
  Segments segs;
  std::vector<Segments> level_segs;    // every level id's segments (each curve at Scene::clamp_level), for part 2b
  std::vector<Stroke> strokes;         // kinematic strokes
  std::vector<Stroke> device_strokes;  // device strokes (a longer run-up where the shape allows it)
};

constexpr int kTunnelLevel = 0;
constexpr double kClearlyPastM = 0.25e-3;  // "clearly past the wall": farther than this from it [m]

/// A stroke along direction angle alpha through aim point c: `before_m` before it, `after_m` after it.
Stroke stroke_through(Vec2 c, double alpha_rad, double before_m, double after_m) {
  const Vec2 d{std::cos(alpha_rad), std::sin(alpha_rad)};
  return {c - before_m * d, c + after_m * d};
}

std::vector<StrokeScene> make_stroke_scenes() {
  const int max_levels = config::Settings{}.haptics.max_levels;
  std::vector<StrokeScene> out;
  // `behind` says where a handle that has crossed the shape is unambiguously behind it: there the proxy
  // has no way round the shape, so it must be in contact. Outside it (say, a handle carried past the tip
  // of the thin ellipse by its momentum) the proxy may rightly go round, and the missed-contact rule
  // does not judge. Every stroke must end inside it.
  auto finish = [&](StrokeScene s, const std::vector<Polyline>& curves, const std::function<bool(Vec2)>& behind) {
    s.behind = behind;
    s.scene = Scene::build(curves, max_levels);
    s.segs = level_segments(s.scene, kTunnelLevel);
    for (int l = 0; l < max_levels; ++l) s.level_segs.push_back(level_segments(s.scene, l));
    for (const auto* v : {&s.strokes, &s.device_strokes}) {
      for (const Stroke& st : *v) {
        if (!behind(st.end_m) || s.segs.crossings(st.start_m, st.end_m) == 0) {
          std::fprintf(stderr, "bench_stability: stroke of %s does not end behind the shape\n", s.name.c_str());
          std::exit(3);
        }
      }
    }
    out.push_back(std::move(s));
  };
  const double deg = std::numbers::pi / 180.0;
  // Aim points and angles avoid exact symmetry (a stroke through a vertex exactly is a tie, not a test).
  // Wall and thin curve: 30 mm run-up (45 mm with the device, which must accelerate), 12 mm past the
  // wall, so that the handle's foot on the wall stays well inside the wall's span.
  {
    StrokeScene s;
    s.name = "straight_wall";
    s.description = "open straight polyline x = 0, y in [-0.04, 0.04] m, 161 points";
    Polyline p;
    for (int i = 0; i <= 160; ++i) p.points_m.push_back({0.0, -0.04 + 0.08 * i / 160.0});
    for (double y0 : {-0.0051, 0.00023, 0.0063}) {
      for (double a : {0.0, 25.0, -40.0}) {
        s.strokes.push_back(stroke_through({0.0, y0}, a * deg, 0.03, 0.012));
        s.device_strokes.push_back(stroke_through({0.0, y0}, a * deg, 0.045, 0.012));
      }
    }
    finish(std::move(s), {p}, [](Vec2 q) { return q.x > 0.0 && std::abs(q.y) < 0.036; });
  }
  {
    StrokeScene s;
    s.name = "thin_closed";
    s.description = "closed ellipse centred at the origin, 0.2 mm wide (x) by 60 mm tall (y), 512 points";
    s.thickness_m = 0.0002;
    Polyline p;
    p.closed = true;
    for (int i = 0; i < 512; ++i) {
      const double t = 2.0 * std::numbers::pi * i / 512.0;
      p.points_m.push_back({0.0001 * std::cos(t), 0.03 * std::sin(t)});
    }
    for (double y0 : {-0.0051, 0.00023, 0.0063}) {
      for (double a : {0.0, 25.0, -40.0}) {
        s.strokes.push_back(stroke_through({0.0, y0}, a * deg, 0.03, 0.012));
        s.device_strokes.push_back(stroke_through({0.0, y0}, a * deg, 0.045, 0.012));
      }
    }
    finish(std::move(s), {p}, [](Vec2 q) { return q.x > 0.0001 && std::abs(q.y) < 0.026; });
  }
  for (double wedge_deg : {30.0, 10.0}) {
    StrokeScene s;
    s.name = "wedge_" + std::to_string(static_cast<int>(wedge_deg));
    s.description = std::to_string(static_cast<int>(wedge_deg)) +
                    "-degree wedge: apex (0.01, 0) m, two 50 mm arms opening towards -x, 201 points; strokes from "
                    "inside into the apex";
    s.wedge_deg = wedge_deg;
    const Vec2 apex{0.01, 0.0};
    const double half = 0.5 * wedge_deg * deg;
    const Vec2 arm_a{-std::cos(half), std::sin(half)}, arm_b{-std::cos(half), -std::sin(half)};
    Polyline p;
    for (int i = 100; i >= 1; --i) p.points_m.push_back(apex + (0.05 * i / 100.0) * arm_a);
    p.points_m.push_back(apex);
    for (int i = 1; i <= 100; ++i) p.points_m.push_back(apex + (0.05 * i / 100.0) * arm_b);
    // Aim 1 mm short of the apex, slightly off the bisector; tilts of ±40 % of the half-angle keep the
    // start inside the wedge, so every stroke is driven into the corner from its concave side and ends
    // 29 mm beyond the apex, outside the wedge, where the arms (50 mm) leave the proxy no way round.
    const Vec2 aim = apex + Vec2{-0.001, 0.000037};
    for (double frac : {0.0, 0.4, -0.4}) {
      s.strokes.push_back(stroke_through(aim, frac * half, 0.03, 0.03));
      s.device_strokes.push_back(stroke_through(aim, frac * half, 0.03, 0.03));  // the arms bound the run-up
    }
    // Behind = outside the wedge and within 45 mm of the apex (the arms are 50 mm long).
    finish(std::move(s), {p}, [apex, arm_a, arm_b](Vec2 q) {
      const bool inside = cross(arm_a, q - apex) > 0.0 && cross(arm_b, q - apex) < 0.0;
      return !inside && distance(q, apex) < 0.045;
    });
    // The corner must survive the arc-length resampling, or the test is of a rounded wedge.
    StrokeScene& w = out.back();
    for (int i = 0; i < static_cast<int>(w.scene.curve(0).point_count[kTunnelLevel]); ++i) {
      const double d = distance(w.scene.points(0, kTunnelLevel)[i], apex);
      w.apex_gap_m = w.apex_gap_m < 0.0 ? d : std::min(w.apex_gap_m, d);
    }
  }
  return out;
}

/// Failure counts of a set of strokes at one speed.
struct StrokeTally {
  int strokes = 0;
  int ticks = 0;
  int tunnel_ticks = 0;       // ticks with a proxy sub-move crossing the polyline
  int strokes_tunnelled = 0;  // strokes with any tunnel tick or ending on the far side
  int strokes_far_side = 0;   // strokes whose final proxy is on the far side
  int missed_ticks = 0;       // ticks with the handle clearly past the wall and the state Free
  int unjudged_ticks = 0;     // ticks with the handle across the shape but outside its `behind` region
  int strokes_missed = 0;
  int contact_ticks = 0;  // ticks in Edge or Vertex
  int vertex_ticks = 0;
  int iteration_limit_ticks = 0;  // ticks whose move budget ran out (the proxy stays valid, but it is a sign)
  int query_budget_ticks = 0;     // ticks whose collision queries ran out of the box-test budget
  double max_handle_step_m = 0;   // the largest handle jump in one tick [m]
  double impact_speed_sum = 0;    // device: sum of handle speeds at first contact [m/s]
  int impacts = 0;
  double max_depth_m = 0;  // largest handle distance past the wall while in contact [m]
  void add(const StrokeTally& o) {
    strokes += o.strokes;
    ticks += o.ticks;
    tunnel_ticks += o.tunnel_ticks;
    strokes_tunnelled += o.strokes_tunnelled;
    strokes_far_side += o.strokes_far_side;
    missed_ticks += o.missed_ticks;
    strokes_missed += o.strokes_missed;
    unjudged_ticks += o.unjudged_ticks;
    contact_ticks += o.contact_ticks;
    vertex_ticks += o.vertex_ticks;
    iteration_limit_ticks += o.iteration_limit_ticks;
    query_budget_ticks += o.query_budget_ticks;
    max_handle_step_m = std::max(max_handle_step_m, o.max_handle_step_m);
    impact_speed_sum += o.impact_speed_sum;
    impacts += o.impacts;
    max_depth_m = std::max(max_depth_m, o.max_depth_m);
  }
  bool failed() const { return strokes_tunnelled > 0 || strokes_missed > 0; }
};

/// Checks one tick's servo output against the polyline. `start` is the stroke's start (free side).
struct TickChecker {
  TickChecker(const StrokeScene& sc, Vec2 start_m) : segs(&sc.segs), behind(&sc.behind), start(start_m) {}
  const Segments* segs;
  const std::function<bool(Vec2)>* behind;
  Vec2 start;
  bool any_tunnel = false, any_missed = false, had_contact = false;
  Vec2 prev_handle;
  bool first = true;
  void check(Vec2 handle, const ServoOutput& so, StrokeTally& t) {
    ++t.ticks;
    bool tunnel = false;
    for (int i = 0; i + 1 < so.contact.path_count; ++i) {
      if (segs->crossings(so.contact.path_m[i], so.contact.path_m[i + 1]) > 0) tunnel = true;
    }
    if (tunnel) {
      ++t.tunnel_ticks;
      any_tunnel = true;
    }
    const bool in_contact = so.contact.state != ContactState::Free;
    t.contact_ticks += in_contact;
    t.vertex_ticks += so.contact.state == ContactState::Vertex;
    t.iteration_limit_ticks += (so.contact.events & kEventIterationLimit) != 0;
    t.query_budget_ticks += (so.contact.events & kEventQueryBudget) != 0;
    const bool crossed = segs->crossings(start, handle) > 0;
    const bool past = crossed && (*behind)(handle);
    t.unjudged_ticks += crossed && !past;
    const double dist = past ? segs->distance(handle) : 0.0;
    if (past && in_contact) t.max_depth_m = std::max(t.max_depth_m, dist);
    if (past && dist > kClearlyPastM && !in_contact) {
      ++t.missed_ticks;
      any_missed = true;
    }
    if (!first) t.max_handle_step_m = std::max(t.max_handle_step_m, distance(prev_handle, handle));
    prev_handle = handle;
    first = false;
    had_contact = had_contact || in_contact;
  }
  void finish(Vec2 final_proxy, StrokeTally& t) {
    ++t.strokes;
    const bool far = (segs->crossings(start, final_proxy) % 2) == 1;
    t.strokes_far_side += far;
    t.strokes_tunnelled += (any_tunnel || far);
    t.strokes_missed += any_missed;
  }
};

/// The shipped servo settings, but for two that would make the level-0 checker judge something else:
/// the level is fixed at kTunnelLevel (the shipped level_mode "auto" picks a level from hand speed, and a
/// coarser level's wall lies up to its error away from the level-0 polyline, across it at a thin curve or
/// a wedge's apex), and push-through is off (the shipped pop_force_n lets a proxy pressed that hard for
/// pop_hold_s through a wall on purpose, kEventPopThrough: a slow stroke that ends 29 mm past a wedge's apex
/// presses that long). Both are on by default, so part 2 sets them off itself, so it measures what it says: whether the
/// proxy ever crosses the wall it renders. auto_levels: the shipped level_mode "auto" instead (part 2b), push-through
/// still off.
ServoParams stroke_servo_params(bool auto_levels = false) {
  config::Settings s;
  if (!auto_levels) {
    s.haptics.level_mode = "fixed";
    s.haptics.level = kTunnelLevel;
  }
  s.haptics.pop_force_n = 0.0;
  return app::servo_params_from(s);
}

/// The handle of a kinematic stroke: moved along the stroke at speed_m_per_s, one sample per servo period,
/// then parked at its end for kDwellTicks (the proxy must stay put with the handle parked past the wall).
struct KinematicPath {
  static constexpr long kDwellTicks = 30;
  KinematicPath(const Stroke& st, double speed, double period)
      : start(st.start_m),
        len(distance(st.start_m, st.end_m)),
        dir((1.0 / len) * (st.end_m - st.start_m)),
        speed_m_per_s(speed),
        period_s(period),
        move_ticks(static_cast<long>(std::ceil(len / (speed * period)))) {}
  long ticks() const { return move_ticks + kDwellTicks; }
  /// The device sample of tick k, k in [1, ticks()].
  ServoInput input(long k) const {
    ServoInput in;
    in.sample.handle_m = start + std::min(len, static_cast<double>(k) * speed_m_per_s * period_s) * dir;
    in.sample.status = DeviceStatus::Ok;
    in.sample.time_ns = static_cast<std::int64_t>(k * 1000000);
    return in;
  }
  Vec2 start;
  double len;
  Vec2 dir;
  double speed_m_per_s;
  double period_s;
  long move_ticks;
};

/// Part 2b's tally: the kinematic strokes with the shipped auto levels.
struct AutoLevelTally {
  int strokes = 0;
  int ticks = 0;
  int tunnel_ticks = 0;       // ticks with a proxy sub-move crossing a polyline of a level id rendered that tick
  int strokes_tunnelled = 0;  // strokes with a tunnel tick, or ending on the far side of the final level's polyline
  int contact_ticks = 0;
  int level_changes = 0;
  double level_sum = 0.0;  // sum over ticks of the level in use (for the mean)
  void add(const AutoLevelTally& o) {
    strokes += o.strokes;
    ticks += o.ticks;
    tunnel_ticks += o.tunnel_ticks;
    strokes_tunnelled += o.strokes_tunnelled;
    contact_ticks += o.contact_ticks;
    level_changes += o.level_changes;
    level_sum += o.level_sum;
  }
};

/// Part 2b: a kinematic stroke (as kinematic_stroke) with the shipped auto levels, push-through off. Each
/// tick's proxy sub-moves are checked against the polylines of the level ids the proxy rendered that tick:
/// the level in use (ServoOutput::level) and, while a change is in transition, the previous one
/// (ContactOutput::transition_level), both walls then; the final proxy against the final level's polyline.
/// No missed-contact rule here: a coarser level's wall lies up to its error from the level-0 polyline, so
/// "clearly past the wall" would depend on the level.
AutoLevelTally auto_level_stroke(const StrokeScene& sc, const Stroke& st, double speed_m_per_s) {
  const ServoParams sp = stroke_servo_params(true);
  SceneStep servo(sc.scene, sp);
  servo.start(st.start_m);
  const KinematicPath path(st, speed_m_per_s, sp.period_s);
  const auto segs_of = [&](int id) -> const Segments& {
    return sc.level_segs[static_cast<std::size_t>(std::clamp<int>(id, 0, static_cast<int>(sc.level_segs.size()) - 1))];
  };
  AutoLevelTally t;
  bool any_tunnel = false;
  ServoOutput so;
  for (long k = 1; k <= path.ticks(); ++k) {
    servo.update(path.input(k), so);
    ++t.ticks;
    t.level_sum += so.level;
    t.level_changes += so.level_changed;
    t.contact_ticks += so.contact.state != ContactState::Free;
    bool tunnel = false;
    for (int i = 0; i + 1 < so.contact.path_count; ++i) {
      const Vec2 p = so.contact.path_m[i], q = so.contact.path_m[i + 1];
      if (segs_of(so.level).crossings(p, q) > 0) tunnel = true;
      if (so.contact.transition_level >= 0 && segs_of(so.contact.transition_level).crossings(p, q) > 0) tunnel = true;
    }
    t.tunnel_ticks += tunnel;
    any_tunnel = any_tunnel || tunnel;
  }
  ++t.strokes;
  t.strokes_tunnelled += any_tunnel || (segs_of(so.level).crossings(st.start_m, so.contact.proxy_m) % 2) == 1;
  return t;
}

/// A stroke with the SceneStep alone: the handle is exactly on the stroke every tick.
/// `control`: no SceneStep at all, a proxy glued to the handle (free, one straight move per tick), i.e.
/// a renderer that ignores the walls: the checker must call every such stroke a failure.
StrokeTally kinematic_stroke(const StrokeScene& sc, const Stroke& st, double speed_m_per_s, bool control = false) {
  const ServoParams sp = stroke_servo_params();
  SceneStep servo(sc.scene, sp);
  servo.start(st.start_m);
  const KinematicPath path(st, speed_m_per_s, sp.period_s);
  StrokeTally t;
  TickChecker chk(sc, st.start_m);
  ServoOutput so;
  for (long k = 1; k <= path.ticks(); ++k) {
    const ServoInput in = path.input(k);
    if (control) {
      so.contact.path_m[0] = so.contact.path_count > 0 ? so.contact.proxy_m : st.start_m;
      so.contact.path_m[1] = in.sample.handle_m;
      so.contact.path_count = 2;
      so.contact.proxy_m = in.sample.handle_m;
      so.contact.state = ContactState::Free;
      so.contact.events = kEventNone;
    } else {
      servo.update(in, so);
    }
    chk.check(in.sample.handle_m, so, t);
  }
  chk.finish(so.contact.proxy_m, t);
  return t;
}

// The device strokes' hand: firm (so that it follows the stroke), damped relative to the target's motion
// (a hand moving with the stroke does not brake it), and no stronger than the wall's 3.5 N clamp, so the
// handle gets past a wall only by its momentum, as a fast visitor's would.
constexpr double kDeviceHandStiffnessNPerM = 400.0;
constexpr double kDeviceHandDampingNSPerM = 4.0;
constexpr double kDeviceHandMaxForceN = 3.0;

/// A stroke through the simulated pantograph: a firm hand pulls the handle after a target moving along
/// the stroke at `speed_m_per_s`. The servo runs 0.6 s with the handle parked first, so that the
/// guard's 0.5 s start-up ramp is over when the stroke begins.
StrokeTally device_stroke(const StrokeScene& sc, const Stroke& st, double speed_m_per_s) {
  const ServoParams sp = stroke_servo_params();
  const Chunking ch = chunking_for(sp.period_s);
  SimPantographParams dp;  // shipped device
  dp.substeps = ch.substeps;
  SimulatedPantograph dev(dp, st.start_m);
  dev.open();
  ModelHandParams hand;
  hand.stiffness_n_per_m = kDeviceHandStiffnessNPerM;
  hand.damping_n_s_per_m = kDeviceHandDampingNSPerM;
  hand.max_force_n = kDeviceHandMaxForceN;
  SceneStep servo(sc.scene, sp);
  servo.start(dev.read().handle_m);
  const double len = distance(st.start_m, st.end_m);
  const Vec2 dir = (1.0 / len) * (st.end_m - st.start_m);
  const double park_s = 0.6, move_s = len / speed_m_per_s, dwell_s = 0.2;
  const long n_ticks = std::lround((park_s + move_s + dwell_s) / sp.period_s);
  StrokeTally t;
  TickChecker chk(sc, st.start_m);
  ServoOutput so;
  for (long k = 0; k < n_ticks; ++k) {
    ServoInput in;
    in.sample = dev.read();
    servo.update(in, so);
    dev.write_force(so.force_n);
    const double t_s = static_cast<double>(k) * sp.period_s;
    if (t_s >= park_s) {
      const bool was_contact = chk.had_contact;
      chk.check(in.sample.handle_m, so, t);
      if (!was_contact && chk.had_contact) {
        t.impact_speed_sum += length(dev.velocity_m_per_s());
        ++t.impacts;
      }
    }
    for (int c = 0; c < ch.chunks; ++c) {
      const double tc = t_s + c * ch.chunk_s;
      const double s = std::clamp((tc - park_s) * speed_m_per_s, 0.0, len);
      const Vec2 target = st.start_m + s * dir;
      const Vec2 target_v = (tc >= park_s && s < len) ? speed_m_per_s * dir : Vec2{};
      // Damping relative to the target's motion: a hand that moves with the stroke does not brake it.
      dev.step(ch.chunk_s, model_hand_force(hand, target, dev.true_position_m(), dev.velocity_m_per_s() - target_v));
    }
  }
  chk.finish(so.contact.proxy_m, t);
  return t;
}

json tally_json(double speed, const StrokeTally& t) {
  json j;
  j["speed_m_per_s"] = sig4(speed);
  j["strokes"] = t.strokes;
  j["ticks"] = t.ticks;
  j["tunnel_ticks"] = t.tunnel_ticks;
  j["strokes_tunnelled"] = t.strokes_tunnelled;
  j["strokes_far_side"] = t.strokes_far_side;
  j["missed_contact_ticks"] = t.missed_ticks;
  j["unjudged_ticks"] = t.unjudged_ticks;
  j["strokes_missed_contact"] = t.strokes_missed;
  j["contact_ticks"] = t.contact_ticks;
  j["vertex_ticks"] = t.vertex_ticks;
  j["iteration_limit_ticks"] = t.iteration_limit_ticks;
  j["query_budget_ticks"] = t.query_budget_ticks;
  j["max_handle_step_m"] = sig4(t.max_handle_step_m);
  j["max_depth_in_contact_m"] = sig4(t.max_depth_m);
  if (t.impacts > 0) j["mean_impact_speed_m_per_s"] = sig4(t.impact_speed_sum / t.impacts);
  return j;
}

json run_part2(bool quick) {
  const std::vector<double> speeds = log_grid(0.05, 5.0, quick ? 5 : 13);
  std::vector<double> device_speeds;
  for (double v : log_grid(0.05, 1.0, quick ? 3 : 7)) device_speeds.push_back(v);
  const std::vector<StrokeScene> scenes = make_stroke_scenes();
  const ServoParams sp = stroke_servo_params();
  json out;
  out["level"] = kTunnelLevel;
  out["servo"] = {{"rate_hz", 1.0 / sp.period_s},
                  {"stiffness_n_per_m", sp.contact.stiffness_n_per_m},
                  {"max_force_n", sp.contact.max_force_n},
                  {"query_box_budget", sp.query_box_budget},
                  {"level_mode", sp.auto_level ? "auto" : "fixed"},
                  {"static_friction", sp.contact.static_friction},
                  {"dynamic_friction", sp.contact.dynamic_friction},
                  {"pop_force_n", sp.contact.pop_force_n}};
  out["device_hand"] = {{"stiffness_n_per_m", kDeviceHandStiffnessNPerM},
                        {"damping_n_s_per_m_relative_to_target", kDeviceHandDampingNSPerM},
                        {"max_force_n", kDeviceHandMaxForceN}};
  out["clearly_past_m"] = kClearlyPastM;
  out["rules"] = {
      {"tunnelling",
       "a proxy sub-move path_m[i] -> path_m[i+1] crosses a level-0 segment (p, q strictly on opposite sides of the "
       "segment's line, the crossing within the closed segment), or the final proxy is on the far side"},
      {"missed_contact",
       "handle past the wall (start -> handle crosses the polyline), > clearly_past_m from it and inside the shape's "
       "behind region (no way round), and contact state Free; unjudged_ticks counts handles across but outside it"}};
  // One job per (scene, drive, speed), run in parallel; tallies land in fixed slots, so the output does
  // not depend on the scheduling.
  struct Job {
    std::size_t scene;
    bool device;
    double speed_m_per_s;
    StrokeTally tally;
  };
  std::vector<Job> jobs;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    for (double v : speeds) jobs.push_back(Job{i, false, v, {}});
    for (double v : device_speeds) jobs.push_back(Job{i, true, v, {}});
  }
  parallel_for(jobs.size(), [&](std::size_t j) {
    Job& job = jobs[j];
    const StrokeScene& sc = scenes[job.scene];
    for (const Stroke& st : job.device ? sc.device_strokes : sc.strokes) {
      job.tally.add(job.device ? device_stroke(sc, st, job.speed_m_per_s)
                               : kinematic_stroke(sc, st, job.speed_m_per_s));
    }
  });
  // Control: the same kinematic strokes with a proxy that ignores the walls. Every stroke must be
  // counted as tunnelled and as a missed contact, or the checker is blind and nothing here means anything.
  json control = json::array();
  for (const StrokeScene& sc : scenes) {
    StrokeTally t;
    for (const Stroke& st : sc.strokes) t.add(kinematic_stroke(sc, st, 0.5, true));
    control.push_back({{"scene", sc.name},
                       {"strokes", t.strokes},
                       {"strokes_tunnelled", t.strokes_tunnelled},
                       {"strokes_missed_contact", t.strokes_missed}});
    if (t.strokes_tunnelled != t.strokes || t.strokes_missed != t.strokes) {
      std::fprintf(stderr, "bench_stability: the checker missed failures of the wall-blind control on %s\n",
                   sc.name.c_str());
      std::exit(3);
    }
  }
  out["control_wall_blind_proxy"] = control;
  // Part 2b: the kinematic strokes again with the shipped auto levels.
  struct AutoJob {
    std::size_t scene;
    double speed_m_per_s;
    AutoLevelTally tally;
  };
  std::vector<AutoJob> auto_jobs;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    for (double v : speeds) auto_jobs.push_back(AutoJob{i, v, {}});
  }
  parallel_for(auto_jobs.size(), [&](std::size_t j) {
    AutoJob& job = auto_jobs[j];
    for (const Stroke& st : scenes[job.scene].strokes)
      job.tally.add(auto_level_stroke(scenes[job.scene], st, job.speed_m_per_s));
  });
  json auto_scenes = json::array();
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    json rows = json::array();
    int failing = 0;
    for (const AutoJob& job : auto_jobs) {
      if (job.scene != i) continue;
      const AutoLevelTally& t = job.tally;
      failing += t.strokes_tunnelled;
      rows.push_back({{"speed_m_per_s", sig4(job.speed_m_per_s)},
                      {"strokes", t.strokes},
                      {"ticks", t.ticks},
                      {"tunnel_ticks", t.tunnel_ticks},
                      {"strokes_tunnelled", t.strokes_tunnelled},
                      {"contact_ticks", t.contact_ticks},
                      {"level_changes", t.level_changes},
                      {"mean_level", sig4(t.ticks > 0 ? t.level_sum / t.ticks : 0.0)}});
    }
    std::fprintf(stderr, "  %-14s auto levels, failing strokes: kinematic %d\n", scenes[i].name.c_str(), failing);
    auto_scenes.push_back({{"name", scenes[i].name}, {"kinematic", rows}});
  }
  out["auto_levels"] = {
      {"level_mode", "auto"},
      {"pop_force_n", 0.0},
      {"rule",
       "a proxy sub-move crosses a segment of the level id in use or of the previous one while a change is in "
       "transition, or the final proxy is on the far side of the final level's polyline; no missed-contact rule"},
      {"scenes", auto_scenes}};
  json jscenes = json::array();
  double first_fail_kin = 0.0, first_fail_dev = 0.0;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const StrokeScene& sc = scenes[i];
    json js;
    js["name"] = sc.name;
    js["description"] = sc.description;
    if (sc.thickness_m > 0.0) js["thickness_m"] = sc.thickness_m;
    if (sc.wedge_deg > 0.0) {
      js["wedge_deg"] = sc.wedge_deg;
      js["apex_gap_m"] = sc.apex_gap_m;
    }
    js["segments"] = sc.segs.segs.size();
    js["strokes_per_speed"] = sc.strokes.size();
    js["device_strokes_per_speed"] = sc.device_strokes.size();
    json kin = json::array(), dev = json::array();
    int kin_fail = 0, dev_fail = 0;
    for (const Job& job : jobs) {
      if (job.scene != i) continue;
      (job.device ? dev : kin).push_back(tally_json(job.speed_m_per_s, job.tally));
      if (job.tally.failed()) {
        double& first = job.device ? first_fail_dev : first_fail_kin;
        if (first == 0.0 || job.speed_m_per_s < first) first = job.speed_m_per_s;
        (job.device ? dev_fail : kin_fail) += job.tally.strokes_tunnelled + job.tally.strokes_missed;
      }
    }
    js["kinematic"] = kin;
    js["device"] = dev;
    std::fprintf(stderr, "  %-14s failing strokes: kinematic %d, device %d\n", sc.name.c_str(), kin_fail, dev_fail);
    jscenes.push_back(js);
  }
  out["speeds_m_per_s"] = json::array();
  for (double v : speeds) out["speeds_m_per_s"].push_back(sig4(v));
  out["device_speeds_m_per_s"] = json::array();
  for (double v : device_speeds) out["device_speeds_m_per_s"].push_back(sig4(v));
  out["scenes"] = jscenes;
  out["first_failure_speed_kinematic_m_per_s"] = first_fail_kin > 0.0 ? json(sig4(first_fail_kin)) : json(nullptr);
  out["first_failure_speed_device_m_per_s"] = first_fail_dev > 0.0 ? json(sig4(first_fail_dev)) : json(nullptr);
  return out;
}

}  // namespace

// ───────────────────────────── Part 3: each device profile's model ─────────────────────────────

/// The wall device of a profile's shipped settings, in the workspace frame the servo loop works in:
///   simulated — the simulated pantograph as the kiosk runs it (read, step, write: no delay);
///   a Haply   — its five-bar mapped onto the workspace by the driver's uniform scale s (io::workspace_scale:
///               links and motor spacing × s, the motors s·|rect_center_y| above the rectangle's centre),
///               mass m/s and damping b/s (the same force moves a workspace metre s times further), the
///               firmware's encoder counting at half its resolution (Encoder library), and one tick of
///               delay (the driver reads the reply to the packet of the tick before).
/// The torque limit is lifted as in part 1.
WallDevice profile_device(const config::Settings& s) {
  WallDevice d;
  d.params = app::sim_params_from(s);
  d.params.max_torque_n_m = 1e4;
  if (!config::is_usb_type(s.device.type)) return d;
  const double scale =
      std::min(s.workspace.width_m / s.device.rect_width_m, s.workspace.height_m / s.device.rect_height_m);
  d.params.geometry.motor_half_spacing_m = scale * 0.5 * s.device.motor_spacing_m;
  d.params.geometry.base_m = {0.0, -scale * s.device.rect_center_y_m};
  d.params.geometry.proximal_m = scale * s.device.link_proximal_m;
  d.params.geometry.distal_m = scale * s.device.link_distal_m;
  d.params.handle_mass_kg = s.device.handle_mass_kg / scale;
  d.params.handle_damping_n_s_per_m = s.device.handle_damping_n_s_per_m / scale;
  d.params.encoder_counts_per_rev = static_cast<int>(std::lround(s.device.encoder1_resolution / 2.0));
  d.params.stop_margin_m = scale * 0.005;  // the firmware emulator's stops, 5 mm outside the device rectangle
  d.delay_ticks = 1;
  return d;
}

json run_part3(bool quick) {
  const std::vector<double> grid = log_grid(100.0, 20000.0, quick ? 10 : 19);
  const int refine_steps = quick ? 3 : 6;
  const WallBench bench;
  struct Case {
    config::Settings s;
    WallDevice device;
  };
  std::vector<Case> cases;
  std::vector<Series> series;
  for (const config::DeviceProfile& p : config::device_profiles()) {
    const config::Settings s = config::profile_defaults(p.type);
    const WallDevice d = profile_device(s);
    for (HandMode mode : {HandMode::Push, HandMode::LetGo})
      series.push_back(Series{s.haptics.servo_rate_hz, mode, d, json()});
    cases.push_back({s, d});
  }
  parallel_for(series.size(), [&](std::size_t i) { run_series(bench, grid, refine_steps, series[i]); });
  json out;
  out["grid_n_per_m"] = json::array();
  for (double k : grid) out["grid_n_per_m"].push_back(sig4(k));
  json profiles = json::array();
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const config::Settings& s = cases[i].s;
    const config::DeviceProfile& p = config::device_profile(s.device.type);
    const json& push = series[2 * i].result;
    const json& let_go = series[2 * i + 1].result;
    const double limit =
        std::min(push["largest_stable_n_per_m"].get<double>(), let_go["largest_stable_n_per_m"].get<double>());
    json j;
    j["type"] = std::string(p.type);
    j["name"] = std::string(p.name);
    j["servo_rate_hz"] = s.haptics.servo_rate_hz;
    j["handle_mass_kg"] = sig4(cases[i].device.params.handle_mass_kg);
    j["handle_damping_n_s_per_m"] = sig4(cases[i].device.params.handle_damping_n_s_per_m);
    j["encoder_counts_per_rev"] = cases[i].device.params.encoder_counts_per_rev;
    j["encoder_step_normal_m"] = sig4(normal_encoder_step_m(cases[i].device.params, {0.0, 0.0}));
    j["delay_ticks"] = cases[i].device.delay_ticks;
    j["largest_stable_push_n_per_m"] = push["largest_stable_n_per_m"];
    j["largest_stable_let_go_n_per_m"] = let_go["largest_stable_n_per_m"];
    j["largest_stable_n_per_m"] = sig4(limit);
    j["profile_limit_n_per_m"] = p.stable_stiffness_n_per_m;
    j["default_n_per_m"] = s.haptics.stiffness_n_per_m;
    j["default_margin"] = sig4(limit / s.haptics.stiffness_n_per_m);
    j["force_everywhere_n"] = sig4(config::force_everywhere_n(s, s.device.type));
    j["max_force_n"] = s.haptics.max_force_n;
    j["pop_force_n"] = s.haptics.pop_force_n;
    j["push"] = push;
    j["let_go"] = let_go;
    std::fprintf(
        stderr,
        "  %-22s push %6.0f  let-go %6.0f N/m: limit %6.0f, profile allows %6.0f, default %4.0f (margin %.1fx)\n",
        std::string(p.name).c_str(), push["largest_stable_n_per_m"].get<double>(),
        let_go["largest_stable_n_per_m"].get<double>(), limit, p.stable_stiffness_n_per_m, s.haptics.stiffness_n_per_m,
        limit / s.haptics.stiffness_n_per_m);
    profiles.push_back(j);
  }
  out["profiles"] = profiles;
  return out;
}

int main(int argc, char** argv) {
  std::string out_path = "docs/bench/stability.json";
  bool quick = false, profiles_only = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
      out_path = argv[++i];
    } else if (std::strcmp(argv[i], "--quick") == 0) {
      quick = true;
    } else if (std::strcmp(argv[i], "--profiles") == 0) {
      profiles_only = true;
    } else {
      std::fprintf(stderr, "usage: %s [--out FILE.json] [--quick] [--profiles]\n", argv[0]);
      return 2;
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  json root;
  root["generator"] = "bench_stability";
  root["quick"] = quick;
  if (!profiles_only) {
    std::fprintf(stderr, "part 1: largest stable wall stiffness per servo rate\n");
    const auto t1 = std::chrono::steady_clock::now();
    root["stiffness"] = run_part1(quick);
    root["stiffness"]["elapsed_s"] = sig4(seconds_since(t1));
    std::fprintf(stderr, "part 2: tunnelling and missed contacts against hand speed\n");
    const auto t2 = std::chrono::steady_clock::now();
    root["tunnelling"] = run_part2(quick);
    root["tunnelling"]["elapsed_s"] = sig4(seconds_since(t2));
  }
  std::fprintf(stderr, "part 3: each device profile's model\n");
  const auto t3 = std::chrono::steady_clock::now();
  root["profiles"] = run_part3(quick);
  root["profiles"]["elapsed_s"] = sig4(seconds_since(t3));
  root["elapsed_s"] = sig4(seconds_since(t0));

  try {
    const std::filesystem::path p(out_path);
    if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
    std::ofstream f(p);
    if (!f) throw std::runtime_error("cannot open for writing");
    f << root.dump(1) << '\n';
    if (!f) throw std::runtime_error("write failed");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_stability: '%s': %s\n", out_path.c_str(), e.what());
    return 1;
  }
  std::fprintf(stderr, "wrote %s in %.1f s\n", out_path.c_str(), seconds_since(t0));
  return 0;
}
