// Built scenes on disk (scene_cache.hpp).
#include "pictures/scene_cache.hpp"

#include "pictures/kiosk_folders.hpp"

#include "pictures/scene_entry.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string_view>
#include <utility>

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <spdlog/spdlog.h>

#ifndef HK_PROGRAM_VERSION
#error "HK_PROGRAM_VERSION (the project's version) must be defined by the build"
#endif

namespace hk::app {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kSuffix = ".scene";
constexpr std::string_view kRefSuffix = ".ref";
constexpr std::size_t kRefBytes = 2 * crypto_generichash_BYTES + 1;  // a key and a line feed
constexpr std::string_view kTempPrefix = ".tmp-";
/// A temporary file this old is a crashed writer's [s].
constexpr auto kStaleTemp = std::chrono::hours(1);

std::string errno_text(int e) { return std::strerror(e); }

/// Reads the whole file `fd` of `size` bytes; false on a read error or a short read.
bool read_all(int fd, std::uint8_t* out, std::size_t size) {
  std::size_t got = 0;
  while (got < size) {
    const ssize_t n = ::read(fd, out + got, size - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    got += static_cast<std::size_t>(n);
  }
  return true;
}

/// Writes all of `data` to `fd`; false with errno set on failure.
bool write_all(int fd, const std::uint8_t* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return false;
    if (n == 0) {
      errno = ENOSPC;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

/// Creates `dir` and every missing parent with mode 0700; false with errno set when it could not (a
/// component that exists but is no folder: ENOTDIR).
bool make_dirs(const std::string& dir) {
  std::string prefix;
  std::size_t pos = 0;
  while (pos != std::string::npos) {
    pos = dir.find('/', pos + 1);
    prefix = dir.substr(0, pos);
    if (prefix.empty()) continue;
    if (::mkdir(prefix.c_str(), 0700) == 0) continue;
    if (errno != EEXIST) return false;
    struct stat st {};
    if (::stat(prefix.c_str(), &st) != 0) return false;
    if (!S_ISDIR(st.st_mode)) {
      errno = ENOTDIR;
      return false;
    }
  }
  return true;
}

/// Hash input helpers: lengths and numbers as fixed-size little-endian words, so no two inputs hash alike.
void hash_u64(crypto_generichash_state& st, std::uint64_t v) {
  std::uint8_t b[8];
  for (int i = 0; i < 8; ++i) b[i] = static_cast<std::uint8_t>(v >> (8 * i));
  crypto_generichash_update(&st, b, sizeof b);
}
void hash_text(crypto_generichash_state& st, std::string_view s) {
  hash_u64(st, s.size());
  crypto_generichash_update(&st, reinterpret_cast<const unsigned char*>(s.data()), s.size());
}

/// Starts a BLAKE2b-256 over `domain`, the entry format, the program version and every
/// scene_shaping_fields() setting ("table.key" and its exact value: doubles by their bits).
void begin_settings_hash(crypto_generichash_state& st, std::string_view domain, const config::Settings& s) {
  [[maybe_unused]] const int ready = sodium_init();  // picks the fastest BLAKE2b; the portable one serves when it fails
  crypto_generichash_init(&st, nullptr, 0, crypto_generichash_BYTES);
  hash_text(st, domain);
  hash_u64(st, kSceneCacheFormat);
  hash_text(st, HK_PROGRAM_VERSION);
  for (const config::FieldDescriptor* d : scene_shaping_fields()) {
    hash_text(st, std::string(d->table) + "." + std::string(d->key));
    std::visit(
        [&st](const auto* p) {
          using T = std::remove_cv_t<std::remove_pointer_t<decltype(p)>>;
          if constexpr (std::is_same_v<T, double>) {
            hash_text(st, "d");
            hash_u64(st, std::bit_cast<std::uint64_t>(*p));
          } else if constexpr (std::is_same_v<T, std::string>) {
            hash_text(st, "s");
            hash_text(st, *p);
          } else {
            hash_text(st, "i");
            hash_u64(st, static_cast<std::uint64_t>(static_cast<std::int64_t>(*p)));
          }
        },
        d->cref(s));
  }
}

/// The hash as 64 lower-case hex digits.
std::string final_hex(crypto_generichash_state& st) {
  std::array<std::uint8_t, crypto_generichash_BYTES> h{};
  crypto_generichash_final(&st, h.data(), h.size());
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * h.size());
  for (std::uint8_t b : h) {
    out.push_back(kHex[b >> 4]);
    out.push_back(kHex[b & 15]);
  }
  return out;
}

}  // namespace

std::string scene_cache_dir(const config::Settings& s) {
  return kiosk_folder(s.kiosk.scene_cache, "CACHE_DIRECTORY", "XDG_CACHE_HOME", ".cache", "scenes");
}

std::vector<const config::FieldDescriptor*> scene_shaping_fields() {
  std::vector<const config::FieldDescriptor*> out;
  for (const config::FieldDescriptor& d : config::field_descriptors()) {
    if (d.apply == config::ApplyWhen::scene || d.table == "workspace" ||
        (d.table == "haptics" && d.key == "max_levels"))
      out.push_back(&d);
  }
  return out;
}

SceneCache::SceneCache(std::string dir, std::int64_t max_bytes)
    : dir_(std::move(dir)), max_bytes_(std::max<std::int64_t>(max_bytes, 1)) {
  while (dir_.size() > 1 && dir_.back() == '/') dir_.pop_back();
}

std::string SceneCache::entry_path(const std::string& key) const {
  if (dir_.empty()) return "";
  return dir_ + "/" + key + std::string(kSuffix);
}

std::string SceneCache::key(std::span<const std::uint8_t> file_bytes, const config::Settings& s) {
  crypto_generichash_state st;
  begin_settings_hash(st, "haptic-kiosk scene", s);
  hash_text(st, "file");
  hash_u64(st, file_bytes.size());
  crypto_generichash_update(&st, file_bytes.data(), file_bytes.size());
  return final_hex(st);
}

std::optional<FileStamp> SceneCache::stamp(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::nullopt;
  FileStamp f;
  f.path = path;
  f.device = static_cast<std::uint64_t>(st.st_dev);
  f.inode = static_cast<std::uint64_t>(st.st_ino);
  f.size_bytes = static_cast<std::uint64_t>(st.st_size);
  f.mtime_ns = static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
  f.ctime_ns = static_cast<std::int64_t>(st.st_ctim.tv_sec) * 1'000'000'000 + st.st_ctim.tv_nsec;
  return f;
}

namespace {

/// The name of the ref file of a stamp under settings (64 hex digits and ".ref").
std::string ref_name(const FileStamp& f, const config::Settings& s) {
  crypto_generichash_state st;
  begin_settings_hash(st, "haptic-kiosk file stamp", s);
  hash_text(st, f.path);
  for (const std::uint64_t v : {f.device, f.inode, f.size_bytes, static_cast<std::uint64_t>(f.mtime_ns),
                                static_cast<std::uint64_t>(f.ctime_ns)})
    hash_u64(st, v);
  return final_hex(st) + std::string(kRefSuffix);
}

}  // namespace

std::optional<std::string> SceneCache::known_key(const FileStamp& stamp, const config::Settings& s) const {
  if (dir_.empty()) return std::nullopt;
  const std::string path = dir_ + "/" + ref_name(stamp, s);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) return std::nullopt;
  std::array<char, kRefBytes + 1> buf{};
  const ssize_t n = ::read(fd, buf.data(), buf.size());
  ::close(fd);
  const std::string key(buf.data(), n > 0 ? static_cast<std::size_t>(n) : 0);
  if (key.size() == kRefBytes && key.back() == '\n' && is_key(key.substr(0, kRefBytes - 1)))
    return key.substr(0, kRefBytes - 1);
  ::unlink(path.c_str());
  spdlog::warn("scene cache: ref '{}' does not hold a key; removed", path);
  return std::nullopt;
}

void SceneCache::remember_key(const FileStamp& stamp, const config::Settings& s, const std::string& key) {
  if (dir_.empty() || !is_key(key)) return;
  const std::string text = key + "\n";
  const std::string failed = write_atomically(ref_name(stamp, s), std::vector<std::uint8_t>(text.begin(), text.end()));
  if (!failed.empty())
    warn_once(failed, "in '" + dir_ + "': cannot " + failed + "; pictures are read again to find their scenes");
}

std::string SceneCache::write_atomically(const std::string& name, const std::vector<std::uint8_t>& bytes) const {
  auto failed = [](const std::string& stage, int err) { return stage + ": " + errno_text(err); };
  if (!make_dirs(dir_)) return failed("create the folder", errno);
  std::string temp = dir_ + "/" + std::string(kTempPrefix) + name + "-XXXXXX";
  const int fd = ::mkostemp(temp.data(), O_CLOEXEC);
  if (fd < 0) return failed("create a file", errno);
  const bool written = write_all(fd, bytes.data(), bytes.size()) && ::fsync(fd) == 0;
  const int write_errno = errno;
  const bool closed = ::close(fd) == 0;
  if (!written || !closed) {
    const int err = written ? errno : write_errno;
    ::unlink(temp.c_str());
    return failed("write a file", err);
  }
  if (::rename(temp.c_str(), (dir_ + "/" + name).c_str()) != 0) {
    const int err = errno;
    ::unlink(temp.c_str());
    return failed("rename a file", err);
  }
  const int dfd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {  // the rename itself durable; a failure here costs only that
    ::fsync(dfd);
    ::close(dfd);
  }
  return "";
}

std::optional<ImageScene> SceneCache::load(const std::string& key, const config::Settings& s) const {
  if (dir_.empty() || !is_key(key)) return std::nullopt;
  const std::string path = entry_path(key);
  auto bad = [&path](const std::string& why) -> std::optional<ImageScene> {
    const bool removed = ::unlink(path.c_str()) == 0;
    spdlog::warn("scene cache: entry '{}' {}; {}", path, why,
                 removed ? "removed" : "could not be removed: " + errno_text(errno));
    return std::nullopt;
  };
  try {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) {
      if (errno == ENOENT || errno == ENOTDIR) return std::nullopt;  // no entry, or no folder (store says why)
      if (errno == ELOOP) return bad("is a symbolic link");
      spdlog::warn("scene cache: cannot read entry '{}': {}", path, errno_text(errno));
      return std::nullopt;
    }
    struct Closer {
      int fd;
      ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0) return std::nullopt;
    if (!S_ISREG(st.st_mode)) return bad("is not a regular file");
    if (st.st_size < static_cast<off_t>(kSceneEntryPrefixBytes))
      return bad("is too short to be an entry (" + std::to_string(st.st_size) + " bytes)");
    if (st.st_size > kSceneCacheMaxEntryBytes)
      return bad("is larger than an entry may be (" + std::to_string(st.st_size) + " bytes)");
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(st.st_size));
    if (!read_all(fd, bytes.data(), bytes.size())) return bad("could not be read whole");
    ImageScene is = decode_entry(bytes, key);
    bytes = {};
    try {
      is.scene = std::make_unique<Scene>(Scene::build(is.polylines, s.haptics.max_levels));
    } catch (const hk::Error& e) {
      return bad(std::string("holds curves the trees cannot be built from: ") + e.what());
    }
    if (is.scene->total_segments(0) != is.segments_after_budget)
      return bad("rebuilds to another number of level-0 segments");
    is.times.multires_ms = is.scene->build_times().multires_ms;
    is.times.tree_ms = is.scene->build_times().tree_ms;
    if (is.descriptors.size() != is.polylines.size()) describe_scene_shapes(is);  // an entry written without them
    ::futimens(fd, nullptr);  // most recently used; a read-only folder keeps the old time
    return is;
  } catch (const BadEntry& e) {
    return bad(e.why);
  } catch (const std::exception& e) {
    spdlog::warn("scene cache: entry '{}' not loaded: {}", path, e.what());
    return std::nullopt;
  } catch (...) {
    spdlog::warn("scene cache: entry '{}' not loaded", path);
    return std::nullopt;
  }
}

void SceneCache::warn_once(const std::string& reason, const std::string& what) {
  const std::lock_guard lock(mutex_);
  if (warned_.insert(reason).second) spdlog::warn("scene cache: {}", what);
}

bool SceneCache::store(const std::string& key, const ImageScene& is) {
  if (dir_.empty()) return false;
  if (!is_key(key)) {
    warn_once("key", "'" + key + "' is not a scene key; nothing stored");
    return false;
  }
  if (is.text_pending || !is.scene) return false;  // not complete: its text is still to be read, or no trees
  std::vector<std::uint8_t> bytes;
  try {
    bytes = encode_entry(key, is);
  } catch (const BadEntry& e) {
    warn_once("encode", "a scene could not be stored: " + e.why);
    return false;
  } catch (const std::exception& e) {
    warn_once("encode", std::string("a scene could not be stored: ") + e.what());
    return false;
  }
  const auto size = static_cast<std::int64_t>(bytes.size());
  if (size > kSceneCacheMaxEntryBytes || size > max_bytes_) {
    warn_once("size", "a scene of " + std::to_string(size) + " bytes is larger than the cache of '" + dir_ +
                          "' keeps (" + std::to_string(std::min(max_bytes_, kSceneCacheMaxEntryBytes)) +
                          " bytes); not stored");
    return false;
  }
  const std::string failed = write_atomically(key + std::string(kSuffix), bytes);
  if (!failed.empty()) {
    warn_once(failed, "in '" + dir_ + "': cannot " + failed + "; built scenes are not kept");
    return false;
  }
  try {
    evict(key);
  } catch (const std::exception& e) {
    warn_once("evict", std::string("cannot keep '") + dir_ + "' under its size: " + e.what());
  }
  return true;
}

void SceneCache::evict(const std::string& keep) {
  const std::lock_guard lock(mutex_);
  struct Entry {
    std::string path;
    std::int64_t bytes;
    std::int64_t mtime_ns;
  };
  std::vector<Entry> entries;
  std::vector<std::string> refs;
  std::int64_t total = 0;
  const auto now = std::chrono::system_clock::now();
  std::error_code ec;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const std::string path = it->path().string();
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
    const std::int64_t mtime_ns = static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
    if (name.starts_with(kTempPrefix)) {  // a crashed writer's, or one being written now (recent)
      const auto age =
          now - std::chrono::system_clock::time_point(std::chrono::duration_cast<std::chrono::system_clock::duration>(
                    std::chrono::nanoseconds(mtime_ns)));
      if (age > kStaleTemp) ::unlink(path.c_str());
      continue;
    }
    if (name.ends_with(kRefSuffix)) {
      refs.push_back(path);
      continue;
    }
    if (!name.ends_with(kSuffix) || !is_key(name.substr(0, name.size() - kSuffix.size()))) continue;
    total += st.st_size;
    if (name.substr(0, name.size() - kSuffix.size()) != keep) entries.push_back({path, st.st_size, mtime_ns});
  }
  if (total > max_bytes_) {
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
      return a.mtime_ns != b.mtime_ns ? a.mtime_ns < b.mtime_ns : a.path < b.path;
    });
    for (const Entry& e : entries) {
      if (total <= max_bytes_) break;
      if (::unlink(e.path.c_str()) == 0 || errno == ENOENT) total -= e.bytes;
    }
  }
  // A ref whose entry is gone points nowhere: removed (a lookup through it would read the file anyway).
  for (const std::string& ref : refs) {
    std::array<char, kRefBytes> buf{};
    const int fd = ::open(ref.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) continue;
    const ssize_t n = ::read(fd, buf.data(), buf.size());
    ::close(fd);
    const std::string key(buf.data(), n == static_cast<ssize_t>(kRefBytes) ? kRefBytes - 1 : 0);
    struct stat st {};
    if (!is_key(key) || ::stat(entry_path(key).c_str(), &st) != 0) ::unlink(ref.c_str());
  }
}

}  // namespace hk::app
