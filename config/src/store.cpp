/// @file store.cpp
/// The start-up load with its fallbacks (corrupt file kept aside, then .bak, then the defaults), the
/// audit log, and the operator panel's one-field edits (checked with the loader's own checks).

#include "config/store.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>

#include "detail.hpp"

namespace hk::config {

namespace {

using detail::fail;
using detail::one_line;
using detail::Source;

constexpr std::size_t kNoCut = std::numeric_limits<std::size_t>::max();

/// `unix_s` as UTC broken-down time; false when it does not fit.
bool utc(std::int64_t unix_s, std::tm& tm) {
  const auto t = static_cast<std::time_t>(unix_s);
  return static_cast<std::int64_t>(t) == unix_s && ::gmtime_r(&t, &tm) != nullptr;
}

/// strftime of `unix_s` in UTC with `format`; the plain number when the time does not fit.
std::string format_utc(std::int64_t unix_s, const char* format) {
  std::tm tm{};
  char buf[64];
  if (utc(unix_s, tm)) {
    const std::size_t n = std::strftime(buf, sizeof buf, format, &tm);
    if (n > 0) return std::string(buf, n);
  }
  return std::to_string(unix_s);
}

/// "2026-11-22T03:04:05Z".
std::string iso_utc(std::int64_t unix_s) { return format_utc(unix_s, "%Y-%m-%dT%H:%M:%SZ"); }

/// "20261122T030405Z" (for file names).
std::string compact_utc(std::int64_t unix_s) { return format_utc(unix_s, "%Y%m%dT%H%M%SZ"); }

/// True when field `d` holds the same value in `a` and `b` (exact for doubles, as Settings::operator==).
bool same_value(const FieldDescriptor& d, const Settings& a, const Settings& b) {
  const ConstFieldRef rb = d.cref(b);
  return std::visit(
      [&](auto* pa) {
        using P = decltype(pa);
        return *pa == *std::get<P>(rb);
      },
      d.cref(a));
}

/// True when `path` is a regular file this process can open for reading.
bool openable_regular_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return false;
  ::close(fd);
  return true;
}

/// Flushes the directory holding `path` (best effort).
void sync_parent_dir(const std::string& path) {
  std::string dir = path;
  const std::size_t slash = dir.find_last_of('/');
  dir = slash == std::string::npos ? "." : slash == 0 ? "/" : dir.substr(0, slash);
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    (void)::fsync(fd);
    ::close(fd);
  }
}

/// Renames `from` to `to` unless `to` exists; returns 0, EEXIST, or another errno value.
int rename_no_replace(const std::string& from, const std::string& to) {
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return 0;
  const int err = errno;
  if (err != EINVAL && err != ENOSYS) return err;
  // A file system without RENAME_NOREPLACE: check, then rename (a window only a concurrent writer hits).
  struct stat st {};
  if (::lstat(to.c_str(), &st) == 0) return EEXIST;
  return ::rename(from.c_str(), to.c_str()) == 0 ? 0 : errno;
}

/// Moves the bad file at `path` to "<path>.corrupt-<time>[-N]". Returns the new name, or nullopt with
/// `err` set when it could not be moved.
std::optional<std::string> keep_aside(const std::string& path, std::int64_t now_unix_s, int& err) {
  const std::string base = path + ".corrupt-" + compact_utc(now_unix_s);
  for (int n = 0; n < 10000; ++n) {
    const std::string name = n == 0 ? base : base + "-" + std::to_string(n);
    err = rename_no_replace(path, name);
    if (err == 0) {
      sync_parent_dir(path);
      return name;
    }
    if (err != EEXIST) return std::nullopt;
  }
  return std::nullopt;  // err = EEXIST
}

[[noreturn]] void audit_fail(const std::string& log_path, const std::string& what, int err) {
  throw ConfigError(
      log_path, "",
      "audit log '" + one_line(log_path) + "': not written: " + what + ": " + one_line(std::strerror(err)));
}

/// Appends `lines` to the log with one O_APPEND write where possible, then fsync.
void append_to_log(const std::string& log_path, const std::string& lines) {
  const int fd = ::open(log_path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) audit_fail(log_path, "cannot open it", errno);
  const char* p = lines.data();
  std::size_t left = lines.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      audit_fail(log_path, "cannot write", err);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    audit_fail(log_path, "cannot flush it to disk", err);
  }
  if (::close(fd) != 0) audit_fail(log_path, "cannot close it", errno);
}

/// `text` without surrounding spaces and tabs.
std::string_view trim(std::string_view text) {
  const std::size_t b = text.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  const std::size_t e = text.find_last_not_of(" \t");
  return text.substr(b, e - b + 1);
}

/// `t` without one leading '+' that starts a number ("+5" reads as 5, as in TOML).
std::string_view without_plus(std::string_view t) {
  if (t.size() >= 2 && t[0] == '+' && t[1] != '+' && t[1] != '-') t.remove_prefix(1);
  return t;
}

/// `t` as a whole decimal integer; `overflow` set when it is one but does not fit in long long.
std::optional<long long> parse_integer(std::string_view t, bool& overflow) {
  overflow = false;
  t = without_plus(t);
  if (t.empty()) return std::nullopt;
  long long v = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (end != t.data() + t.size()) return std::nullopt;
  if (ec == std::errc::result_out_of_range) {
    overflow = true;
    return std::nullopt;
  }
  if (ec != std::errc{}) return std::nullopt;
  return v;
}

/// `t` as a real number (decimal, exponent, inf, nan); a magnitude beyond double reads as ±inf.
std::optional<double> parse_real(std::string_view t) {
  t = without_plus(t);
  if (t.empty()) return std::nullopt;
  double v = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (end != t.data() + t.size()) return std::nullopt;
  if (ec == std::errc::result_out_of_range) {
    // Too large or too small for a double: too large can't be allowed anyway; too small is as good as 0.
    const bool neg = t.front() == '-';
    const std::size_t e = t.find_first_of("eE");
    const bool tiny = e != std::string_view::npos && t.substr(e + 1).find('-') != std::string_view::npos;
    return tiny ? (neg ? -0.0 : 0.0) : (neg ? -HUGE_VAL : HUGE_VAL);
  }
  if (ec != std::errc{}) return std::nullopt;
  return v;
}

/// The typed text as the loader shows a string value: quoted, one line, at most 80 bytes.
std::string quoted(std::string_view t) { return hk::quoted(t, 80, '"'); }

/// Sets field `d` of `edited` from `text`, or throws ConfigError (source "operator panel") with the
/// loader's message for that value.
void assign_from_text(Settings& edited, const FieldDescriptor& d, std::string_view text, const Source& src) {
  const std::string key = detail::qualified(d);
  switch (d.kind) {
    case FieldKind::real: {
      const std::string_view t = trim(text);
      // As in TOML: an integer is shown as written, a float by its shortest form.
      bool overflow = false;
      std::string shown;
      std::optional<double> v;
      if (auto i = parse_integer(t, overflow)) {
        v = static_cast<double>(*i);
        shown = std::to_string(*i);
      } else if ((v = parse_real(t))) {
        // "inf" and "nan" are shown as the loader shows them; a magnitude beyond double as typed.
        const bool word = t.find_first_of("iInN") != std::string_view::npos;
        shown = std::isfinite(*v) || word ? detail::format_real(*v) : one_line(t, 80);
      }
      if (!v)
        fail(src, key, key + " = " + quoted(t) + " is not a number; expected a number in " + detail::allowed_text(d));
      if (auto why = detail::real_problem(d, *v)) fail(src, key, key + " = " + shown + " " + *why);
      *std::get<double*>(d.ref(edited)) = *v;
      return;
    }
    case FieldKind::integer: {
      const std::string_view t = trim(text);
      bool overflow = false;
      const std::optional<long long> v = parse_integer(t, overflow);
      if (!v) {
        const std::string allowed = detail::allowed_text(d);
        if (overflow) fail(src, key, key + " = " + one_line(t, 80) + " is out of range " + allowed);
        // The loader says "has the wrong type (float)"; shown as typed, "2.0 is not an integer" reads right.
        if (parse_real(t))
          fail(src, key, key + " = " + one_line(t, 80) + " is not an integer; expected an integer in " + allowed);
        fail(src, key, key + " = " + quoted(t) + " is not a number; expected an integer in " + allowed);
      }
      if (auto why = detail::integer_problem(d, *v)) fail(src, key, key + " = " + std::to_string(*v) + " " + *why);
      std::visit(
          [&](auto* p) {
            using T = std::remove_pointer_t<decltype(p)>;
            if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::int64_t>) {
              *p = static_cast<T>(*v);  // in range: bounds of int fields fit in int
            }
          },
          d.ref(edited));
      return;
    }
    case FieldKind::text: {
      if (auto why = detail::text_problem(d, text)) fail(src, key, key + " = " + quoted(text) + " " + *why);
      *std::get<std::string*>(d.ref(edited)) = std::string(text);
      return;
    }
  }
}

}  // namespace

LoadedSettings load_settings_with_fallback(const std::string& path, std::int64_t now_unix_s) {
  LoadedSettings r;
  // What load_settings refuses before reading a byte (missing, a directory, unreadable) is the caller's
  // mistake, not a damaged file: refuse it the same way.
  if (!openable_regular_file(path)) {
    r.settings = load_settings(path);  // throws the loader's message
    return r;
  }
  std::string problem;
  try {
    r.settings = load_settings(path);
    return r;
  } catch (const ConfigError& e) {
    problem = e.what();
  }

  std::string notice = problem;
  int err = 0;
  if (auto kept = keep_aside(path, now_unix_s, err)) {
    r.corrupt_path = *kept;
    notice += "; the file is kept as '" + one_line(*kept, kNoCut) + "'";
  } else {
    notice += "; it could not be moved aside (" + one_line(std::strerror(err)) + ") and stays at '" +
              one_line(path, kNoCut) + "'";
  }

  const std::string bak = path + ".bak";
  struct stat st {};
  if (::stat(bak.c_str(), &st) != 0) {
    r.settings = Settings{};
    r.from = LoadedSettings::From::defaults;
    notice += "; running the defaults (there is no .bak)";
  } else {
    try {
      r.settings = load_settings(bak);
      r.from = LoadedSettings::From::backup;
      notice += "; running the .bak of " + iso_utc(static_cast<std::int64_t>(st.st_mtim.tv_sec)) + " instead";
    } catch (const ConfigError&) {
      r.settings = Settings{};
      r.from = LoadedSettings::From::defaults;
      notice += "; running the defaults (the .bak does not load either)";
    }
  }
  for (char& c : notice)
    if (c == '\n' || c == '\r') c = ' ';
  r.notice = std::move(notice);
  return r;
}

std::string audit_log_path(const Settings& s, const std::string& settings_path) {
  return s.operator_.audit_log.empty() ? settings_path + ".audit.log" : s.operator_.audit_log;
}

std::vector<SettingChange> diff_settings(const Settings& before, const Settings& after) {
  std::vector<SettingChange> changes;
  for (const auto& d : field_descriptors()) {
    if (same_value(d, before, after)) continue;
    SettingChange c{detail::qualified(d), detail::toml_value(d, before), detail::toml_value(d, after)};
    if (d.group == FieldGroup::hidden) {  // a secret (the PIN's hash) never goes into a log
      const bool had = !std::get<const std::string*>(d.cref(before))->empty();
      const bool has = !std::get<const std::string*>(d.cref(after))->empty();
      c.old_value = had ? "(set)" : "\"\"";
      c.new_value = !has ? "(removed)" : had ? "(changed)" : "(set)";
    }
    changes.push_back(std::move(c));
  }
  return changes;
}

void append_audit(const std::string& log_path, std::int64_t unix_s, std::string_view who,
                  const std::vector<SettingChange>& changes) {
  if (changes.empty()) return;
  const std::string prefix = iso_utc(unix_s) + " " + one_line(who, kNoCut) + " ";
  std::string lines;
  for (const auto& c : changes)
    lines += prefix + one_line(c.key, kNoCut) + " " + one_line(c.old_value, kNoCut) + " -> " +
             one_line(c.new_value, kNoCut) + "\n";
  append_to_log(log_path, lines);
}

void append_audit_event(const std::string& log_path, std::int64_t unix_s, std::string_view who,
                        std::string_view event) {
  append_to_log(log_path, iso_utc(unix_s) + " " + one_line(who, kNoCut) + " " + one_line(event, kNoCut) + "\n");
}

std::string set_field_from_text(Settings& s, const FieldDescriptor& d, std::string_view text) {
  const Source src{"operator panel", false};
  Settings edited = s;
  try {
    assign_from_text(edited, d, text, src);
    detail::validate_as(edited, src);  // the cross-field rules, with the new value in place
  } catch (const ConfigError& e) {
    return e.what();
  }
  s = std::move(edited);
  return {};
}

FieldRefusal field_refusal(const FieldDescriptor& d, std::string_view text) {
  switch (d.kind) {
    case FieldKind::real: {
      const std::string_view t = trim(text);
      bool overflow = false;
      std::optional<double> v;
      if (auto i = parse_integer(t, overflow)) v = static_cast<double>(*i);
      if (!v) v = parse_real(t);
      if (!v) return FieldRefusal::not_a_number;
      return detail::real_problem(d, *v) ? FieldRefusal::out_of_range : FieldRefusal::none;
    }
    case FieldKind::integer: {
      const std::string_view t = trim(text);
      bool overflow = false;
      const std::optional<long long> v = parse_integer(t, overflow);
      if (!v)
        return overflow        ? FieldRefusal::out_of_range
               : parse_real(t) ? FieldRefusal::not_an_integer
                               : FieldRefusal::not_a_number;
      return detail::integer_problem(d, *v) ? FieldRefusal::out_of_range : FieldRefusal::none;
    }
    case FieldKind::text:
      if (!detail::text_problem(d, text)) return FieldRefusal::none;
      return d.check ? FieldRefusal::other : FieldRefusal::not_a_choice;
  }
  return FieldRefusal::other;
}

std::string field_text(const Settings& s, const FieldDescriptor& d) {
  return std::visit(
      [](auto* p) -> std::string {
        using T = std::remove_cvref_t<decltype(*p)>;
        if constexpr (std::is_same_v<T, double>) {
          return detail::format_real(*p);
        } else if constexpr (std::is_same_v<T, std::string>) {
          return *p;
        } else {
          return std::to_string(*p);
        }
      },
      d.cref(s));
}

}  // namespace hk::config
