#pragma once
/// @file picture_shelf.hpp
/// The library's pictures as scenes, all built off the window thread (scene_builder.hpp): the scene the
/// visitor asked for first, then the neighbours of the picture shown (next, then previous) built ahead and
/// kept within [kiosk] prefetch_mb, so Next and Previous are felt at once. A library picture's scene comes
/// from the scene cache when it holds one for the file and the settings (scene_cache.hpp), with the picture's
/// notes (its sidecar, else what the file says of itself). Besides library pictures, the shelf rebuilds the
/// scene shown when the operator's settings change (want_rebuild).
///
/// Window thread only; the builds run on the builder's worker, each with a copy of what it needs.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "config/settings.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/scene_builder.hpp"
#include "pictures/scene_cache.hpp"

namespace hk::app {

/// A scene the shelf was asked for, once its build ended.
struct ShelfDelivery {
  enum class Kind {
    Picture,  ///< a library picture the visitor asked for (want_picture)
    Rebuild,  ///< the scene shown, rebuilt with new settings (want_rebuild): no new announcement
  };
  Kind kind = Kind::Picture;
  BuiltScene built;  ///< built.scene null: the build failed (built.error says why, one line)
};

/// The library's scenes, asked for and built ahead. Not thread-safe: the window thread.
class PictureShelf {
 public:
  /// `pictures`: the library's files, in order (list_pictures); `cache`: where built scenes are kept (null:
  /// none); `s`: the settings the scenes are built with.
  PictureShelf(std::vector<std::string> pictures, std::shared_ptr<SceneCache> cache, const config::Settings& s);

  /// Library pictures.
  int count() const { return static_cast<int>(pictures_.size()); }
  /// Library picture `index`'s path (0 <= index < count()).
  const std::string& path(int index) const { return pictures_.at(static_cast<std::size_t>(index)); }
  /// The library's files, in order.
  const std::vector<std::string>& pictures() const { return pictures_; }
  /// The library's files become `pictures` (a listing of the folder watched): what was built ahead of a picture
  /// still there is kept under its new index unless its path is in `changed` (its files changed); builds under
  /// way and the ask waiting are dropped (they carry the old numbering).
  void replace_pictures(std::vector<std::string> pictures, const std::vector<std::string>& changed);
  /// Index of `path` in the library (the same file, by std::filesystem::equivalent), −1 when it is not there.
  int find(const std::string& path) const;
  /// Puts `path` first in the library (documentation runs: --show of a picture from elsewhere).
  void add_first(const std::string& path) { pictures_.insert(pictures_.begin(), path); }

  /// Settings for the builds from now on. `shape_changed`: they change what a scene is, so what was built
  /// ahead, or is being built, with the old ones is dropped and an ask waiting is forgotten.
  void set_settings(const config::Settings& s, bool shape_changed);
  /// The longest side [px] library pictures are shrunk to on their worker (fit_picture).
  void set_side_px(int px) { side_px_ = px; }

  /// Picture `index`'s scene, taken off the shelf when it was built ahead (nothing then waits); else null,
  /// and the build is asked for (poll delivers it).
  std::unique_ptr<ImageScene> take_or_want(int index);
  /// Asks for scene `id` rebuilt by `job` (the scene shown, with new settings), in place of any ask.
  void want_rebuild(int id, SceneJob job);
  /// Picture `index` rebuilt with the settings in use (want_rebuild with the library's job).
  void want_rebuild_picture(int index) { want_rebuild(index, picture_job(index)); }
  /// The scene asked for is not wanted any more (the visitor went elsewhere).
  void drop_want();
  /// Whether a scene asked for has not been delivered yet.
  bool busy() const { return wanted_id_ != kNoWant; }

  /// The builds that ended: those built ahead kept (or, failed, not asked again in these settings); the one
  /// asked for delivered once.
  std::optional<ShelfDelivery> poll();
  /// Blocks until the build asked for has ended, at most `timeout_s` [s] (tests, scripted runs). Returns
  /// whether it ended; poll() then delivers it.
  bool wait(double timeout_s) { return builder_.wait_want(timeout_s); }
  /// Keeps, of what was built ahead, the neighbours of the picture asked for or else of `shown`, the library
  /// picture shown (−1: none, so the first picture, the one a visitor reaches after the tutorial), within
  /// [kiosk] prefetch_mb, next first, and asks for the ones missing.
  void build_ahead(int shown);
  /// Library pictures built ahead and waiting (their indices).
  std::vector<int> ahead() const;
  /// Scene builds started since the start (asked for and built ahead).
  std::uint64_t builds_started() const { return builder_.builds_started(); }
  /// How long each scene build that ended since the last call took [ms] (asked for, built ahead, rebuilt; those
  /// dropped for old settings too), oldest first; the list is then emptied.
  std::vector<double> take_build_times_ms() { return std::exchange(build_times_ms_, {}); }

 private:
  static constexpr int kNoWant = -1000000;
  struct Ahead {
    int index = 0;  // library picture
    std::unique_ptr<ImageScene> scene;
    std::size_t bytes = 0;  // its memory (approx_scene_bytes)
  };
  SceneJob picture_job(int index) const;  // builds library picture `index` with the settings in use
  void absorb_built();                    // the builder's finished scenes: kept ahead, or the wanted one noted

  std::vector<std::string> pictures_;
  std::shared_ptr<SceneCache> cache_;  // shared with the builds under way (null: none)
  config::Settings s_;
  int side_px_ = kScreenPictureMaxSidePx;
  SceneBuilder builder_;
  std::uint64_t generation_ = 1;  // bumped when the settings that shape a scene change: older builds are dropped
  int wanted_id_ = kNoWant;       // the scene asked for, not yet delivered
  ShelfDelivery::Kind wanted_kind_ = ShelfDelivery::Kind::Picture;
  std::optional<BuiltScene> wanted_done_;  // the wanted scene's build, once ended
  std::vector<Ahead> ahead_;               // library pictures built ahead
  std::vector<int> ahead_refused_;      // built ahead in this generation but failed or over the budget: not asked again
  std::vector<double> build_times_ms_;  // builds ended, not yet taken (take_build_times_ms)
};

}  // namespace hk::app
