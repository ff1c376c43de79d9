#pragma once
/// @file hand_controller.hpp
/// A closed-loop model hand for headless runs (DESIGN.md "Headless runs"): each tick the
/// hand is told what it feels (where the handle is, how fast it moves, the force the device puts on it) and
/// answers where it pulls the handle and how hard it may push. A HandPath (open loop: a target that ignores
/// what is felt) is one such hand (PathHand); the visitor-like explorer (`--hand explorer`) is another.
///
/// The simulated pantograph applies model_hand_force(params with max_force_n = command.max_force_n,
/// command.target_m, handle, velocity) to the handle; the force a hand can push with is thus per tick, so a
/// hand can press harder than its usual max_force_n when it means to push through a wall (pop_force_n).

#include "haptics/hand_path.hpp"
#include "hk/vec2.hpp"

namespace hk {

/// What the model hand feels at one tick (all in the workspace frame).
struct HandFeel {
  double t_s = 0.0;              ///< time since the run started [s]
  Vec2 handle_m;                 ///< where the handle is [m] (the device's true position)
  Vec2 handle_velocity_m_per_s;  ///< its velocity [m/s]
  Vec2 device_force_n;     ///< the force the device put on the handle at the last tick [N] (what a fingertip feels)
  bool heard_pop = false;  ///< the push-through earcon sounded at the last tick (what an ear hears); false where no
                           ///< servo output reaches the hand (the emulated device's thread)
};

/// What the model hand does at one tick.
struct HandCommand {
  Vec2 target_m;             ///< where the hand pulls the handle to [m] (a spring-damper, model_hand_force)
  double max_force_n = 2.0;  ///< the most the hand pushes with this tick [N], > 0
};

/// A model hand that reacts to what it feels. Deterministic: the same feels give the same commands.
/// Not for the servo thread (it runs in the headless loop, beside the simulated device).
class HandController {
 public:
  virtual ~HandController() = default;
  /// The command for this tick, from what the hand feels. Called once per tick, t_s increasing.
  virtual HandCommand command(const HandFeel& feel) = 0;
  /// Where the handle starts [m] (the command's target at t = 0).
  virtual Vec2 start_m() const = 0;
  /// How long the hand has something to do [s] (a run of unspecified duration lasts this + 0.5 s).
  virtual double natural_duration_s() const = 0;
};

/// A HandPath as a controller: the target follows the path whatever is felt, pushing with at most
/// `max_force_n` [N] (the [hand] max_force_n of the settings).
class PathHand final : public HandController {
 public:
  PathHand(const HandPath& path, double max_force_n) : path_(&path), max_force_n_(max_force_n) {}
  HandCommand command(const HandFeel& feel) override { return HandCommand{path_->at(feel.t_s), max_force_n_}; }
  Vec2 start_m() const override { return path_->at(0.0); }
  double natural_duration_s() const override { return path_->duration_s(); }

 private:
  const HandPath* path_;
  double max_force_n_;
};

}  // namespace hk
