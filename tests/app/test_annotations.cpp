/// @file test_annotations.cpp
/// Files of names staff give regions (formats/annotations.hpp) read as the W3C model and IIIF write them, and
/// bad ones: refused whole with one line naming the file and the rule, or each bad annotation left out with
/// one such line while the good ones are kept. Real files in tests/data/bad and tests/data/annotations.

#include <gtest/gtest.h>

#include <string>

#include "formats/annotations.hpp"
#include "meaning/names.hpp"
#include "test_paths.hpp"

namespace hk::app {
namespace {

std::string bad(const std::string& name) { return std::string(HK_TEST_DATA_DIR) + "/bad/" + name; }
std::string good(const std::string& name) { return std::string(HK_TEST_DATA_DIR) + "/annotations/" + name; }

/// The message of the AnnotationError `f` throws, "" when it throws none.
template <typename F>
std::string refusal(F f) {
  try {
    f();
  } catch (const AnnotationError& e) {
    return e.what();
  }
  return "";
}

bool one_line(const std::string& s) { return s.find('\n') == std::string::npos && s.size() < 600; }

TEST(Annotations, AFileThatIsNotJsonOrNotTheModelIsRefusedWholeInOneLine) {
  for (const auto& [file, rule] : {std::pair<std::string, std::string>{"annotations_not_json.json", "not JSON"},
                                   {"annotations_wrong_type.json", "'Collection' is not Annotation"}}) {
    const std::string why = refusal([&] { (void)read_annotations(bad(file), "shapes.png"); });
    EXPECT_NE(why.find(file), std::string::npos) << why;
    EXPECT_NE(why.find(rule), std::string::npos) << why;
    EXPECT_TRUE(one_line(why)) << why;
  }
  const std::string missing = refusal([] { (void)read_annotations(bad("no_such.annotations.json"), "a.png"); });
  EXPECT_NE(missing.find("cannot be read"), std::string::npos) << missing;
  EXPECT_NE(refusal([] { (void)parse_annotations("[]]", "x.json", ""); }).find("not JSON"), std::string::npos);
}

TEST(Annotations, EachBrokenAnnotationIsLeftOutWithItsRuleAndTheGoodOnesKept) {
  const AnnotationSet set = read_annotations(bad("annotations_mixed.json"), "shapes.png");
  // Kept: "sun", "nowhere" (outside the picture: only the drawing can tell), "empty drawing", "broken svg"
  // (librsvg judges them when they are drawn).
  ASSERT_EQ(set.annotations.size(), 4u);
  EXPECT_EQ(set.annotations[0].name, "sun");
  const std::string all = [&] {
    std::string s;
    for (const std::string& p : set.problems) {
      EXPECT_TRUE(one_line(p)) << p;
      EXPECT_NE(p.find("annotations_mixed.json"), std::string::npos) << p;
      s += p + "\n";
    }
    return s;
  }();
  EXPECT_NE(all.find("annotation 1: the name is longer than 200 bytes"), std::string::npos) << all;
  EXPECT_NE(all.find("annotation 3: the name has a control character"), std::string::npos) << all;
  EXPECT_NE(all.find("annotation 5: its region has no positive width and height"), std::string::npos) << all;
  EXPECT_NE(all.find("annotation 8: its SVG selector is larger than 64 kB"), std::string::npos) << all;
  EXPECT_NE(all.find("annotation 9: it has no text body"), std::string::npos) << all;
  EXPECT_NE(all.find("annotation 10: its target has no FragmentSelector"), std::string::npos) << all;
  // Drawn on an 800 x 520 picture: outside it, and SVGs that draw nothing or cannot be read, are left out too.
  std::vector<std::string> problems;
  const std::vector<meaning::NamedRegion> regions = meaning::draw_regions(set, 800, 520, 800, 520, "m.json", &problems);
  ASSERT_EQ(regions.size(), 1u);
  EXPECT_EQ(regions[0].name, "sun");
  EXPECT_EQ(regions[0].area_px, 180.0 * 180.0);
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_NE(problems[0].find("annotation 2: its region lies outside the picture"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("annotation 3: its SVG selector draws nothing"), std::string::npos) << problems[1];
  EXPECT_NE(problems[2].find("annotation 4: its SVG selector cannot be"), std::string::npos) << problems[2];
}

TEST(Annotations, MoreThanAThousandAreCutAtTheLimitWithOneLine) {
  const AnnotationSet set = read_annotations(bad("annotations_too_many.json"), "shapes.png");
  EXPECT_EQ(set.annotations.size(), kMaxAnnotations);
  ASSERT_EQ(set.problems.size(), 1u);
  EXPECT_NE(set.problems[0].find("more than 1000 annotations"), std::string::npos) << set.problems[0];
}

TEST(Annotations, WhatTheKioskWritesTheW3cModelReadsTheSame) {
  const AnnotationSet set = read_annotations(good("tagging_manifest.json"), "shapes.png");
  ASSERT_EQ(set.annotations.size(), 4u);
  EXPECT_EQ(set.canvas_width_px, 1600);
  const std::string page = write_annotation_page(set, "shapes.png");
  const AnnotationSet back = parse_annotations(page, "written.json", "shapes.png");
  ASSERT_EQ(back.annotations.size(), set.annotations.size());
  for (std::size_t i = 0; i < set.annotations.size(); ++i) {
    const Annotation &a = set.annotations[i], &b = back.annotations[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.description, b.description);
    EXPECT_EQ(a.language, b.language);
    EXPECT_EQ(a.selector.kind, b.selector.kind);
    EXPECT_EQ(a.selector.percent, b.selector.percent);
    EXPECT_EQ(a.selector.x, b.selector.x);
    EXPECT_EQ(a.selector.w, b.selector.w);
    EXPECT_EQ(a.selector.svg, b.selector.svg);
  }
  // The W3C model's shape: an AnnotationPage of Annotations with TextualBody bodies and SpecificResource targets.
  EXPECT_NE(page.find("\"type\": \"AnnotationPage\""), std::string::npos);
  EXPECT_NE(page.find("\"purpose\": \"identifying\""), std::string::npos);
  EXPECT_NE(page.find("\"type\": \"SpecificResource\""), std::string::npos);
  EXPECT_EQ(annotations_path("/srv/library/horse.png"), "/srv/library/horse.annotations.json");
  EXPECT_EQ(annotations_path_in("/var/lib/haptic-kiosk/names", "/srv/library/horse.png"),
            "/var/lib/haptic-kiosk/names/horse.annotations.json");
}

TEST(Annotations, EachLanguagesNameIsReadWrittenBackAndChosenForTheVisitor) {
  // The shipped butterfly names each part in English, French, German and Spanish, a TextualBody a language.
  const AnnotationSet set =
      read_annotations(std::string(HK_SHIPPED_PICTURES_DIR) + "/butterfly.annotations.json", "butterfly.jpg");
  ASSERT_FALSE(set.annotations.empty());
  EXPECT_TRUE(set.problems.empty());
  const Annotation& wing = set.annotations[0];
  EXPECT_EQ(wing.name, "left wing");
  EXPECT_EQ(wing.language, "en");
  ASSERT_EQ(wing.translations.size(), 3u);
  EXPECT_EQ(wing.translations.at("fr").name, "l'aile gauche");
  std::string language;
  EXPECT_EQ(annotation_text_in(wing, "fr-CA", &language).name, "l'aile gauche");  // the subtag's
  EXPECT_EQ(language, "fr");
  EXPECT_EQ(annotation_text_in(wing, "de").description,
            "Das linke Flügelpaar, schwarz mit Reihen cremeweißer Flecken.");
  EXPECT_EQ(annotation_text_in(wing, "it", &language).name, "left wing");  // none in Italian: its own
  EXPECT_EQ(language, "en");
  // Written back, every language's bodies come back as they were.
  const AnnotationSet back = parse_annotations(write_annotation_page(set, "butterfly.jpg"), "w.json", "butterfly.jpg");
  ASSERT_EQ(back.annotations.size(), set.annotations.size());
  for (std::size_t i = 0; i < set.annotations.size(); ++i) {
    ASSERT_EQ(back.annotations[i].translations.size(), set.annotations[i].translations.size()) << i;
    for (const auto& [tag, tr] : set.annotations[i].translations) {
      EXPECT_EQ(back.annotations[i].translations.at(tag).name, tr.name);
      EXPECT_EQ(back.annotations[i].translations.at(tag).description, tr.description);
    }
  }
  // The names drawn on the picture keep every language's.
  std::vector<std::string> problems;
  const std::vector<meaning::NamedRegion> regions = meaning::draw_regions(set, 493, 356, 493, 356, "b", &problems);
  ASSERT_FALSE(regions.empty());
  EXPECT_EQ(meaning::region_name_in(regions[0], "es"), "el ala izquierda");
  EXPECT_EQ(meaning::region_name_in(regions[0], "en-GB"), "left wing");
}

TEST(Annotations, ATextInALanguageThatIsNoTagIsLeftOutWithOneLineAndTheRestKept) {
  const std::string page = R"({"type": "AnnotationPage", "items": [{"type": "Annotation", "motivation": "identifying",
    "body": [{"type": "TextualBody", "value": "tail", "language": "en"},
             {"type": "TextualBody", "value": "la queue", "language": "fr"},
             {"type": "TextualBody", "value": "??", "language": "not a language!"},
             {"type": "TextualBody", "value": "Schweif\u0007", "language": "de"}],
    "target": "horse.png#xywh=1,2,30,40"},
   {"type": "Annotation", "body": {"type": "TextualBody", "value": "head", "language": "en"},
    "target": "horse.png#xywh=5,5,10,10"}]})";
  const AnnotationSet set = parse_annotations(page, "langs.json", "horse.png");
  // The control character in the German name leaves its annotation out; the bad tag only that text.
  ASSERT_EQ(set.annotations.size(), 1u);
  EXPECT_EQ(set.annotations[0].name, "head");
  ASSERT_EQ(set.problems.size(), 2u);
  EXPECT_NE(set.problems[0].find("'not a language!' is not a BCP 47 tag"), std::string::npos) << set.problems[0];
  EXPECT_NE(set.problems[1].find("annotation 1: the name in de has a control character"), std::string::npos)
      << set.problems[1];
  for (const std::string& p : set.problems) EXPECT_TRUE(one_line(p)) << p;
}

}  // namespace
}  // namespace hk::app
