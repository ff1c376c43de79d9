#include "hk/language.hpp"

#include <algorithm>
#include <cctype>

#include "hk/text.hpp"

namespace hk {

bool is_language_tag(std::string_view tag) {
  if (tag.empty() || tag.size() > 35) return false;
  std::size_t start = 0;
  for (int part = 0;; ++part) {
    const std::size_t end = std::min(tag.find('-', start), tag.size());
    const std::string_view sub = tag.substr(start, end - start);
    const bool ok = part == 0 ? sub.size() >= 2 && sub.size() <= 3 &&
                                    std::all_of(sub.begin(), sub.end(), [](char c) { return c >= 'a' && c <= 'z'; })
                              : !sub.empty() && sub.size() <= 8 && std::all_of(sub.begin(), sub.end(), [](char c) {
                                  return std::isalnum(static_cast<unsigned char>(c)) != 0;
                                });
    if (!ok) return false;
    if (end == tag.size()) return true;
    start = end + 1;
  }
}

std::vector<std::string> language_list(std::string_view list, std::string* problem) {
  std::vector<std::string> out;
  const auto fail = [&](const std::string& why) {
    if (problem) *problem = why;
    return std::vector<std::string>();
  };
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t end = std::min(list.find(',', start), list.size());
    std::string_view item = list.substr(start, end - start);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (!is_language_tag(item)) return fail(quoted(item, 40) + " is not a language tag such as \"fr\" or \"pt-BR\"");
    if (std::find(out.begin(), out.end(), item) != out.end()) return fail(quoted(item, 40) + " is given twice");
    out.emplace_back(item);
    if (out.size() > kMaxLanguages) return fail("more than " + std::to_string(kMaxLanguages) + " languages");
    start = end + 1;
  }
  return out;
}

}  // namespace hk
