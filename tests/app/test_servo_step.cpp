// ServoStep::step as a pure step, driven by the kiosk's ServoRunner: no device inside it, the same samples give
// the same commands bit for bit, nothing is allocated or freed in a tick (counted by a replaced global operator
// new in this translation unit) and nothing in it waits on the device (a transport that records every wait),
// through a whole run with a tour, picture swaps, new gains and a device that stalls and comes back; and a
// device that comes back gets its force back through the start-up ramp.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <new>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "curves.hpp"
#include "haptics/hapi_emulator.hpp"
#include "haptics/io/haply_device.hpp"
#include "haptics/io/tty_transport.hpp"
#include "haptics/pty_emulator.hpp"
#include "haptics/sim_pantograph.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/device_setup.hpp"
#include "runtime/guided_tour.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/servo_runner.hpp"
#include "runtime/servo_step.hpp"
#include "runtime/simulation.hpp"

// ── Counting allocation ───────────────────────────────────────────────────────────────────────────
// Replaces the global allocation functions of the whole test_app executable (allowed, also under ASan,
// which intercepts the malloc/free these forward to). They count only on a thread whose flag is set,
// around the calls under test, so the rest of the executable is unaffected.
namespace {
thread_local bool g_counting = false;
std::atomic<long> g_allocations{0};
std::atomic<long> g_frees{0};

[[gnu::noinline]] void* counted_alloc(std::size_t n) {
  if (g_counting) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n == 0 ? 1 : n);
}
[[gnu::noinline]] void* counted_aligned_alloc(std::size_t n, std::align_val_t al) {
  if (g_counting) g_allocations.fetch_add(1, std::memory_order_relaxed);
  const auto a = static_cast<std::size_t>(al);
  return std::aligned_alloc(a, (n + a - 1) / a * a + (n == 0 ? a : 0));
}
// Out of line: inlined into a delete-expression, free() would look mismatched to GCC's
// -Wmismatched-new-delete.
[[gnu::noinline]] void counted_free(void* p) noexcept {
  if (g_counting && p != nullptr) g_frees.fetch_add(1, std::memory_order_relaxed);
  std::free(p);
}

/// Counts the allocations and frees of this thread while alive.
struct CountAllocations {
  CountAllocations() { g_counting = true; }
  ~CountAllocations() { g_counting = false; }
};
}  // namespace

void* operator new(std::size_t n) {
  if (void* p = counted_alloc(n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (void* p = counted_alloc(n)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return counted_alloc(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return counted_alloc(n); }
void* operator new(std::size_t n, std::align_val_t al) {
  if (void* p = counted_aligned_alloc(n, al)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n, std::align_val_t al) {
  if (void* p = counted_aligned_alloc(n, al)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { counted_free(p); }
void operator delete[](void* p) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { counted_free(p); }

namespace hk::app {
namespace {

std::unique_ptr<SceneBundle> bundle(const ServoParams& sp, int id, double half = 0.02) {
  auto b = std::make_unique<SceneBundle>(std::make_unique<Scene>(Scene::build({test::square(half)}, 3)), sp);
  b->id = id;
  return b;
}

/// The kiosk's defaults; the model hand starts left of a 4 cm square and pulls towards `target` (its
/// centre at first), so it presses on the left wall. The caller does what ServoThread does each tick.
struct Rig {
  config::Settings s;
  ServoParams sp;
  SimulatedPantograph device;
  ModelHandParams hand;
  audio::SpscRing<audio::CueEvent> cues{1024};
  ServoStep core;
  Vec2 target{0.0, 0.0};
  std::vector<DeviceSample> samples;  // what step() was given
  std::vector<Vec2> commands;         // what it asked for

  explicit Rig(config::Settings settings = {})
      : s(std::move(settings)),
        sp(servo_params_from(s)),
        device(sim_params_from(s), {-0.03, 0.0}),
        hand(hand_params_from(s)),
        core(CueTrackerParams{}, &cues) {
    device.open();
  }
  ServoRunner runner{core, device};
  /// One ServoRunner tick: read, step, write (allocations counted when `count`), then the plant and the drain.
  void tick(bool count = false) {
    ServoTick t;
    if (count) {
      CountAllocations c;
      runner.tick(t);
      core.publish_display();
    } else {
      runner.tick(t);
      core.publish_display();
    }
    samples.push_back(t.sample);
    commands.push_back(t.command.force_n);
    device.step(sp.period_s, model_hand_force(hand, target, device.true_position_m(), device.velocity_m_per_s()));
    audio::CueEvent e;
    while (cues.try_pop(e)) {
    }
  }
  void run(double seconds, bool count = false) {
    for (long k = 0, n = static_cast<long>(seconds / sp.period_s + 0.5); k < n; ++k) tick(count);
  }
};

/// A level mode and a render mode of the kiosk's settings, and the level id the test fixes for a while in it.
struct StepMode {
  const char* level_mode;
  const char* render;
  int fixed_level;
};

class ServoStepModes : public ::testing::TestWithParam<StepMode> {};

// Every level mode (levels, tolerance steps, the tolerance cut with its shared masks) and both render modes:
// the step allocates and frees nothing through contact, a fixed level, the policy again, new gains, a slide
// and a picture change (fade, swap, ramp in).
TEST_P(ServoStepModes, NothingIsAllocatedOrFreedInTheStep) {
  config::Settings settings;
  settings.haptics.level_mode = GetParam().level_mode;
  settings.haptics.render = GetParam().render;
  Rig r(settings);
  const bool grooves = std::string(GetParam().render) == "grooves";
  if (grooves) r.target = {-0.02, 0.0};  // a groove does not stop the hand: pull it onto the left wall's line
  r.samples.reserve(10000);
  r.commands.reserve(10000);
  r.core.publish(bundle(r.sp, 1));
  r.tick();  // the first picture is taken (outside the count: the loop was sized on this thread anyway)
  g_allocations = 0;
  g_frees = 0;
  r.run(1.0, true);  // ramp in, press on the left wall
  ASSERT_NE(r.core.display().state, ContactState::Free) << "the hand must be in contact for this to test anything";
  const int fixed = GetParam().fixed_level;
  ASSERT_NE(r.core.display().level, fixed) << "the fixed level must be a change";
  r.core.request_level(fixed);
  r.run(0.3, true);
  EXPECT_EQ(r.core.display().level, fixed) << "a level change happened in the counted steps";
  r.core.request_level(ServoStep::kAutoLevel);
  ServoGains g = servo_gains_from(r.s);
  g.stiffness_n_per_m *= 2.0;
  g.static_friction = 0.1;
  g.dynamic_friction = 0.05;
  r.core.set_gains(g);                       // the caller's side
  r.target = {grooves ? -0.02 : 0.0, 0.01};  // slide along the wall
  r.run(0.5, true);
  EXPECT_EQ(r.core.display().stiffness_n_per_m, 2.0 * r.s.haptics.stiffness_n_per_m);
  r.core.publish(bundle(r.sp, 2, 0.015));  // built and handed over outside the count
  r.run(1.5, true);                        // fade, swap (the old bundle goes to the retired ring), ramp in
  EXPECT_EQ(r.core.display().scene_id, 2);
  EXPECT_EQ(g_allocations.load(), 0) << "operator new called in ServoStep::step";
  EXPECT_EQ(g_frees.load(), 0) << "operator delete called in ServoStep::step";
  EXPECT_EQ(r.core.collect_retired(), 1);
  // The counter counts: an allocation in a counted region shows.
  {
    CountAllocations c;
    auto p = std::make_unique<int>(3);
    EXPECT_EQ(*p, 3);
  }
  EXPECT_EQ(g_allocations.load(), 1);
  EXPECT_EQ(g_frees.load(), 1);
}

INSTANTIATE_TEST_SUITE_P(LevelAndRenderModes, ServoStepModes,
                         ::testing::Values(StepMode{"auto", "walls", 2},
                                           StepMode{"tolerance", "walls", kToleranceLevelBase + 1},
                                           StepMode{"cut", "walls", kCutLevelBase + 1}, StepMode{"auto", "grooves", 2},
                                           StepMode{"cut", "grooves", kCutLevelBase + 1}),
                         [](const ::testing::TestParamInfo<StepMode>& i) {
                           return std::string(i.param.level_mode) + "_" + i.param.render;
                         });

class ServoStepTourModes : public ::testing::TestWithParam<const char*> {};

TEST_P(ServoStepTourModes, NothingIsAllocatedOrFreedInAGuidedTour) {
  // The guided tour in the servo path: taken, led through the transit (walls
  // suspended), round the outline, let go, and a second one cancelled by a key; the paths are planned and
  // freed outside the count. In each level mode (the walls the tour presses on: levels, tolerance steps, cut).
  config::Settings settings;
  settings.haptics.level_mode = GetParam();
  Rig r(settings);
  r.hand = ModelHandParams{0.0, 0.0, 0.0};  // relaxed: the tour leads the handle
  r.samples.reserve(40000);
  r.commands.reserve(40000);
  r.core.publish(bundle(r.sp, 1));
  r.tick();
  r.run(0.6);
  const Scene square = Scene::build({test::square(0.02)}, 3);  // the bundle's picture
  const TourParams tp = tour_params_from(r.s);
  VisitTouches none;
  none.reset(1, 1);
  auto plan = plan_tour(square, 1, r.device.read().handle_m, none, tp);
  ASSERT_TRUE(plan.has_value());
  plan->id = 1;
  r.core.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
  g_allocations = 0;
  g_frees = 0;
  for (int k = 0; k < 30000 && r.core.display().tour_phase != TourPhase::Done; ++k) r.tick(true);
  EXPECT_EQ(r.core.display().tour_phase, TourPhase::Done);
  plan = plan_tour(square, 1, r.device.read().handle_m, none, tp);
  ASSERT_TRUE(plan.has_value());
  plan->id = 2;
  r.core.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
  r.run(0.3, true);
  r.core.cancel_tour();
  r.run(0.2, true);
  EXPECT_EQ(r.core.display().tour_phase, TourPhase::Stopped);
  const int level = r.core.display().level;
  EXPECT_EQ(is_cut_level(level), std::string(GetParam()) == "cut") << "the walls of the mode: level id " << level;
  EXPECT_EQ(is_tolerance_level(level), std::string(GetParam()) == "tolerance") << "level id " << level;
  EXPECT_EQ(g_allocations.load(), 0) << "operator new called in ServoStep::step during a tour";
  EXPECT_EQ(g_frees.load(), 0) << "operator delete called in ServoStep::step during a tour";
  r.core.collect_retired();
}

INSTANTIATE_TEST_SUITE_P(LevelModes, ServoStepTourModes, ::testing::Values("auto", "tolerance", "cut"),
                         [](const ::testing::TestParamInfo<const char*>& i) { return std::string(i.param); });

// ── Tripwires over a whole run on the emulated board ─────────────────────────────────────────────
/// Set on the servo's thread from the device's read to its write: inside ServoRunner::tick.
thread_local bool g_in_tick = false;
std::atomic<long> g_waits{0};    // transport calls inside a tick that could wait (timeout_us > 0)
std::atomic<long> g_tick_io{0};  // transport calls inside a tick (the tripwire is on the path)

/// The tty transport, recording every call made inside a tick that is allowed to wait.
class WaitRecordingTransport final : public io::ByteTransport {
 public:
  explicit WaitRecordingTransport(std::string path) : inner_(std::move(path)) {}
  void open() override { inner_.open(); }
  void close() noexcept override { inner_.close(); }
  int write(const std::uint8_t* data, int n, int timeout_us) noexcept override {
    note(timeout_us);
    return inner_.write(data, n, timeout_us);
  }
  int read(std::uint8_t* buf, int capacity, int timeout_us) noexcept override {
    note(timeout_us);
    return inner_.read(buf, capacity, timeout_us);
  }
  void flush_input() noexcept override { inner_.flush_input(); }
  bool is_open() const noexcept override { return inner_.is_open(); }
  std::string name() const override { return inner_.name(); }

 private:
  static void note(int timeout_us) noexcept {
    if (!g_in_tick) return;
    g_tick_io.fetch_add(1, std::memory_order_relaxed);
    if (timeout_us > 0) g_waits.fetch_add(1, std::memory_order_relaxed);
  }
  io::TtyTransport inner_;
};

/// The board, with allocations counted and transport waits recorded from its read to its write (the tick).
class TripwireDevice final : public Device {
 public:
  explicit TripwireDevice(Device& inner) : inner_(inner) {}
  void open() override { inner_.open(); }
  DeviceSample read() noexcept override {
    g_in_tick = true;
    g_counting = true;
    return inner_.read();
  }
  void write_force(Vec2 force_n) noexcept override {
    inner_.write_force(force_n);
    g_counting = false;
    g_in_tick = false;
  }
  void close() noexcept override { inner_.close(); }
  DeviceStatus status() const noexcept override { return inner_.status(); }
  std::string name() const override { return inner_.name(); }

 private:
  Device& inner_;
};

TEST(ServoStep, AWholeRunOnTheEmulatedBoardNeitherAllocatesNorWaitsInATick) {
  // The kiosk's runner over the emulated Haply board, bytes through a pty: a hand circling through a square's
  // walls, a guided tour, new gains, a second picture swapped in (faded), a level request, and the board
  // stalling for 0.3 s (the device Lost, then back: the picture restarts at the handle). In every tick:
  // no allocation or free, and no transport call that may wait.
  std::vector<std::string> notes;
  const config::Settings s = settings_for_board(config::Settings{}, &notes);
  const ServoParams sp = servo_params_from(s);
  const io::HaplyDeviceParams dp = haply_params_from(s);
  const double scale = io::workspace_scale(dp);
  const Vec2 centre = dp.rect_center_device_m;
  std::atomic<bool> relaxed{false};   // the hand lets the tour lead
  std::atomic<bool> pressing{false};  // the hand pushes into the square's middle, through its wall
  const ModelHandParams hp = hand_params_from(s);
  hapi::HandForce hand = [&](double t_s, Vec2 handle_device_m, Vec2 velocity_device_m_per_s) {
    if (relaxed.load()) return Vec2{};
    const Vec2 h = scale * (handle_device_m - centre), v = scale * velocity_device_m_per_s;
    const Vec2 target = pressing.load() ? Vec2{} : Vec2{0.03 * std::cos(0.8 * t_s), 0.03 * std::sin(0.8 * t_s)};
    return model_hand_force(hp, target, h, v);  // the same vector in both frames
  };
  DeviceChoice choice;
  choice.kind = DeviceChoice::Kind::HaplyEmulator;
  choice.faults.stall_at_s = 6.0;
  choice.faults.stall_s = 0.3;
  hapi::FirmwareEmulator emulator(emulator_params_from(s, choice), centre + Vec2{0.03 / scale, 0.0}, hand);
  hapi::PtyEmulator pty(emulator);
  const std::string tty = pty.device_path();
  io::HaplyDevice board(dp, [tty] { return std::make_unique<WaitRecordingTransport>(tty); });
  board.open();
  TripwireDevice device(board);

  audio::SpscRing<audio::CueEvent> cues(1024);
  ServoStep core(cue_params_from(s), &cues);
  core.publish(bundle(sp, 1));
  const Scene square = Scene::build({test::square(0.02)}, 3);  // bundle 1's picture
  const TourParams tp = tour_params_from(s);
  long contact_ticks = 0, lost_ticks = 0, tour_ticks = 0, fade_ticks = 0;
  DeviceStatus last_status = DeviceStatus::Closed;
  bool second_published = false;
  const auto script = [&](std::int64_t k) {
    if (k == 1500) {
      relaxed = true;
      VisitTouches none;
      none.reset(1, 1);
      auto plan = plan_tour(square, 1, core.display().handle_m, none, tp);
      ASSERT_TRUE(plan.has_value());
      plan->id = 1;
      core.publish_tour(std::make_unique<TourPath>(std::move(*plan)));
    }
    if (k == 3500) {
      core.cancel_tour();
      relaxed = false;
    }
    if (k == 4000) {
      ServoGains g = gains_of(sp);
      g.stiffness_n_per_m *= 0.6;
      core.set_gains(g);
    }
    // The next picture comes while the hand presses on a wall, so its force fades before the swap.
    if (k == 5000) pressing = true;
    if (k >= 5000 && !second_published && (length(core.display().force_n) > 0.5 || k == 5800)) {
      second_published = true;
      core.publish(bundle(sp, 2, 0.015));
    }
    if (k == 5900) pressing = false;
    if (k == 7500) core.request_level(0);
  };
  HeadlessClock clock(9000, sp.period_s);
  ServoRunner runner(core, device);
  g_allocations = 0;
  g_frees = 0;
  g_waits = 0;
  g_tick_io = 0;
  runner.run(clock, [&](ServoTick& t) {
    core.publish_display();
    const ServoDisplayState& d = core.display();
    contact_ticks += d.state != ContactState::Free;
    lost_ticks += t.sample.status != DeviceStatus::Ok;
    last_status = t.sample.status;
    tour_ticks += d.tour_phase == TourPhase::Transit || d.tour_phase == TourPhase::Outline;
    fade_ticks += second_published && d.scene_id == 1;
    for (audio::CueEvent e; cues.try_pop(e);) {
    }
    script(t.index);
    core.collect_retired();
    // The board in step with the run (as run_simulation does), outside the tick.
    const std::int64_t sent = board.counters().ticks;
    for (int i = 0; i < 1000; ++i) {
      long done = 0;
      pty.with_emulator([&](hapi::FirmwareEmulator& e) { done = e.torque_commands(); });
      if (done >= sent) break;
      std::this_thread::sleep_for(std::chrono::microseconds(20));
    }
    board.wait_reply(10000);
  });
  board.close();
  pty.stop();
  EXPECT_EQ(g_allocations.load(), 0) << "operator new called in a tick";
  EXPECT_EQ(g_frees.load(), 0) << "operator delete called in a tick";
  EXPECT_EQ(g_waits.load(), 0) << "a transport call in a tick was allowed to wait";
  EXPECT_GT(g_tick_io.load(), 9000) << "the tripwire sits on the board's path";
  EXPECT_GT(contact_ticks, 500) << "the hand must press on walls";
  EXPECT_GT(tour_ticks, 200) << "the tour must run";
  EXPECT_GT(lost_ticks, 10) << "the stall must lose the board";
  EXPECT_EQ(last_status, DeviceStatus::Ok) << "and it must come back";
  EXPECT_GT(fade_ticks, 10) << "the old picture fades before the swap";
  EXPECT_EQ(core.display().scene_id, 2);
  EXPECT_EQ(core.display().level, 0);
}

TEST(ServoStep, SameSamplesGiveBitIdenticalCommands) {
  // A closed-loop run through the simulated pantograph, recorded; then a second core, given the same
  // pictures, requests and gains at the same ticks, replays the recorded samples with no device at all.
  Rig a;
  const auto script = [](ServoStep& core, const ServoParams& sp, long k) {
    if (k == 0) core.publish(bundle(sp, 1));
    if (k == 900) core.request_level(0);
    if (k == 1400) {
      ServoGains g = gains_of(sp);
      g.stiffness_n_per_m = 1300.0;
      core.set_gains(g);
    }
    if (k == 1800) core.publish(bundle(sp, 2, 0.015));
  };
  const long n = 3000;
  for (long k = 0; k < n; ++k) {
    script(a.core, a.sp, k);
    if (k == 1000) a.target = {0.0, 0.012};
    a.tick();
  }
  ServoStep b(CueTrackerParams{}, nullptr);
  long contact_ticks = 0;
  for (long k = 0; k < n; ++k) {
    script(b, a.sp, k);
    ServoCommand cmd;
    b.step(a.samples[static_cast<std::size_t>(k)], false, cmd);
    ASSERT_EQ(cmd.force_n.x, a.commands[static_cast<std::size_t>(k)].x) << "tick " << k;
    ASSERT_EQ(cmd.force_n.y, a.commands[static_cast<std::size_t>(k)].y) << "tick " << k;
    contact_ticks += b.last_output().contact.state != ContactState::Free;
  }
  EXPECT_GT(contact_ticks, 1000) << "the run must press on walls";
  EXPECT_EQ(b.display_back().scene_id, 2);
}

TEST(ServoStep, AReturningDeviceGetsItsForceBackThroughTheRamp) {
  // Scripted samples, no device: the hand presses 1 mm into the left wall, the device is lost while the
  // hand goes 5 mm deeper, then it comes back.
  const config::Settings s;
  const ServoParams sp = servo_params_from(s);
  ServoStep core(CueTrackerParams{}, nullptr);
  core.publish(bundle(sp, 1));
  ServoCommand cmd;
  const auto step = [&](Vec2 h, DeviceStatus st) {
    DeviceSample smp;
    smp.handle_m = h;
    smp.status = st;
    core.step(smp, false, cmd);
    core.publish_display();
    return cmd.force_n;
  };
  for (int i = 0; i <= 100; ++i) step({-0.03 + 0.011 * i / 100.0, 0.0}, DeviceStatus::Ok);  // to 1 mm inside
  for (int i = 0; i < 600; ++i) step({-0.019, 0.0}, DeviceStatus::Ok);                      // past the ramp
  const Vec2 pressing = step({-0.019, 0.0}, DeviceStatus::Ok);
  ASSERT_GT(length(pressing), 0.7) << "800 N/m × 1 mm";
  ASSERT_EQ(core.display().device_status, DeviceStatus::Ok);
  for (int i = 0; i <= 100; ++i) {
    const Vec2 f = step({-0.019 + 0.005 * i / 100.0, 0.0}, DeviceStatus::Lost);
    ASSERT_EQ(length(f), 0.0);
  }
  EXPECT_EQ(core.display().device_status, DeviceStatus::Lost) << "the display can announce it";
  // Back: without the restart the proxy would still be at the wall, 6 mm from the handle, and the whole
  // clamped force would come back in one tick.
  const double ramp_step_n = sp.guard.max_force_n * sp.period_s / sp.guard.ramp_s;
  Vec2 prev = step({-0.014, 0.0}, DeviceStatus::Ok);
  EXPECT_EQ(core.display().device_status, DeviceStatus::Ok);
  EXPECT_LE(length(prev), ramp_step_n + 1e-12) << "the first tick back";
  EXPECT_LT(length(core.display().proxy_m - core.display().handle_m), 1e-9) << "the picture restarted at the handle";
  for (int i = 1; i <= 700; ++i) {
    const Vec2 h{-0.014 - 0.006 * std::min(1.0, i / 300.0), 0.0};  // the hand backs out through the wall
    const Vec2 f = step(h, DeviceStatus::Ok);
    ASSERT_LE(length(f - prev), ramp_step_n + 800.0 * 0.006 / 300.0 + 1e-9) << "tick " << i << " after the return";
    prev = f;
  }
}

}  // namespace
}  // namespace hk::app
