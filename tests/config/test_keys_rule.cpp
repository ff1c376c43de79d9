// The cross-field rule of [keys]: each visitor action needs its own key, so a key does one
// thing and the spoken help can name each action's key. The first clash in table order is refused, attributed
// to the earlier action and naming the later one.

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <string_view>

#include "config/keys.hpp"
#include "config/load.hpp"
#include "config_test_util.hpp"

namespace hk::config {
namespace {

using test::capture_error;
using test::is_one_line;

/// The [keys] actions in table order, with their fields.
constexpr std::array<std::pair<std::string_view, std::string KeysSettings::*>, 11> kActions{
    {{"help", &KeysSettings::help},
     {"next", &KeysSettings::next},
     {"previous", &KeysSettings::previous},
     {"describe", &KeysSettings::describe},
     {"finer", &KeysSettings::finer},
     {"coarser", &KeysSettings::coarser},
     {"volume_up", &KeysSettings::volume_up},
     {"volume_down", &KeysSettings::volume_down},
     {"tutorial", &KeysSettings::tutorial},
     {"guide", &KeysSettings::guide},
     {"capture", &KeysSettings::capture}}};

TEST(KeysRule, ShippedKeysAreAllDifferentAndValid) { EXPECT_NO_THROW(validate(Settings{})); }

TEST(KeysRule, TheExampleOfTheIssue) {
  Settings s;
  s.keys.next = "UP";  // the shipped finer key
  const auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "keys.next");
  EXPECT_EQ(std::string(e->what()), "settings: keys.next = \"UP\" is also keys.finer; each action needs its own key");
}

TEST(KeysRule, EveryPairOfActionsOnOneKeyIsRefusedNamingBoth) {
  int pairs = 0;
  for (std::size_t i = 0; i < kActions.size(); ++i) {
    for (std::size_t j = i + 1; j < kActions.size(); ++j) {
      SCOPED_TRACE(std::string(kActions[i].first) + " and " + std::string(kActions[j].first));
      Settings s;
      s.keys.*kActions[i].second = "X";  // no shipped action is on X
      EXPECT_NO_THROW(validate(s));
      s.keys.*kActions[j].second = "X";
      const auto e = capture_error([&] { validate(s); });
      ASSERT_TRUE(e);
      const std::string earlier = "keys." + std::string(kActions[i].first);
      EXPECT_EQ(e->key(), earlier);
      EXPECT_EQ(std::string(e->what()), "settings: " + earlier + " = \"X\" is also keys." +
                                            std::string(kActions[j].first) + "; each action needs its own key");
      EXPECT_TRUE(is_one_line(e->what()));
      ++pairs;
    }
  }
  EXPECT_EQ(pairs, 55);  // 11 actions: 11 · 10 / 2
}

TEST(KeysRule, ThreeOnOneKeyReportsTheFirstPairInTableOrder) {
  Settings s;
  s.keys.tutorial = "SPACE";
  s.keys.describe = "SPACE";
  s.keys.previous = "SPACE";
  const auto e = capture_error([&] { validate(s); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "keys.previous");
  EXPECT_NE(std::string(e->what()).find("is also keys.describe;"), std::string::npos) << e->what();
}

TEST(KeysRule, SwappingTwoKeysIsFine) {
  Settings s;
  std::swap(s.keys.next, s.keys.finer);
  EXPECT_NO_THROW(validate(s));
  // Every action moved to another key name, all different: fine.
  const auto names = visitor_key_names();
  for (std::size_t i = 0; i < kActions.size(); ++i)
    s.keys.*kActions[i].second = std::string(names[names.size() - 1 - i]);
  EXPECT_NO_THROW(validate(s));
}

TEST(KeysRule, ASettingsFileWithTwoActionsOnOneKeyIsRefused) {
  const auto e = capture_error([] { (void)parse_settings("[keys]\nhelp = \"D\"\n", "kiosk.toml"); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->key(), "keys.help");
  EXPECT_NE(std::string(e->what()).find("kiosk.toml"), std::string::npos) << e->what();
  EXPECT_NE(std::string(e->what()).find("keys.help = \"D\" is also keys.describe; each action needs its own key"),
            std::string::npos)
      << e->what();
}

}  // namespace
}  // namespace hk::config
