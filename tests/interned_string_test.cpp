#include "solver/util/interned_string.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace leaflux {
namespace {

// Equal texts are one copy, whatever they were made from; the empty string holds none.
TEST(InternedString, HoldsOneCopyOfEachText) {
    const std::string leaf = "leaf";
    const InternedString a(leaf), b("leaf"), c(std::string_view("leaf-2").substr(0, 4));
    EXPECT_EQ(&a.str(), &b.str());
    EXPECT_EQ(&a.str(), &c.str());
    EXPECT_EQ(a, b);
    EXPECT_EQ(a.str(), "leaf");
    const InternedString stem("stem");
    EXPECT_NE(a, stem);
    EXPECT_NE(&a.str(), &stem.str());
    const InternedString none, empty("");
    EXPECT_TRUE(none.empty());
    EXPECT_EQ(none, empty);
    EXPECT_EQ(none.str(), "");
    const std::string& read = a;  // read as a std::string
    EXPECT_EQ(read, leaf);
}

// A text no holder keeps is made anew (its table entry may be dropped): its holders still
// read it right, before and after many others came and went.
TEST(InternedString, OutlivesTheTextsOthersDropped) {
    const InternedString kept("kept");
    for (int round = 0; round < 3; ++round) {
        std::vector<InternedString> passing;
        for (int i = 0; i < 1000; ++i) passing.emplace_back("passing " + std::to_string(i));
        EXPECT_EQ(passing[999].str(), "passing 999");
    }
    EXPECT_EQ(kept.str(), "kept");
    EXPECT_EQ(InternedString("kept"), kept);
    EXPECT_EQ(InternedString("passing 5").str(), "passing 5");
}

}  // namespace
}  // namespace leaflux
