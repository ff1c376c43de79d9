// One-line InputError messages (see input_error.hpp for why they are centralised).

#include "input_error.hpp"

#include <cstdio>

namespace hk::vision::detail {

std::string printable_path(const std::string& path) {
  std::string out;
  out.reserve(path.size());
  for (const char c : path) {
    const auto b = static_cast<unsigned char>(c);
    if (b < 0x20 || b == 0x7F) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", b);
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

void throw_input_error(const std::string& path, const std::string& problem) {
  throw InputError("image '" + printable_path(path) + "': " + problem);
}

}  // namespace hk::vision::detail
