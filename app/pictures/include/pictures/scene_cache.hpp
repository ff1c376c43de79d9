#pragma once
/// @file scene_cache.hpp
/// Built scenes of library pictures kept on disk, so that a kiosk's first picture after a reboot is felt at
/// once: a load reads the curves and the report back and rebuilds only the collision trees (Scene::build,
/// about 1 ms), where a build runs edge detection, linking and simplification (tens to hundreds of ms, OCR
/// seconds).
///
/// An entry is one file `<dir>/<key>.scene`, key = SceneCache::key (64 hex digits). Its layout:
///
///   offset  size  field
///        0     8  magic "HKSCENE\0"
///        8     4  format version, uint32 little-endian (kSceneCacheFormat)
///       12     8  payload size in bytes, uint64 little-endian (= file size − 52)
///       20    32  BLAKE2b-256 (libsodium crypto_generichash, unkeyed) of bytes 0..19 and the payload
///       52     …  payload: one CBOR map (RFC 8949, nlohmann::json::to_cbor), see scene_cache.cpp
///                 `to_payload` for its keys; polyline points and strengths are CBOR byte strings of
///                 little-endian IEEE-754 doubles (x0 y0 x1 y1 …), the picture (when the scene holds one)
///                 JPEG bytes (quality 90).
///
/// An entry is trusted only whole: a wrong magic, another format version, a size that disagrees, a checksum
/// that does not match, a payload that is not the expected CBOR map, or one naming another key is removed
/// and logged in one line. Files are written to a temporary name in the same folder, fsync'ed and renamed,
/// so a crash leaves either the old entry, the new one or a stray temporary file (swept after an hour).

#include <cstdint>
#include <mutex>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "config/load.hpp"
#include "config/settings.hpp"
#include "pictures/image_scene.hpp"

namespace hk::app {

/// Version of the entry layout and payload; entries of any other version are stale (removed on load).
inline constexpr std::uint32_t kSceneCacheFormat = 2;

/// Largest entry read or written [bytes] (64 MiB); larger files are not entries.
inline constexpr std::int64_t kSceneCacheMaxEntryBytes = 64LL << 20;

/// [kiosk] scene_cache resolved to a folder (absolute path, no trailing slash added):
///   "off" → "" (no cache);
///   "auto" → $CACHE_DIRECTORY + "/scenes" (systemd's CacheDirectory=; its first entry when colon-separated),
///            else $XDG_CACHE_HOME + "/haptic-kiosk/scenes", else $HOME + "/.cache/haptic-kiosk/scenes",
///            else "" (environment values that are empty or not absolute are skipped, as XDG asks);
///   an absolute folder → itself (validate() allows nothing else).
/// Never throws; reads the environment at each call.
std::string scene_cache_dir(const config::Settings& s);

/// The settings a scene build reads, in field_descriptors() order: every field with ApplyWhen::scene, the
/// [workspace] table (a restart field, but it sets px_to_m) and haptics.max_levels. What SceneCache::key
/// hashes besides the file.
std::vector<const config::FieldDescriptor*> scene_shaping_fields();

/// What tells a picture file as it is now without reading it: its path and stat (device, inode, size,
/// modification and status-change times). Writing to the file, renaming another over it or copying one in
/// its place changes it (the status-change time cannot be set back by a program).
struct FileStamp {
  std::string path;
  std::uint64_t device = 0, inode = 0, size_bytes = 0;
  std::int64_t mtime_ns = 0, ctime_ns = 0;  ///< [ns since the epoch]
};

/// Built scenes on disk, keyed by picture bytes and settings (file layout: see the file comment). Thread
/// safe: load and store may run on several threads at once, and several kiosks may share a folder (the
/// rename makes each entry appear whole).
class SceneCache {
 public:
  /// A cache in folder `dir` (absolute; "" = off: load finds nothing, store writes nothing) holding at most
  /// `max_bytes` bytes of entries (> 0; the least recently used entries go first). Touches no file.
  explicit SceneCache(std::string dir, std::int64_t max_bytes = 512LL << 20);

  /// The folder ("" when off).
  const std::string& dir() const { return dir_; }

  /// The key of a picture file's scene, 64 lower-case hex digits: BLAKE2b-256 over the format version
  /// (kSceneCacheFormat), the program version (PROJECT_VERSION), each scene_shaping_fields() setting as
  /// "table.key" and its exact value (doubles by their bits), and `file_bytes` (the picture file as read).
  /// Settings that do not shape a scene (servo gains, session timing, ...) leave it unchanged. Never throws.
  static std::string key(std::span<const std::uint8_t> file_bytes, const config::Settings& s);

  /// The scene stored under `key`, its Scene rebuilt from its polylines with s.haptics.max_levels (the key
  /// holds max_levels, so the trees are those of the build). image_path is the one the scene was built
  /// with (key() covers the bytes, not the name: a caller loading a copy under another name sets it);
  /// times are the build's, except multires_ms and tree_ms, this rebuild's. with_text is empty and
  /// text_pending false (only complete scenes are stored). The entry's modification time is set to now
  /// (least recently used order); a folder that refuses it still loads.
  /// The rebuilt trees must have segments_after_budget level-0 segments (as every build's do), else the
  /// entry is taken for corrupt.
  /// @return nullopt when off, when there is no entry, or when the entry is corrupt or stale (the file is
  ///         then removed and logged in one line, spdlog::warn). Never throws.
  std::optional<ImageScene> load(const std::string& key, const config::Settings& s) const;

  /// Stores `is` under `key` (a key() value; anything else is refused): only a complete scene
  /// (!is.text_pending, is.scene set). Creates the folder and any missing parent (mode 0700) on first
  /// store; writes a temporary file in the folder, fsyncs it, renames it over `<key>.scene` and fsyncs the
  /// folder; then removes the least recently used entries (by modification time) until the folder's
  /// entries total at most max_bytes, the new one kept.
  /// @return true when the entry is in place; false when off, when the scene is not complete, or when it
  ///         could not be written (read-only folder, disk full, entry larger than max_bytes or
  ///         kSceneCacheMaxEntryBytes): the failure is logged with spdlog::warn once per reason and cache.
  ///         Never throws.
  bool store(const std::string& key, const ImageScene& is);

  /// The stamp of the file at `path` now (stat, links followed); nullopt when it cannot be taken. Never throws.
  static std::optional<FileStamp> stamp(const std::string& path);

  /// The key remembered (remember_key) for a file with this stamp under these settings, read from its ref
  /// file `<dir>/<ref>.ref` (ref: BLAKE2b-256 over the format, program version, scene-shaping settings and
  /// the stamp; content: the key and a line feed). So a picture seen before is found without reading or
  /// hashing its bytes (tens to hundreds of ms for a large photo). nullopt when off, when nothing is
  /// remembered, or when the ref file is not one (then removed). Never throws.
  std::optional<std::string> known_key(const FileStamp& stamp, const config::Settings& s) const;

  /// Remembers that the file with `stamp` (taken before its bytes were read, so a file changed meanwhile
  /// is read again next time) has key `key` (a key() value): its ref file written atomically. Refs whose
  /// entry is gone are removed with the entries evicted. A failure costs only the lookup (logged once).
  /// Never throws.
  void remember_key(const FileStamp& stamp, const config::Settings& s, const std::string& key);

  /// The path of the entry of `key` ("" when off).
  std::string entry_path(const std::string& key) const;

 private:
  /// Logs `what` with spdlog::warn unless `reason` was already logged by this cache.
  void warn_once(const std::string& reason, const std::string& what);
  /// Removes the least recently used entries until they total at most max_bytes_ (`keep` is never removed),
  /// then the ref files whose entry is gone.
  void evict(const std::string& keep);
  /// Writes `bytes` to `<dir_>/<name>` atomically (temporary file, fsync, rename, folder fsync), creating
  /// the folder when missing. @return "" when done, else the failed stage and errno text.
  std::string write_atomically(const std::string& name, const std::vector<std::uint8_t>& bytes) const;

  std::string dir_;
  std::int64_t max_bytes_;
  std::mutex mutex_;              ///< guards warned_ and serialises eviction
  std::set<std::string> warned_;  ///< reasons already logged
};

}  // namespace hk::app
