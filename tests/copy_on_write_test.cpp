#include "solver/util/copy_on_write.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>

namespace leaflux {
namespace {

TEST(CopyOnWrite, CopiesShareOneValueUntilOneIsEdited) {
    CopyOnWrite<std::string> original;
    EXPECT_EQ(*original, "");  // empty: T{}, nothing allocated
    original.Edit() = "leaf";
    const CopyOnWrite<std::string> copy = original;
    CopyOnWrite<std::string> edited = original;
    EXPECT_TRUE(copy.SharesWith(original));
    EXPECT_TRUE(edited.SharesWith(original));
    edited.Edit() += "1042";
    EXPECT_FALSE(edited.SharesWith(original));
    EXPECT_EQ(*original, "leaf");
    EXPECT_EQ(*copy, "leaf");
    EXPECT_EQ(*edited, "leaf1042");
    // A sole holder edits its value in place.
    const std::string* before = &*edited;
    edited.Edit() += "b";
    EXPECT_EQ(&*edited, before);
    // Moved and assigned away, the others keep theirs.
    CopyOnWrite<std::string> moved = std::move(edited);
    original = moved;
    EXPECT_EQ(*original, "leaf1042b");
    EXPECT_EQ(*copy, "leaf");
    original = CopyOnWrite<std::string>();
    EXPECT_EQ(*original, "");
    EXPECT_EQ(*moved, "leaf1042b");
}

}  // namespace
}  // namespace leaflux
