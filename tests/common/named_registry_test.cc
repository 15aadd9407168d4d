#include "robomach/common/named_registry.h"

#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "robomach/common/enum_names.h"

namespace robomach {
namespace demo {
// An enum with its printer, for ParseByName (found by argument-dependent lookup).
enum class Shade { kLight, kMid, kDark };
inline const char* ToString(Shade s) {
  switch (s) {
    case Shade::kLight: return "light";
    case Shade::kMid: return "mid";
    case Shade::kDark: return "dark";
  }
  return "?";
}
}  // namespace demo

namespace {

// The what() of f's std::invalid_argument ("" if it throws none).
template <class F>
std::string RefusalOf(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

NamedRegistry<int> Sizes() {
  NamedRegistry<int> r("unknown size");
  r.Add("small", 1).Add("medium", 2).Add("large", 3);
  return r;
}

TEST(NamedRegistry, FindsEveryEntryByNameInTheOrderAdded) {
  const NamedRegistry<int> r = Sizes();
  EXPECT_EQ(r.size(), 3u);
  EXPECT_EQ(r.Names(), (std::vector<std::string>{"small", "medium", "large"}));
  EXPECT_EQ(r.Values(), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(r.Find("small"), 1);
  EXPECT_EQ(r.Find("medium"), 2);
  EXPECT_EQ(r.Find("large"), 3);
  EXPECT_TRUE(r.Contains("large"));
  EXPECT_FALSE(r.Contains("Large"));  // names are exact
  ASSERT_NE(r.Get("medium"), nullptr);
  EXPECT_EQ(*r.Get("medium"), 2);
  EXPECT_EQ(r.Get("huge"), nullptr);
  EXPECT_EQ(r.entries()[2].first, "large");
  EXPECT_EQ(r.what(), "unknown size");
}

TEST(NamedRegistry, RefusesAnUnknownNameNamingEveryKnownOne) {
  const NamedRegistry<int> r = Sizes();
  EXPECT_EQ(r.NameList(), "small, medium or large");
  EXPECT_EQ(RefusalOf([&] { r.Find("huge"); }), "unknown size 'huge': expected small, medium or large");
  EXPECT_EQ(RefusalOf([&] { r.Find(""); }), "unknown size '': expected small, medium or large");
}

TEST(NamedRegistry, RefusesANameAddedTwice) {
  NamedRegistry<int> r = Sizes();
  EXPECT_THROW(r.Add("small", 4), std::logic_error);
  EXPECT_EQ(r.size(), 3u);
  EXPECT_EQ(r.Find("small"), 1);  // the first entry stays
}

TEST(NamedRegistry, ListsOneTwoOrNoNames) {
  EXPECT_EQ(NameListOf({}), "");
  EXPECT_EQ(NameListOf({"a"}), "a");
  EXPECT_EQ(NameListOf({"a", "b"}), "a or b");
  EXPECT_EQ(NameListOf({"a", "b", "c", "d"}), "a, b, c or d");
  NamedRegistry<int> one("unknown kind");
  one.Add("only", 7);
  EXPECT_EQ(RefusalOf([&] { one.Find("other"); }), "unknown kind 'other': expected only");
}

// The enum case of the idiom: ParseByName accepts exactly the printer's
// names and refuses anything else with the registry's message.
TEST(ParseByName, IsTheRegistrysIdiomForAnEnum) {
  using demo::Shade;
  static constexpr Shade kAll[] = {Shade::kLight, Shade::kMid, Shade::kDark};
  for (Shade s : kAll) EXPECT_EQ(ParseByName("shade", ToString(s), kAll), s) << ToString(s);
  const std::string refusal = RefusalOf([] { ParseByName("shade", "Dark", kAll); });
  EXPECT_EQ(refusal, "shade 'Dark': expected light, mid or dark");
  NamedRegistry<Shade> as_registry("shade");
  for (Shade s : kAll) as_registry.Add(ToString(s), s);
  EXPECT_EQ(RefusalOf([&] { as_registry.Find("Dark"); }), refusal);  // one message format
}

}  // namespace
}  // namespace robomach
