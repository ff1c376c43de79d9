// Fuzz harness: a file of names staff give regions, W3C Web Annotation as IIIF publishes it
// (app/formats/include/formats/annotations.hpp).
//
// Entry point: hk::app::parse_annotations. Properties:
//  - a refusal is an AnnotationError whose what() is one line naming the source, of bounded length;
//  - an accepted file keeps the documented limits: at most kMaxAnnotations annotations, each with a name or a
//    description within its byte limit and valid UTF-8 without control characters (a description may break
//    lines), a rectangle of positive size or an SVG of at most kMaxSvgBytes; every problem is one line naming
//    the source; a canvas size is positive when given;
//  - what write_annotation_page writes of it reads back as the same annotations.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "formats/annotations.hpp"
#include "fuzz_common.hpp"

namespace {

constexpr const char* kSource = "fuzz.annotations.json";

void check_set(const hk::app::AnnotationSet& set) {
  using hk::app::AnnotationSelector;
  FUZZ_CHECK(set.annotations.size() <= hk::app::kMaxAnnotations, "");
  FUZZ_CHECK(set.canvas_width_px >= 0 && set.canvas_height_px >= 0, "");
  FUZZ_CHECK((set.canvas_width_px > 0) == (set.canvas_height_px > 0), "");
  for (const std::string& p : set.problems) {
    FUZZ_CHECK(hk::fuzz::is_one_line(p), p);
    FUZZ_CHECK(p.find(kSource) != std::string::npos, p);
  }
  for (const hk::app::Annotation& a : set.annotations) {
    FUZZ_CHECK(!a.name.empty() || !a.description.empty(), "");
    FUZZ_CHECK(a.name.size() <= hk::app::kMaxNameBytes, a.name);
    FUZZ_CHECK(hk::fuzz::is_one_line(a.name), a.name);
    FUZZ_CHECK(a.description.size() <= hk::app::kMaxRegionDescriptionBytes, a.description);
    if (a.selector.kind == AnnotationSelector::Kind::rect)
      FUZZ_CHECK(a.selector.w > 0 && a.selector.h > 0, "");
    else
      FUZZ_CHECK(!a.selector.svg.empty() && a.selector.svg.size() <= hk::app::kMaxSvgBytes, "");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  hk::app::AnnotationSet set;
  try {
    set = hk::app::parse_annotations(text, kSource, "picture.png");
  } catch (const hk::app::AnnotationError& e) {
    const std::string what = e.what();
    FUZZ_CHECK(hk::fuzz::is_one_line(what), what);
    FUZZ_CHECK(what.size() < 1024, what);
    FUZZ_CHECK(what.find(kSource) != std::string::npos, what);
    return 0;
  }
  check_set(set);
  // Written and read again: the same annotations.
  const std::string page = hk::app::write_annotation_page(set, "picture.png");
  hk::app::AnnotationSet back;
  try {
    back = hk::app::parse_annotations(page, kSource, "picture.png");
  } catch (const hk::app::AnnotationError& e) {
    FUZZ_CHECK(false, std::string(e.what()) + "\n" + page);
  }
  FUZZ_CHECK(back.annotations.size() == set.annotations.size(), page);
  for (std::size_t i = 0; i < set.annotations.size(); ++i) {
    const hk::app::Annotation &a = set.annotations[i], &b = back.annotations[i];
    FUZZ_CHECK(a.name == b.name && a.description == b.description, page);
    FUZZ_CHECK(a.selector.kind == b.selector.kind && a.selector.svg == b.selector.svg, page);
  }
  return 0;
}
