#pragma once
/// @file stick_pages.hpp
/// Where Next and Previous go on a USB stick: page by page through a document, then on to the next
/// document's first page (or the previous document's last), round the stick. One rule for the flow that
/// asks for pages and for the stick service that builds the neighbours ahead.

#include <cstddef>
#include <span>

namespace hk::app {

/// A page of a stick's document: `document` indexes the stick's listing (−1: none yet), `page` counts from 1
/// (a picture has one page).
struct StickPage {
  int document = -1;
  int page = 1;
  friend bool operator==(const StickPage&, const StickPage&) = default;
};

/// The page one step (`delta` > 0: Next, else Previous) from `at`, on a stick whose documents have
/// `pages[d]` pages each (≥ 1). From no page (`at.document` < 0) Next goes to the first document's first
/// page and Previous to the last document's last page. `pages` must not be empty. Never throws.
inline StickPage step_stick_page(std::span<const int> pages, StickPage at, int delta) {
  const int n = static_cast<int>(pages.size());
  auto pages_of = [&](int d) {
    return pages[static_cast<std::size_t>(d)] < 1 ? 1 : pages[static_cast<std::size_t>(d)];
  };
  if (at.document < 0 || at.document >= n) {
    const int d = delta > 0 ? 0 : n - 1;
    return {d, delta > 0 ? 1 : pages_of(d)};
  }
  if (delta > 0) {
    if (at.page + 1 > pages_of(at.document)) return {(at.document + 1) % n, 1};
    return {at.document, at.page + 1};
  }
  if (at.page - 1 < 1) {
    const int d = (at.document - 1 + n) % n;
    return {d, pages_of(d)};
  }
  return {at.document, at.page - 1};
}

}  // namespace hk::app
