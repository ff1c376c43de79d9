/// @file save.cpp
/// Settings -> commented TOML text, and the atomic save (temp file, fsync, .bak, rename).

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "config/load.hpp"
#include "detail.hpp"

namespace hk::config {

namespace {

using detail::fail;
using detail::one_line;
using detail::Source;

/// Throws FileWriteError for the file `path`: "<what>: <strerror(err)>".
[[noreturn]] void io_fail(const std::string& path, const std::string& what, int err) {
  throw FileWriteError(path, err, what + ": " + one_line(std::strerror(err)));
}

/// Creates `<prefix>XXXXXX` (a new, unique name) holding `text` with `mode`, fsync'ed and closed, and
/// returns its path. On failure removes it and throws FileWriteError naming `src` (the file being written).
std::string write_temp(const std::string& src, const std::string& prefix, const std::string& text, mode_t mode) {
  std::vector<char> tmpl(prefix.begin(), prefix.end());
  for (char c : std::string_view("XXXXXX")) tmpl.push_back(c);
  tmpl.push_back('\0');
  const int fd = ::mkostemp(tmpl.data(), O_CLOEXEC);
  if (fd < 0) {
    const std::string dir = std::filesystem::path(prefix).parent_path().string();
    io_fail(src, "cannot create a temporary file in '" + one_line(dir) + "'", errno);
  }
  const std::string tmp(tmpl.data());
  const auto abandon = [&](const std::string& what, int err) {
    ::unlink(tmp.c_str());
    io_fail(src, what, err);
  };
  if (int err = detail::write_all(fd, text)) {
    ::close(fd);
    abandon("cannot write '" + one_line(tmp) + "'", err);
  }
  if (::fchmod(fd, mode) != 0) {
    const int err = errno;
    ::close(fd);
    abandon("cannot set the mode of '" + one_line(tmp) + "'", err);
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    abandon("cannot flush '" + one_line(tmp) + "' to disk", err);
  }
  if (::close(fd) != 0) abandon("cannot close '" + one_line(tmp) + "'", errno);
  return tmp;
}

/// Reads the whole file at `path` into `text` and its permission bits into `mode`; returns 0 or an errno value.
int read_whole(const std::string& path, std::string& text, mode_t& mode) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return errno;
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    return err;
  }
  mode = st.st_mode & 07777;
  text.clear();
  char buf[8192];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      return err;
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return 0;
}

/// The mode a saved file gets: an existing regular file's own (`replaces_a_file`), else 0644; 0600 whenever
/// it holds the PIN's hash.
struct TargetMode {
  mode_t mode = 0644;
  bool replaces_a_file = false;
};

/// TargetMode of the file at `path`: `new_mode` for a new file, or always when `force`.
TargetMode target_mode(const std::string& path, mode_t new_mode, bool force) {
  TargetMode t;
  t.mode = new_mode;
  struct stat st {};
  t.replaces_a_file = ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
  if (t.replaces_a_file && !force) t.mode = st.st_mode & 07777;
  return t;
}

/// Keeps the file at `path` as `path`.bak before it is replaced: a second name for the old file (a copy
/// where hard links are not possible), renamed over .bak, so .bak is always a complete file. On failure
/// removes `tmp` (the new file not yet renamed) and throws FileWriteError.
void keep_backup(const std::string& src, const std::string& path, const std::string& tmp,
                 const std::string& temp_prefix) {
  const std::string bak = path + ".bak";
  const std::string what = "cannot keep the old file as '" + one_line(bak) + "'";
  std::string bak_tmp = tmp + ".bak";
  if (::linkat(AT_FDCWD, path.c_str(), AT_FDCWD, bak_tmp.c_str(), AT_SYMLINK_FOLLOW) != 0) {
    const int err = errno;
    bak_tmp.clear();
    // No hard links here (vfat: EPERM), or the target is a symbolic link to another file system:
    // a copy does the same job.
    if (err == EPERM || err == EOPNOTSUPP || err == EXDEV || err == EMLINK) {
      std::string old_text;
      mode_t old_mode = 0600;
      if (int rerr = read_whole(path, old_text, old_mode)) {
        ::unlink(tmp.c_str());
        io_fail(src, what + " (copying it)", rerr);
      }
      try {
        bak_tmp = write_temp(src, temp_prefix, old_text, old_mode);
      } catch (...) {
        ::unlink(tmp.c_str());
        throw;
      }
    } else {
      ::unlink(tmp.c_str());
      io_fail(src, what, err);
    }
  }
  if (::rename(bak_tmp.c_str(), bak.c_str()) != 0) {
    const int err = errno;
    ::unlink(bak_tmp.c_str());
    ::unlink(tmp.c_str());
    io_fail(src, what, err);
  }
}

/// Makes a rename in `dir` durable. Best effort: some file systems refuse fsync on a directory, and the
/// rename before it is already the commit point, so a failure is never reported.
void flush_directory(const std::filesystem::path& dir) {
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace

std::string to_toml(const Settings& settings) {
  static const Settings kDefaults{};
  std::string out;
  out += "# haptic-kiosk settings (TOML), written by hk::config::to_toml.\n";
  out += "# Every key is optional: a key left out keeps its default. Unknown tables or keys, wrong\n";
  out += "# types and values outside the range given above each key are refused with an error.\n";
  for (const auto& table : detail::tables()) {
    out += "\n[";
    out += table.name;
    out += "]\n# ";
    out += table.help;
    out += '\n';
    for (const auto& d : field_descriptors()) {
      if (d.table != table.name) continue;
      out += "\n# ";
      out += d.help;
      if (d.kind == FieldKind::text && d.check) {
        // Free text: its help says what it holds.
      } else if (d.kind == FieldKind::text) {
        out += " Allowed: " + detail::allowed_text(d) + ".";
      } else {
        out += " Range ";
        out += detail::allowed_text(d);
        out += d.kind == FieldKind::integer ? ", an integer." : ".";
      }
      out += " Default " + detail::toml_value(d, kDefaults) + ".\n";
      out += d.key;
      out += " = ";
      out += detail::toml_value(d, settings);
      out += '\n';
    }
  }
  return out;
}

void save_settings_atomic(const Settings& settings, const std::string& path, const SaveOptions& options) {
  const Source src{path, true};
  try {
    detail::validate_as(settings, src);
  } catch (const ConfigError& e) {
    throw ConfigError(e.source(), e.key(), std::string(e.what()) + "; not saved");
  }
  // A file with the PIN's hash is only ever the owner's.
  const bool pin = !settings.operator_.pin_hash.empty();
  try {
    write_file_atomic(to_toml(settings), path, pin ? 0600 : 0644, pin, options);
  } catch (const FileWriteError& e) {
    fail(src, "", std::string("not saved: ") + e.what() + (e.error_number() != 0 ? " (nothing was changed)" : ""));
  }
}

FileWriteError::FileWriteError(std::string path, int error_number, const std::string& message)
    : hk::Error(message), path_(std::move(path)), error_number_(error_number) {}

void write_file_atomic(const std::string& text, const std::string& path, unsigned new_file_mode, bool force_mode,
                       const SaveOptions& options) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  if (target.filename().empty()) throw FileWriteError(path, 0, "the path names no file");
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  const TargetMode mode = target_mode(path, static_cast<mode_t>(new_file_mode & 07777), force_mode);

  // Every temporary name is ".<name>.tmp.*" beside the target, so one pattern finds what a crash left.
  const std::string temp_prefix = detail::temp_prefix(dir.string(), target.filename().string());
  const std::string tmp = write_temp(path, temp_prefix, text, mode.mode);
  bool tmp_renamed = false;  // after the commit point `tmp` no longer names our file
  const auto reached = [&](SaveStage stage) {
    if (!options.hook) return;
    try {
      options.hook(stage);
    } catch (...) {
      if (!tmp_renamed) ::unlink(tmp.c_str());
      throw;
    }
  };
  reached(SaveStage::temp_written);
  if (mode.replaces_a_file && options.keep_backup) keep_backup(path, path, tmp, temp_prefix);
  reached(SaveStage::backup_kept);

  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    io_fail(path, "cannot rename the temporary file over it", err);
  }
  tmp_renamed = true;
  reached(SaveStage::renamed);
  flush_directory(dir);  // the rename is the commit point; this makes it durable
}

}  // namespace hk::config
