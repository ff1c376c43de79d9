/// @file load.cpp
/// TOML text / file -> Settings, refusing anything unknown, mistyped or out of range.

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include <toml++/toml.h>

#include "config/device_profile.hpp"
#include "config/load.hpp"
#include "detail.hpp"

namespace hk::config {

namespace {

using detail::fail;
using detail::one_line;
using detail::Source;

std::size_t line_of(const toml::source_region& r) { return static_cast<std::size_t>(r.begin.line); }

const char* type_name(toml::node_type t) {
  switch (t) {
    case toml::node_type::string:
      return "string";
    case toml::node_type::integer:
      return "integer";
    case toml::node_type::floating_point:
      return "float";
    case toml::node_type::boolean:
      return "boolean";
    case toml::node_type::table:
      return "table";
    case toml::node_type::array:
      return "array";
    case toml::node_type::date:
      return "date";
    case toml::node_type::time:
      return "time";
    case toml::node_type::date_time:
      return "date-time";
    default:
      return "none";
  }
}

/// The value of a node as it would read in the file (short, one line).
std::string value_text(const toml::node& n) {
  if (auto* v = n.as_integer()) return std::to_string(v->get());
  if (auto* v = n.as_floating_point()) return detail::format_real(v->get());
  if (auto* v = n.as_string()) return hk::quoted(v->get(), 80, '"');
  if (auto* v = n.as_boolean()) return v->get() ? "true" : "false";
  if (n.is_table()) return "{...}";
  if (n.is_array()) return "[...]";
  return std::string("<") + type_name(n.type()) + ">";
}

/// Edit distance, for "did you mean" suggestions.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

/// The closest candidate to `word` if it is close enough to be a likely typo.
template <typename Range>
std::string_view closest(std::string_view word, const Range& candidates) {
  std::string_view best;
  std::size_t best_d = std::numeric_limits<std::size_t>::max();
  for (std::string_view c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  const std::size_t limit = std::max<std::size_t>(2, word.size() / 4);
  return best_d <= limit ? best : std::string_view{};
}

bool is_table_name(std::string_view name) {
  for (const auto& t : detail::tables())
    if (t.name == name) return true;
  return false;
}

std::vector<std::string_view> table_names() {
  std::vector<std::string_view> v;
  for (const auto& t : detail::tables()) v.push_back(t.name);
  return v;
}

[[noreturn]] void unknown_table(const Source& src, std::string_view name, const toml::node& node, std::size_t line) {
  const std::string shown = one_line(name, 60);
  if (!node.is_table() && !node.is_array_of_tables()) {
    // A bare key outside any table.
    std::string body = "unknown key '" + shown + "' outside any table";
    for (const auto& d : field_descriptors())
      if (d.key == name) {
        body += " (did you mean " + detail::qualified(d) + ", i.e. under [" + std::string(d.table) + "]?)";
        fail(src, std::string(name), body, line);
      }
    body +=
        "; keys belong under a table: [haptics], [device], [hand], [vision], [workspace], [audio], [kiosk], [stick], "
        "[camera], [keys] or [operator]";
    fail(src, shown, body, line);  // a quoted key may hold any character: key() is escaped as the message is
  }
  std::string body = "unknown table [" + shown + "]";
  if (auto s = closest(name, table_names()); !s.empty()) body += " (did you mean [" + std::string(s) + "]?)";
  fail(src, "[" + shown + "]", body, line);
}

[[noreturn]] void unknown_key(const Source& src, std::string_view table, std::string_view key, std::size_t line) {
  const std::string shown = std::string(table) + "." + one_line(key, 60);
  std::string body = "unknown key " + shown;
  std::vector<std::string_view> same_table;
  for (const auto& d : field_descriptors())
    if (d.table == table) same_table.push_back(d.key);
  if (auto s = closest(key, same_table); !s.empty()) {
    body += " (did you mean " + std::string(table) + "." + std::string(s) + "?)";
  } else {
    for (const auto& d : field_descriptors())
      if (d.key == key) {
        body += " (did you mean " + detail::qualified(d) + "? it belongs under [" + std::string(d.table) + "])";
        break;
      }
  }
  fail(src, shown, body, line);
}

[[noreturn]] void wrong_type(const Source& src, const FieldDescriptor& d, const toml::node& node,
                             const char* expected) {
  const std::string key = detail::qualified(d);
  fail(src, key,
       key + " = " + value_text(node) + " has the wrong type (" + type_name(node.type()) + "); expected " + expected +
           " " + detail::allowed_text(d),
       line_of(node.source()));
}

void assign(const FieldDescriptor& d, const toml::node& node, Settings& s, const Source& src) {
  const std::string key = detail::qualified(d);
  const std::size_t line = line_of(node.source());
  switch (d.kind) {
    case FieldKind::real: {
      double v = 0;
      if (auto* f = node.as_floating_point()) {
        v = f->get();
      } else if (auto* i = node.as_integer()) {
        v = static_cast<double>(i->get());
      } else {
        wrong_type(src, d, node, "a number in");
      }
      if (auto why = detail::real_problem(d, v)) fail(src, key, key + " = " + value_text(node) + " " + *why, line);
      *std::get<double*>(d.ref(s)) = v;
      break;
    }
    case FieldKind::integer: {
      auto* i = node.as_integer();
      if (!i) wrong_type(src, d, node, "an integer in");
      const std::int64_t v = i->get();
      if (auto why = detail::integer_problem(d, v)) fail(src, key, key + " = " + value_text(node) + " " + *why, line);
      std::visit(
          [&](auto* p) {
            using T = std::remove_pointer_t<decltype(p)>;
            if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::int64_t>) {
              *p = static_cast<T>(v);  // in range: bounds of int fields fit in int
            }
          },
          d.ref(s));
      break;
    }
    case FieldKind::text: {
      auto* str = node.as_string();
      if (!str) wrong_type(src, d, node, "a string,");
      if (auto why = detail::text_problem(d, str->get()))
        fail(src, key, key + " = " + value_text(node) + " " + *why, line);
      *std::get<std::string*>(d.ref(s)) = str->get();
      break;
    }
  }
}

Settings parse_from(std::string_view text, const Source& src) {
  toml::table root;
  try {
    root = toml::parse(text, src.name);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    fail(src, "",
         "TOML syntax error at line " + std::to_string(b.line) + ", column " + std::to_string(b.column) + ": " +
             one_line(e.description(), 160));
  }

  // A [device] type that names a USB board brings its profile: the defaults every key not in the file takes.
  Settings s;
  if (const toml::table* device = root["device"].as_table())
    if (const auto* type = device->get("type"); type && type->is_string() && is_usb_type(type->as_string()->get()))
      s = profile_defaults(type->as_string()->get());
  for (auto&& [tkey, tnode] : root) {
    const std::string_view tname = tkey.str();
    if (!is_table_name(tname)) unknown_table(src, tname, tnode, line_of(tkey.source()));
    const toml::table* table = tnode.as_table();
    if (!table)
      fail(src, std::string(1, '[').append(tname).append("]"),
           std::string(tname) + " = " + value_text(tnode) + " has the wrong type (" + type_name(tnode.type()) +
               "); expected a table [" + std::string(tname) + "]",
           line_of(tnode.source()));
    for (auto&& [key, node] : *table) {
      const FieldDescriptor* d = find_field(tname, key.str());
      if (!d) unknown_key(src, tname, key.str(), line_of(key.source()));
      assign(*d, node, s, src);
    }
  }
  detail::validate_as(s, src);
  return s;
}

struct FileCloser {
  void operator()(std::FILE* f) const noexcept { std::fclose(f); }
};

}  // namespace

Settings parse_settings(std::string_view toml_text, const std::string& source_name) {
  return parse_from(toml_text, Source{source_name, true});
}

Settings load_settings(const std::string& path) {
  const Source src{path, true};
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) {
    const std::string why = ec ? ec.message() : std::string(std::strerror(ENOENT));
    fail(src, "", "cannot open the settings file: " + one_line(why));
  }
  if (fs::is_directory(st)) fail(src, "", "is a directory, not a settings file");
  if (!fs::is_regular_file(st)) fail(src, "", "is not a regular file");

  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "rb"));
  if (!f) fail(src, "", "cannot open the settings file: " + one_line(std::strerror(errno)));
  std::string text;
  std::array<char, 8192> buf;
  for (;;) {
    const std::size_t n = std::fread(buf.data(), 1, buf.size(), f.get());
    text.append(buf.data(), n);
    if (text.size() > kMaxConfigFileBytes)
      fail(src, "",
           "is larger than the limit of " + std::to_string(kMaxConfigFileBytes) + " bytes for a settings file");
    if (n < buf.size()) {
      if (std::ferror(f.get())) fail(src, "", "cannot read the settings file: " + one_line(std::strerror(errno)));
      break;
    }
  }
  return parse_from(text, src);
}

}  // namespace hk::config
