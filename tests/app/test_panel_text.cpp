// The operator panel in the staff's language (visit/panel_text.hpp): the French catalogue built from
// app/kiosk/po/fr.po gives every word of the panel's template, each setting's help included, so that its label
// (config::field_label, the help's first phrase) is French too; a language without a panel catalogue, and a
// damaged catalogue file, leave the panel in English.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include "audio/messages.hpp"
#include "config/load.hpp"
#include "visit/panel_text.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

TEST(PanelText, TheFrenchPanelHasEverySettingInFrenchWithADistinctLabelInItsTab) {
  const PanelText fr = PanelText::load("fr", audio::default_locale_dir());
  ASSERT_EQ(fr.language(), "fr");
  EXPECT_STRNE(fr("Apply"), "Apply");
  EXPECT_STRNE(fr("Status"), "Status");
  std::map<config::FieldGroup, std::set<std::string>> labels;
  for (const config::FieldDescriptor& d : config::field_descriptors()) {
    if (d.group == config::FieldGroup::hidden) continue;
    const std::string key = std::string(d.table) + "." + std::string(d.key);
    const std::string help = fr(d.help);
    EXPECT_NE(help, std::string(d.help)) << key << " has no French help";
    const std::string label = config::field_label(help, key);
    EXPECT_FALSE(label.empty()) << key;
    EXPECT_TRUE(labels[d.group].insert(label).second) << key << ": its label '" << label << "' is another's in its tab";
  }
  // A regional tag takes its language's catalogue.
  EXPECT_EQ(PanelText::load("fr-CA", audio::default_locale_dir()).language(), "fr-CA");
}

TEST(PanelText, NoCatalogueOrADamagedOneLeavesThePanelInEnglish) {
  const PanelText en = PanelText::load("en", audio::default_locale_dir());
  EXPECT_STREQ(en("Apply"), "Apply");
  const PanelText sw = PanelText::load("sw", audio::default_locale_dir());  // no Swahili panel
  EXPECT_EQ(sw.language(), "en");
  EXPECT_STREQ(sw("Apply"), "Apply");
  // A file that is not an MO file.
  const fs::path dir = fs::temp_directory_path() / ("hk_panel_text_" + std::to_string(::getpid()));
  fs::create_directories(dir / "fr" / "LC_MESSAGES");
  std::ofstream(dir / "fr" / "LC_MESSAGES" / "haptic-kiosk-panel.mo", std::ios::binary) << "not an MO file at all";
  const PanelText broken = PanelText::load("fr", dir);
  EXPECT_EQ(broken.language(), "en");
  EXPECT_STREQ(broken("Apply"), "Apply");
  // Nor does a tag that is no language.
  EXPECT_EQ(PanelText::load("not a tag!", audio::default_locale_dir()).language(), "en");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hk::app
