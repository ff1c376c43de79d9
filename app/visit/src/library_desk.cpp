// The library's pictures as the visitor walks them (library_desk.hpp).
#include "visit/library_desk.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>

#include "formats/app_error.hpp"
#include "runtime/metrics.hpp"
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

namespace {

/// The file name of `path`: listings are sorted by it.
std::string file_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

/// Index in `pictures` (sorted by file name, not empty) of the first picture whose file name sorts after `path`'s
/// (`forward`), or of the last one before it; round the ends.
int beside(const std::vector<std::string>& pictures, const std::string& path, bool forward) {
  const std::string name = file_name(path);
  const int n = static_cast<int>(pictures.size());
  if (forward) {
    for (int i = 0; i < n; ++i)
      if (file_name(pictures[static_cast<std::size_t>(i)]) > name) return i;
    return 0;
  }
  for (int i = n - 1; i >= 0; --i)
    if (file_name(pictures[static_cast<std::size_t>(i)]) < name) return i;
  return n - 1;
}

/// Index in `pictures` of `path`, −1 when it is not there.
int index_of(const std::vector<std::string>& pictures, const std::string& path) {
  const auto at = std::find(pictures.begin(), pictures.end(), path);
  return at == pictures.end() ? -1 : static_cast<int>(at - pictures.begin());
}

}  // namespace

void LibraryDesk::offer_listing(std::vector<std::string> pictures, std::vector<std::string> changed) {
  if (pictures.empty()) return;  // the runtime offers the shipped pictures instead
  if (waiting_)                  // not taken yet: what changed then still changed
    changed.insert(changed.end(), waiting_->changed.begin(), waiting_->changed.end());
  waiting_ = LibraryListing{std::move(pictures), std::move(changed)};
}

void LibraryDesk::take_listing() {
  if (!waiting_) return;
  LibraryListing l = std::move(*waiting_);
  waiting_.reset();
  const int shown = stage_.source().picture;
  const std::string shown_path = shown >= 0 && shown < shelf_.count() ? shelf_.path(shown) : std::string{};
  spdlog::info("library: {} pictures (were {}), {} changed", l.pictures.size(), shelf_.count(), l.changed.size());
  if (!shown_path.empty()) stage_.renumber_picture(index_of(l.pictures, shown_path));
  shelf_.replace_pictures(std::move(l.pictures), l.changed);
}

int LibraryDesk::moving_to(int index, int from) {
  if (!waiting_) return index;
  const std::vector<std::string>& next = waiting_->pictures;
  const int n = shelf_.count();
  int to = index_of(next, shelf_.path(index));
  if (to < 0) {  // gone: the one beside where the visitor was, the way they were going
    const bool back = from >= 0 && n > 2 && index == (from + n - 1) % n;
    to = beside(next, shelf_.path(from >= 0 && from < n ? from : index), !back);
  }
  take_listing();
  return to;
}

void LibraryDesk::poll(KioskFlow* flow, double now_s) {
  if (waiting_ && (!flow || flow->view().state == KioskState::Attract)) take_listing();
  if (std::optional<ShelfDelivery> d = shelf_.poll()) {
    BuiltScene& b = d->built;
    spdlog::info("scene {}: built in {:.0f} ms (waited {:.0f} ms to start)", b.id, b.build_ms, b.queued_ms);
    if (!b.scene) {
      kiosk_metrics().error(KioskError::picture_unreadable);
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
  for (const double ms : shelf_.take_build_times_ms()) kiosk_metrics().observe(KioskTiming::scene_build, ms / 1000.0);
}

bool LibraryDesk::finish(KioskFlow* flow, double now_s, double timeout_s) {
  if (!shelf_.busy()) return true;
  const bool came = shelf_.wait(timeout_s);
  poll(flow, now_s);
  return came;
}

}  // namespace hk::app
