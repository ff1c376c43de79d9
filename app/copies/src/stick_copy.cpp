// A take-home copy written onto the visitor's stick (stick_copy.hpp).
#include "copies/stick_copy.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "hk/text.hpp"
#include "hk/unique_fd.hpp"

namespace hk::app {
namespace {

/// Whether a byte is refused in FAT and exFAT names.
bool refused_in_name(unsigned char c) {
  return c < 0x20 || c == 0x7f || std::strchr("\"*/:<>?\\|", static_cast<char>(c)) != nullptr;
}

/// `s` cut to at most `max` bytes, at the start of a UTF-8 character.
std::string cut_utf8(std::string s, std::size_t max) {
  if (s.size() <= max) return s;
  std::size_t end = max;
  while (end > 0 && (static_cast<unsigned char>(s[end]) & 0xC0) == 0x80) --end;
  s.resize(end);
  return s;
}

std::string trimmed(std::string s) {
  const auto edge = [](char c) { return c == ' ' || c == '.'; };
  while (!s.empty() && edge(s.back())) s.pop_back();
  std::size_t i = 0;
  while (i < s.size() && edge(s[i])) ++i;
  return s.substr(i);
}

/// Writes `bytes` to a new file `name` in the folder `dir`. 0, or the errno of what failed.
int write_new_file(int dir, const std::string& name, const std::string& bytes) {
  hk::UniqueFd fd(::openat(dir, name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644));
  if (fd.get() < 0) return errno;
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd.get(), bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n < 0 ? errno : ENOSPC;
    done += static_cast<std::size_t>(n);
  }
  // FAT reserves clusters at close on some drivers: a full stick can first say so here.
  if (::fsync(fd.get()) != 0 && errno != EINVAL) return errno;
  const int raw = fd.release();
  return ::close(raw) == 0 ? 0 : errno;
}

bool no_room(int err) { return err == ENOSPC || err == EDQUOT || err == EFBIG; }

}  // namespace

std::string stick_safe_name(const std::string& text, const std::string& fallback) {
  std::string out;
  for (const char c : text) out += refused_in_name(static_cast<unsigned char>(c)) ? '-' : c;
  out = trimmed(cut_utf8(trimmed(out), kCopyNameMaxBytes));
  return out.empty() ? fallback : out;
}

SavedCopy save_copy_folder(const TactileGraphic& g, const std::string& top, const std::string& folder_pattern,
                           BrailleGrade grade) {
  const std::string title = stick_safe_name(g.title, "haptic-kiosk");
  std::string base = folder_pattern;
  if (const std::size_t at = base.find("{title}"); at != std::string::npos) base.replace(at, 7, title);
  base = stick_safe_name(base, title);
  const std::string shown_top = hk::quoted(top);

  // Everything is drawn before the stick is touched: a failure to draw leaves nothing to undo.
  const std::vector<std::pair<std::string, std::string>> files{
      {title + ".pdf", tactile_pdf(g)}, {title + ".svg", tactile_svg(g)}, {title + ".brf", tactile_brf(g, grade)}};

  hk::UniqueFd top_fd(::open(top.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (top_fd.get() < 0) throw CopyError("copy to " + shown_top + ": cannot open the folder: " + std::strerror(errno));
  SavedCopy saved;
  for (int n = 1; n <= kCopyFolderTries && saved.folder.empty(); ++n) {
    const std::string name = n == 1 ? base : base + " " + std::to_string(n);
    if (::mkdirat(top_fd.get(), name.c_str(), 0755) == 0) {
      saved.folder = name;
    } else if (errno != EEXIST) {
      const int err = errno;
      const std::string why =
          "copy to " + shown_top + ": cannot make the folder " + hk::quoted(name) + ": " + std::strerror(err);
      if (no_room(err)) throw CopyNoRoomError(why);
      throw CopyError(why);
    }
  }
  if (saved.folder.empty()) {
    throw CopyError("copy to " + shown_top + ": " + std::to_string(kCopyFolderTries) + " folders named " +
                    hk::quoted(base) + " are already there");
  }

  hk::UniqueFd dir(::openat(top_fd.get(), saved.folder.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  int err = dir.get() < 0 ? errno : 0;
  std::string failed = saved.folder;
  for (const auto& [name, bytes] : files) {
    if (err != 0) break;
    err = write_new_file(dir.get(), name, bytes);
    saved.files.push_back(name);  // created, maybe partly: undone below if anything failed
    if (err != 0) failed = saved.folder + "/" + name;
  }
  if (err == 0) return saved;

  // Undo: the files this call created, then its folder.
  for (const std::string& name : saved.files) (void)::unlinkat(dir.get(), name.c_str(), 0);
  dir.reset();
  (void)::unlinkat(top_fd.get(), saved.folder.c_str(), AT_REMOVEDIR);
  const std::string why = "copy to " + shown_top + ": cannot write " + hk::quoted(failed) + ": " + std::strerror(err);
  if (no_room(err)) throw CopyNoRoomError(why);
  throw CopyError(why);
}

}  // namespace hk::app
