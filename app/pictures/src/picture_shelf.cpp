// The library's scenes, asked for and built ahead (picture_shelf.hpp).
#include "pictures/picture_shelf.hpp"
#include "pictures/picture_names.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <future>

#include "formats/picture_notes.hpp"
#include "pictures/picture_params.hpp"
#include "vision/intake.hpp"

namespace hk::app {
namespace {

/// Library picture `path`'s scene, with what the file itself says of it (file_notes): from the scene cache
/// when it holds one for this file and these settings (found by the file's stamp without reading it, else
/// by its bytes' key), else built from the bytes read once and stored; a scene whose text is still to be
/// read is stored once it has been read (its with_text stores what it builds). Runs on the builder's worker.
ImageScene cached_or_built(const std::string& path, const config::Settings& s, const std::shared_ptr<SceneCache>& cache,
                           int side_px) {
  // What the file says of itself is read beside the build: exiv2 reads a PNG's chunks through its image
  // data (tens of milliseconds for a 20 MB photo PNG), which need not delay the scene.
  const auto notes_beside = [&path] { return std::async(std::launch::async, [path] { return embedded_notes(path); }); };
  if (!cache) {
    std::future<PictureNotes> notes = notes_beside();
    ImageScene is = build_image_scene(path, s, TextTiming::later);
    fit_picture(is, side_px);
    is.file_notes = notes.get();
    return is;
  }
  const std::optional<FileStamp> stamp = SceneCache::stamp(path);  // before the bytes are read
  if (stamp) {
    if (const std::optional<std::string> known = cache->known_key(*stamp, s)) {
      if (std::optional<ImageScene> hit = cache->load(*known, s)) {
        hit->image_path = path;
        fit_picture(*hit, side_px);  // kept at the size of the screen that stored it
        return std::move(*hit);
      }
    }
  }
  const std::vector<std::uint8_t> bytes = vision::read_input_file(path, extract_params_from(s).limits.max_file_bytes);
  const std::string key = SceneCache::key(bytes, s);
  if (std::optional<ImageScene> hit = cache->load(key, s)) {
    if (stamp) cache->remember_key(*stamp, s, key);
    hit->image_path = path;
    fit_picture(*hit, side_px);
    return std::move(*hit);
  }
  std::future<PictureNotes> notes = notes_beside();
  ImageScene is = build_image_scene_from_bytes(bytes, path, s, TextTiming::later);
  fit_picture(is, side_px);
  is.file_notes = notes.get();
  auto keep = [cache, key, stamp, s](const ImageScene& built) {
    if (cache->store(key, built) && stamp) cache->remember_key(*stamp, s, key);
  };
  if (!is.text_pending) {
    keep(is);
    return is;
  }
  is.with_text = [read = std::move(is.with_text), keep, file_notes = is.file_notes, side_px](const TextRun& run) {
    ImageScene with_text = read(run);
    fit_picture(with_text, side_px);
    with_text.file_notes = file_notes;
    const bool whole = with_text.scene && with_text.ocr.why != "cancelled" && with_text.ocr.why.rfind("failed", 0) != 0;
    if (whole) keep(with_text);
    return with_text;
  };
  return is;
}

/// A library picture's notes: its sidecar's, else `file_notes` (what the file says, read with its scene);
/// a sidecar that cannot be used is logged and the picture shown without notes.
PictureNotes notes_of(const std::string& path, const PictureNotes& file_notes) {
  try {
    return read_picture_notes(path, &file_notes);
  } catch (const PictureNotesError& e) {
    spdlog::warn("{}; the picture is shown without it", e.what());
    return {};
  }
}

}  // namespace

PictureShelf::PictureShelf(std::vector<std::string> pictures, std::shared_ptr<SceneCache> cache,
                           const config::Settings& s)
    : pictures_(std::move(pictures)), cache_(std::move(cache)), s_(s) {}

int PictureShelf::find(const std::string& path) const {
  for (std::size_t i = 0; i < pictures_.size(); ++i) {
    std::error_code ec;
    if (std::filesystem::equivalent(pictures_[i], path, ec)) return static_cast<int>(i);
  }
  return -1;
}

void PictureShelf::replace_pictures(std::vector<std::string> pictures, const std::vector<std::string>& changed) {
  absorb_built();  // what the old numbering built, first
  std::vector<Ahead> kept;
  for (Ahead& a : ahead_) {
    const std::string& old_path = pictures_[static_cast<std::size_t>(a.index)];
    if (std::find(changed.begin(), changed.end(), old_path) != changed.end()) continue;
    const auto at = std::find(pictures.begin(), pictures.end(), old_path);
    if (at == pictures.end()) continue;
    a.index = static_cast<int>(at - pictures.begin());
    kept.push_back(std::move(a));
  }
  ahead_ = std::move(kept);
  ahead_refused_.clear();
  ++generation_;
  builder_.drop_ahead();
  drop_want();
  pictures_ = std::move(pictures);
}

void PictureShelf::set_settings(const config::Settings& s, bool shape_changed) {
  s_ = s;
  if (!shape_changed) return;
  // What was built ahead, or is being built, with the old settings is not used.
  ++generation_;
  ahead_.clear();
  ahead_refused_.clear();
  builder_.drop_ahead();
  drop_want();
}

SceneJob PictureShelf::picture_job(int index) const {
  // A copy of what the build needs: the worker never touches the shelf.
  return [path = pictures_[static_cast<std::size_t>(index)], s = s_, cache = cache_, side_px = side_px_] {
    ImageScene is = cached_or_built(path, s, cache, side_px);
    is.notes = notes_of(path, is.file_notes);
    const std::string names = names_file_for(path, names_dir(s)),
                      file = std::filesystem::path(path).filename().string();
    const bool guesses = guesses_for(path, names_dir(s), is.notes.guesses);
    apply_names(is, names, file, guesses);
    if (is.with_text)  // the scene read again with its text keeps the names
      is.with_text = [read = std::move(is.with_text), names, file, guesses](const TextRun& run) {
        ImageScene with_text = read(run);
        apply_names(with_text, names, file, guesses);
        return with_text;
      };
    return is;
  };
}

std::unique_ptr<ImageScene> PictureShelf::take_or_want(int index) {
  absorb_built();
  for (auto it = ahead_.begin(); it != ahead_.end(); ++it) {
    if (it->index != index) continue;
    std::unique_ptr<ImageScene> is = std::move(it->scene);
    ahead_.erase(it);
    drop_want();  // the visitor moved on: an older ask is not wanted any more
    spdlog::info("picture {}: built ahead, on the device at once", index + 1);
    return is;
  }
  wanted_id_ = index;
  wanted_kind_ = ShelfDelivery::Kind::Picture;
  wanted_done_.reset();
  builder_.want(index, generation_, picture_job(index));
  return nullptr;
}

void PictureShelf::want_rebuild(int id, SceneJob job) {
  wanted_id_ = id;
  wanted_kind_ = ShelfDelivery::Kind::Rebuild;
  wanted_done_.reset();
  builder_.want(id, generation_, std::move(job));
}

void PictureShelf::drop_want() {
  wanted_id_ = kNoWant;
  wanted_done_.reset();
}

void PictureShelf::absorb_built() {
  for (BuiltScene& b : builder_.poll()) {
    build_times_ms_.push_back(b.build_ms);
    if (b.generation != generation_) continue;  // built with settings no longer in use
    if (b.id == wanted_id_) {
      wanted_done_ = std::move(b);
      continue;
    }
    if (b.id < 0 || b.id >= count()) continue;  // a rebuild nobody waits for
    if (!b.scene) {  // not asked again until the settings change (the visitor asking for it hears why)
      ahead_refused_.push_back(b.id);
      continue;
    }
    Ahead a;
    a.index = b.id;
    a.bytes = approx_scene_bytes(*b.scene);
    a.scene = std::make_unique<ImageScene>(std::move(*b.scene));
    ahead_.push_back(std::move(a));
  }
}

std::optional<ShelfDelivery> PictureShelf::poll() {
  absorb_built();
  if (!wanted_done_) return std::nullopt;
  ShelfDelivery d;
  d.kind = wanted_kind_;
  d.built = std::move(*wanted_done_);
  wanted_done_.reset();
  wanted_id_ = kNoWant;
  return d;
}

std::vector<int> PictureShelf::ahead() const {
  std::vector<int> out;
  for (const Ahead& a : ahead_) out.push_back(a.index);
  return out;
}

void PictureShelf::build_ahead(int shown) {
  const int n = count();
  const int at = wanted_id_ >= 0 && wanted_id_ < n ? wanted_id_ : shown;
  // No library picture under the hand (the tutorial, a stick, a capture): the first picture is the one a
  // visitor reaches next (after the tutorial), so it is built ahead, from the scene cache after a restart.
  const int next = at < 0 ? 0 : (at + 1) % n, previous = at < 0 ? 0 : (at + n - 1) % n;
  // Kept: the neighbours of where the visitor is (and is going), within the budget, the next one first.
  const std::size_t budget = static_cast<std::size_t>(s_.kiosk.prefetch_mb) << 20;
  std::vector<Ahead> kept;
  std::size_t used = 0;
  for (const int want : {next, previous}) {
    for (Ahead& a : ahead_) {
      if (a.index != want || !a.scene) continue;
      if (used + a.bytes > budget) {
        spdlog::info("picture {}: its scene ({} MiB) is over [kiosk] prefetch_mb; built when asked for", a.index + 1,
                     a.bytes >> 20);
        ahead_refused_.push_back(a.index);
        continue;
      }
      used += a.bytes;
      kept.push_back(std::move(a));
    }
  }
  ahead_ = std::move(kept);
  if (budget == 0 || n < 2) return;
  for (const int want : {next, previous}) {
    if (want == shown) continue;
    const bool have = std::any_of(ahead_.begin(), ahead_.end(), [&](const Ahead& a) { return a.index == want; });
    const bool refused = std::find(ahead_refused_.begin(), ahead_refused_.end(), want) != ahead_refused_.end();
    if (!have && !refused && !builder_.has(want, generation_)) builder_.ahead(want, generation_, picture_job(want));
  }
}

}  // namespace hk::app
