// Where Next and Previous go on a stick (app/pictures/include/pictures/stick_pages.hpp): page by page, then to the next
// document's first page or the previous document's last, round the stick; the flow and the stick service's builds ahead
// both follow it.
#include <gtest/gtest.h>

#include <vector>

#include "pictures/stick_pages.hpp"

namespace hk::app {
namespace {

TEST(StickPages, NextAndPreviousWalkPagesThenDocumentsRoundTheStick) {
  const std::vector<int> pages = {1, 2, 3};  // a picture, a 2-page PDF, a 3-page PDF
  EXPECT_EQ(step_stick_page(pages, {-1, 1}, +1), (StickPage{0, 1})) << "from no page: the first document's first page";
  EXPECT_EQ(step_stick_page(pages, {-1, 1}, -1), (StickPage{2, 3})) << "from no page: the last document's last page";
  EXPECT_EQ(step_stick_page(pages, {0, 1}, +1), (StickPage{1, 1}));
  EXPECT_EQ(step_stick_page(pages, {1, 1}, +1), (StickPage{1, 2}));
  EXPECT_EQ(step_stick_page(pages, {1, 2}, +1), (StickPage{2, 1}));
  EXPECT_EQ(step_stick_page(pages, {2, 3}, +1), (StickPage{0, 1})) << "round the stick";
  EXPECT_EQ(step_stick_page(pages, {2, 1}, -1), (StickPage{1, 2})) << "the previous document's last page";
  EXPECT_EQ(step_stick_page(pages, {0, 1}, -1), (StickPage{2, 3})) << "round the stick backwards";
  EXPECT_EQ(step_stick_page(pages, {7, 1}, +1), (StickPage{0, 1})) << "a document no longer listed counts as none";
  // Every page is reached once in a walk of Next presses, and Previous walks it back.
  int total = 0;
  for (int p : pages) total += p;
  StickPage at{-1, 1};
  std::vector<StickPage> seen;
  for (int i = 0; i < total; ++i) {
    at = step_stick_page(pages, at, +1);
    for (const StickPage& s : seen)
      EXPECT_FALSE(s == at) << "page " << at.page << " of document " << at.document << " twice";
    seen.push_back(at);
  }
  for (int i = total - 1; i > 0; --i) {
    at = step_stick_page(pages, at, -1);
    EXPECT_EQ(at, seen[static_cast<std::size_t>(i - 1)]);
  }
  const std::vector<int> single = {1};
  EXPECT_EQ(step_stick_page(single, {0, 1}, +1), (StickPage{0, 1})) << "one picture: Next stays on it";
  const std::vector<int> unknown = {0};
  EXPECT_EQ(step_stick_page(unknown, {0, 1}, -1), (StickPage{0, 1})) << "a page count under 1 counts as 1";
}

}  // namespace
}  // namespace hk::app
