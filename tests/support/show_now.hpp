#pragma once
/// @file show_now.hpp
/// A library picture put on the device before the test goes on: LibraryDesk::show_picture builds off the
/// window thread, so a test that needs the picture felt waits for the build (LibraryDesk::finish).

#include "visit/kiosk_runtime.hpp"

namespace hk::test {

/// Shows library picture `index` and waits (at most 60 s) until it is on the device; returns its shapes, or −1
/// when its build failed or did not come.
inline int show_now(app::KioskRuntime& rt, int index, app::KioskFlow* flow = nullptr, double now_s = 0.0) {
  const int shapes = rt.library().show_picture(index);
  if (shapes != app::KioskEffects::kPicturePending) return shapes;
  if (!rt.library().finish(flow, now_s) || rt.stage().shown_id() != index || !rt.stage().shown().scene) return -1;
  return static_cast<int>(rt.stage().shown().scene->curve_count());
}

}  // namespace hk::test
