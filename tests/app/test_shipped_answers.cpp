/// @file test_shipped_answers.cpp
/// What a visitor hears on every shipped library picture (data/pictures, with the names curators wrote beside
/// each): Describe opens with the named parts, largest first, and never says one phrase twice in a row; Where,
/// asked on a grid over the whole workspace, never says one sentence twice in an answer and never names a
/// speck's number as a shape.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "audio/messages.hpp"
#include "cli/explore.hpp"
#include "config/settings.hpp"
#include "formats/picture_notes.hpp"
#include "pictures/picture_names.hpp"
#include "test_paths.hpp"
#include "visit/answers.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

/// `text` cut into phrases at ". ", ", " and ": " (a leading "and " dropped), for speech compared phrase by phrase.
std::vector<std::string> phrases(const std::string& text) {
  std::vector<std::string> out;
  std::string cur;
  const auto flush = [&] {
    if (cur.rfind("and ", 0) == 0) cur.erase(0, 4);
    if (!cur.empty()) out.push_back(cur);
    cur.clear();
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if ((c == '.' || c == ',' || c == ':') && (i + 1 == text.size() || text[i + 1] == ' ')) {
      flush();
      ++i;
      continue;
    }
    cur += c;
  }
  flush();
  return out;
}

/// A shipped picture built as the library builds it, with its curators' names and its sidecar.
struct Shipped {
  ImageScene is;
  PictureNotes notes;
  PictureNames names;
  explicit Shipped(const fs::path& picture) {
    is = build_input_scene(picture.string(), 0, config::Settings{});
    notes = read_picture_notes(picture.string());
    apply_names(is, annotations_path(picture.string()), picture.filename().string(), notes.guesses);
    names = picture_names(is.regions, is.shape_region, is.polylines.size(), is.px_to_m, &is.polylines);
  }
  ShownView view() const {
    static const std::vector<TextBlockM> none;
    return {is.polylines, is.descriptors, none, notes, {0.07, 0.045}, false, false, &names, &is.regions, is.px_to_m};
  }
};

std::vector<fs::path> shipped_pictures() {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(HK_SHIPPED_PICTURES_DIR)) {
    const std::string ext = e.path().extension().string();
    if (ext == ".png" || ext == ".jpg") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(ShippedAnswers, DescribeOpensWithTheNamedPartsAndNeverSaysAPhraseTwiceInARow) {
  const std::vector<fs::path> pictures = shipped_pictures();
  ASSERT_GE(pictures.size(), 4u);
  const audio::MessageCatalog& m = audio::MessageCatalog::english();
  for (const fs::path& p : pictures) {
    SCOPED_TRACE(p.filename().string());
    const Shipped s(p);
    ASSERT_FALSE(s.names.parts.empty()) << "the curators named its parts";
    // A touched shape is said as its part: "part of the left wing" is touched as "the left wing".
    ASSERT_EQ(s.names.part_name.size(), s.names.shape_name.size());
    for (std::size_t c = 0; c < s.names.shape_name.size(); ++c) {
      const std::string& shape = s.names.shape_name[c];
      EXPECT_EQ(s.names.part_name[c], shape.rfind("part of ", 0) == 0 ? shape.substr(8) : shape) << c;
    }
    for (const Vec2 hand : {Vec2{0, 0}, Vec2{-0.06, 0.04}, Vec2{0.06, -0.04}}) {
      const std::string said = describe_answer(s.view(), m, hand, hand);
      const std::vector<std::string> ph = phrases(said);
      for (std::size_t i = 1; i < ph.size(); ++i) EXPECT_NE(ph[i], ph[i - 1]) << said;
      // The largest named part is said before any shape without a name ("Also ...").
      std::string largest = s.names.parts[0].name;
      if (largest.rfind("the ", 0) == 0) largest.erase(0, 4);  // "The horse" opens a sentence
      const std::size_t first_part = said.find(largest);
      ASSERT_NE(first_part, std::string::npos) << said;
      const std::size_t also = said.find("Also ");
      if (also != std::string::npos) {
        EXPECT_LT(first_part, also) << said;
      }
    }
  }
}

TEST(ShippedAnswers, WhereOverTheWholeWorkspaceNeverSaysASentenceTwice) {
  const audio::MessageCatalog& m = audio::MessageCatalog::english();
  for (const fs::path& p : shipped_pictures()) {
    SCOPED_TRACE(p.filename().string());
    const Shipped s(p);
    int answers = 0;
    for (double x = -0.065; x <= 0.066; x += 0.0217)
      for (double y = -0.04; y <= 0.041; y += 0.016) {
        const std::string said = where_answer(s.view(), m, {x, y}, -1);
        const std::vector<std::string> ph = phrases(said);
        for (std::size_t i = 0; i < ph.size(); ++i)
          for (std::size_t j = i + 1; j < ph.size(); ++j)
            if (ph[i].size() > 12) {
              EXPECT_NE(ph[i], ph[j]) << "at " << x << ", " << y << ": " << said;
            }
        ++answers;
      }
    EXPECT_EQ(answers, 42);
  }
}

TEST(ShippedAnswers, EveryPartIsNamedInTheVisitorsLanguage) {
  for (const char* language : {"fr", "de", "es"}) {
    const audio::MessageCatalog m = audio::MessageCatalog::load(language, audio::default_locale_dir());
    ASSERT_EQ(m.language(), language);
    for (const fs::path& p : shipped_pictures()) {
      SCOPED_TRACE(std::string(language) + " " + p.filename().string());
      const Shipped s(p);
      const PictureNames english = s.names;
      const PictureNames names =
          picture_names(s.is.regions, s.is.shape_region, s.is.polylines.size(), s.is.px_to_m, &s.is.polylines, m);
      ASSERT_EQ(names.parts.size(), english.parts.size());
      for (std::size_t i = 0; i < names.parts.size(); ++i) {
        // Each part's name is the curators' in this language, none left in English.
        EXPECT_NE(names.parts[i].name, english.parts[i].name);
        if (names.parts[i].guess) continue;
        bool theirs = false;
        for (const meaning::NamedRegion& r : s.is.regions)
          theirs = theirs || (r.names_in.count(language) && r.names_in.at(language) == names.parts[i].name);
        EXPECT_TRUE(theirs) << names.parts[i].name;
      }
      // Several shapes of one part are said as one of them in this language, as in English.
      for (std::size_t c = 0; c < names.shape_name.size(); ++c) {
        const bool shared_en =
            english.shape_name[c] != english.part_name[c] || english.shape_name[c].rfind("one of ", 0) == 0;
        const std::string one_of = m.word("name_one_of", 1, {{"name", ""}});
        const std::string part_of = m.word("name_part_of", 1, {{"name", ""}});
        const bool shared = names.shape_name[c].rfind(one_of, 0) == 0 || names.shape_name[c].rfind(part_of, 0) == 0;
        EXPECT_EQ(shared, shared_en) << names.shape_name[c] << " / " << english.shape_name[c];
      }
    }
  }
}

}  // namespace
}  // namespace hk::app
