#include "solver/scene/attributes.h"

#include <gtest/gtest.h>

#include <map>

namespace leaflux {
namespace {

// Attributes behaves as the std::map it replaced, entries in name order.
TEST(Attributes, KeepsNamesSortedAndOneValueEach) {
    Attributes attributes;
    EXPECT_TRUE(attributes.empty());
    attributes["order"] = 2.0;
    attributes["length_m"] = 0.1;
    attributes["vigour"] = 0.5;
    attributes["order"] = 3.0;  // overwrites
    ASSERT_EQ(attributes.size(), 3u);
    std::vector<std::string> names;
    for (const auto& [name, value] : attributes) names.push_back(name);
    EXPECT_EQ(names, (std::vector<std::string>{"length_m", "order", "vigour"}));
    EXPECT_EQ(attributes.at("order"), 3.0);
    EXPECT_EQ(attributes.count("order"), 1u);
    EXPECT_EQ(attributes.count("rank"), 0u);
    EXPECT_EQ(attributes.find("rank"), attributes.end());
    EXPECT_THROW(attributes.at("rank"), std::out_of_range);
    EXPECT_EQ(attributes["rank"], 0.0);  // made, as std::map's operator[]
    EXPECT_EQ(attributes.size(), 4u);
}

TEST(Attributes, InsertsPairsInAnyOrderKeepingTheValuesItHas) {
    const std::map<std::string, double> map = {{"b", 2.0}, {"a", 1.0}, {"c", 3.0}};
    const std::vector<std::pair<std::string, double>> unordered = {
        {"c", 30.0}, {"d", 4.0}, {"a", 10.0}, {"d", 40.0}};
    Attributes attributes;
    attributes.insert(map.begin(), map.end());
    attributes.insert(unordered.begin(), unordered.end());
    std::map<std::string, double> expected = map;
    expected.insert(unordered.begin(), unordered.end());  // std::map keeps the first too
    ASSERT_EQ(attributes.size(), expected.size());
    auto want = expected.begin();
    for (const auto& [name, value] : attributes) {
        EXPECT_EQ(name, want->first);
        EXPECT_EQ(value, want->second);
        ++want;
    }
    Attributes same;
    same.insert(expected.begin(), expected.end());
    EXPECT_EQ(attributes, same);
    same["a"] = 11.0;
    EXPECT_NE(attributes, same);
}

// Held by pointer, a node's attributes are still a value: a copy is its own, and none at
// all equal an emptied set.
TEST(Attributes, CopiesAreValues) {
    Attributes original;
    original["height"] = 2.0;
    Attributes copy = original;
    copy["height"] = 3.0;
    copy["width"] = 1.0;
    EXPECT_EQ(original.at("height"), 2.0);
    EXPECT_EQ(original.size(), 1u);
    copy = original;
    EXPECT_EQ(copy, original);
    Attributes none, emptied;
    emptied.insert(original.begin(), original.begin());
    EXPECT_EQ(none, emptied);
    EXPECT_TRUE(none.empty());
    EXPECT_EQ(none.find("height"), none.end());
    EXPECT_EQ(none.count("height"), 0u);
}

TEST(Attributes, CopiesKeepTheirEntriesWhenOneChanges) {
    Attributes original;
    original["length_m"] = 0.1;
    const Attributes copy = original;
    Attributes changed = original;
    changed["length_m"] = 0.2;
    changed["order"] = 1;
    EXPECT_EQ(original.at("length_m"), 0.1);
    EXPECT_EQ(copy.at("length_m"), 0.1);
    EXPECT_EQ(original.size(), 1u);
    EXPECT_EQ(changed.at("length_m"), 0.2);
    EXPECT_EQ(changed.size(), 2u);
    EXPECT_EQ(copy, original);
    // Moved and assigned away, the others keep their entries.
    Attributes moved = std::move(changed);
    original = moved;
    EXPECT_EQ(original.at("order"), 1.0);
    EXPECT_EQ(copy.at("length_m"), 0.1);
    original = Attributes();
    EXPECT_TRUE(original.empty());
    EXPECT_EQ(moved.size(), 2u);
}

}  // namespace
}  // namespace leaflux
