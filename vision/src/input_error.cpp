// One-line InputError messages (see input_error.hpp for why they are centralised).

#include "input_error.hpp"

#include "hk/text.hpp"

namespace hk::vision::detail {

void throw_input_error(const std::string& path, const std::string& problem) {
  throw InputError("image '" + hk::one_line(path) + "': " + problem);
}

}  // namespace hk::vision::detail
