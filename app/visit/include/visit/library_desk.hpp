#pragma once
/// @file library_desk.hpp
/// The library's pictures as the visitor walks them: a picture asked for is put on the device at once when it
/// was built ahead, else asked of the scene builder (PictureShelf) and put on the device when it comes, the
/// picture felt before staying until then; the next and previous pictures are built ahead. It answers the
/// visitor's flow's LibraryEffects (kiosk_effects.hpp). Window thread only.
///
/// A new listing of the library (its folder watched, library_watch.hpp) is taken while nobody is on a visit; during
/// a visit it waits until the visitor moves to a picture (moving_to), so the picture explored stays, under the
/// same number, until they move on; Next from a picture that has gone is the one after it by file name, Previous the
/// one before it.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pictures/library_watch.hpp"
#include "pictures/picture_shelf.hpp"
#include "visit/kiosk_effects.hpp"
#include "visit/stage.hpp"

namespace hk::app {

class KioskFlow;

/// The library's pictures on the stage. Not thread-safe: the window thread.
class LibraryDesk final : public LibraryEffects {
 public:
  /// `shelf` and `stage` outlive the desk.
  LibraryDesk(PictureShelf& shelf, Stage& stage) : shelf_(shelf), stage_(stage) {}

  /// Picture `index` of the library: put on the device at once when it was built ahead (returns its shapes),
  /// else asked of the scene builder (returns kPicturePending; poll puts it on the device and tells the flow).
  /// The picture felt before stays until then. The operator's level comes back (reset_level).
  int show_picture(int index) override;
  int picture_count() const override { return shelf_.count(); }
  int moving_to(int index, int from) override;

  /// A new listing of the library: `pictures` (paths, sorted by file name; an empty one is ignored), `changed`
  /// those whose files changed since they were last listed. Taken by poll while the kiosk waits in attract (or
  /// without a flow), else by moving_to; a newer listing replaces one still waiting.
  void offer_listing(std::vector<std::string> pictures, std::vector<std::string> changed);
  /// The listing offered and not yet taken, if any.
  const std::optional<LibraryListing>& waiting() const { return waiting_; }

  /// Window thread, every frame (`now_s` the frame clock [s]): scenes the builder has finished. The one asked
  /// for is put on the device with the fade and handed to `flow` (picture_ready or picture_failed; null: a
  /// headless caller that only wants it felt); a rebuild after Apply is swapped in without a word; scenes
  /// built ahead are kept within [kiosk] prefetch_mb; then the next and previous pictures of the one shown
  /// are asked for ahead (the first picture while none is shown: the one the tutorial leads to).
  void poll(KioskFlow* flow, double now_s);
  /// Blocks until the scene asked for is built, then poll(flow, now_s) (tests, scripted and headless runs;
  /// never the frame loop). At most `timeout_s` [s]; returns whether it came.
  bool finish(KioskFlow* flow, double now_s, double timeout_s = 60.0);
  /// Whether a scene asked for (a picture, or a rebuild after Apply) is not yet on the device (scripted runs
  /// hold their frames for it).
  bool busy() const { return shelf_.busy(); }
  /// Scene builds started since the start (asked for and built ahead): what the visitor's keys cost.
  std::uint64_t builds_started() const { return shelf_.builds_started(); }
  /// Library pictures built ahead and waiting (their indices).
  std::vector<int> ahead() const { return shelf_.ahead(); }
  /// Index of `path` in the library, −1 when it is not there.
  int find(const std::string& path) const { return shelf_.find(path); }
  /// Puts `path` first in the library (documentation runs: --show of a picture from elsewhere).
  void add_first(const std::string& path) { shelf_.add_first(path); }

 private:
  int put_picture(int index, ImageScene& is);  // library picture `index` on the device, with its notes; its shapes
  void take_listing();                         // the listing waiting becomes the library's

  PictureShelf& shelf_;
  Stage& stage_;
  std::optional<LibraryListing> waiting_;  // offered, not yet taken
};

}  // namespace hk::app
