// The library's pictures as the visitor walks them (library_desk.hpp).
#include "visit/library_desk.hpp"

#include <spdlog/spdlog.h>

#include "formats/app_error.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {

int LibraryDesk::show_picture(int index) {
  stage_.reset_level();  // a level the visitor chose holds for one picture
  if (std::unique_ptr<ImageScene> is = shelf_.take_or_want(index)) return put_picture(index, *is);
  return kPicturePending;
}

int LibraryDesk::put_picture(int index, ImageScene& is) {
  const int shapes = static_cast<int>(is.scene->curve_count());
  PictureNotes notes = std::move(is.notes);  // read on the worker
  stage_.show(is, index, ShownSource{index, -1, 0}, std::move(notes));
  shelf_.build_ahead(index);
  return shapes;
}

void LibraryDesk::poll(KioskFlow* flow, double now_s) {
  if (std::optional<ShelfDelivery> d = shelf_.poll()) {
    BuiltScene& b = d->built;
    spdlog::info("scene {}: built in {:.0f} ms (waited {:.0f} ms to start)", b.id, b.build_ms, b.queued_ms);
    if (!b.scene) {
      spdlog::warn("scene {}: {}; the picture felt before stays", b.id, b.error);
      if (d->kind == ShelfDelivery::Kind::Picture && flow)
        flow->picture_failed(b.id, problem_of(b.error), now_s);  // "Picture N of M" names it
    } else if (d->kind == ShelfDelivery::Kind::Rebuild) {
      // The same picture with the new settings: no new announcement.
      stage_.show(*b.scene, b.id, stage_.source(), stage_.shown().notes);
      if (b.id >= 0 && b.id < picture_count()) shelf_.build_ahead(stage_.source().picture);
    } else {
      const int shapes = put_picture(b.id, *b.scene);
      if (flow) flow->picture_ready(b.id, shapes, now_s);
    }
  }
  shelf_.build_ahead(stage_.source().picture);
}

bool LibraryDesk::finish(KioskFlow* flow, double now_s, double timeout_s) {
  if (!shelf_.busy()) return true;
  const bool came = shelf_.wait(timeout_s);
  poll(flow, now_s);
  return came;
}

}  // namespace hk::app
