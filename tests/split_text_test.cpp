// SplitTextFile: a text scene file read as its nodes apart from the rest gives the nodes the
// whole file's parse gives, in order, and the same errors at the same lines and columns;
// nodes laid out so that they cannot be taken apart stay in the rest.
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "leaflux.pb.h"
#include "server/text_format.h"
#include "tests/temp_file.h"

namespace leaflux {
namespace {

// The nodes of `path` taken apart, in order, and the rest.
v1::Scene ReadSplit(const std::string& path, std::size_t& taken) {
    SplitTextFile file(path, "nodes");
    v1::Scene rest;
    EXPECT_FALSE(file.ReadRest(rest, taken));
    v1::Scene run;
    EXPECT_FALSE(file.ForEachRun(run, [&] {
        for (const v1::Node& node : run.nodes()) *rest.add_nodes() = node;
    }));
    return rest;
}

v1::Scene ReadWhole(const std::string& path) {
    v1::Scene whole;
    EXPECT_FALSE(ReadTextFormat(path, whole));
    return whole;
}

const char* kOddLayouts = R"(version: PROTOCOL_VERSION_CURRENT
bands { name: "PAR" }
nodes { id: 1 type: NODE_TYPE_PLANT }
# a comment { with a brace
nodes: {
  id: 2 parent: 1
  name: "a \"{ name"  # a brace in a string, an escaped quote
}
bands { name: "NIR" }
  nodes <
    id: 3 parent: 1  # a comment with a } brace
    attributes { key: "order" value: 1 }
  >  # after its close, a comment
nodes {
  id: 4 parent: 3 frame { m: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] }
}
)";

TEST(SplitTextFile, TakesEveryNodeApartInOrderAndLeavesTheRest) {
    const std::string path = testing::WriteTempFile("odd.scene.txtpb", kOddLayouts);
    std::size_t taken = 0;
    const v1::Scene split = ReadSplit(path, taken);
    EXPECT_EQ(taken, 4u);
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(split, ReadWhole(path)));
}

TEST(SplitTextFile, LeavesNodesThatShareALineInTheRest) {
    const std::string path = testing::WriteTempFile(
        "shared.scene.txtpb", std::string(kOddLayouts) +
                                  "nodes { id: 5 parent: 1 } nodes { id: 6 parent: 1 }\n"
                                  "nodes { id: 7 parent: 1\n} bands { name: \"UV\" }\n"
                                  "nodes: [{ id: 8 parent: 1 }]\n");
    SplitTextFile file(path, "nodes");
    v1::Scene rest;
    std::size_t taken = 0;
    ASSERT_FALSE(file.ReadRest(rest, taken));
    EXPECT_EQ(taken, 4u);
    ASSERT_EQ(rest.nodes_size(), 4);  // 5, 6, 7 and 8: a caller reads such a file whole
    EXPECT_EQ(rest.nodes(0).id(), 5u);
    EXPECT_EQ(rest.nodes(3).id(), 8u);
    EXPECT_EQ(rest.bands_size(), 3);
}

TEST(SplitTextFile, NamesAMistakeWhereTheWholeFilesParseDoes) {
    std::string many = "bands { name: \"PAR\" }\n";
    for (int i = 1; i <= 3000; ++i) {
        many += "nodes {\n  id: " + std::to_string(i) + "\n  name: \"leaf" + std::to_string(i) +
                "\"\n}\n";
    }
    for (const auto& [what, mistake] :
         {std::pair{"in a node", "nodes {\n  id: 3001\n  nme: \"x\"\n}\n"},
          {"in the rest", "sky { discretisation: 3 }\n"},
          {"a field given twice", "nodes {\n  id: 3001\n  id: 3002\n}\n"},
          {"an unclosed node", "nodes {\n  id: 3001\n"}}) {
        const std::string path =
            testing::WriteTempFile("mistake.scene.txtpb", many + mistake + many);
        v1::Scene whole;
        const auto expected = ReadTextFormat(path, whole);
        ASSERT_TRUE(expected) << what;
        SplitTextFile file(path, "nodes");
        v1::Scene rest, run;
        std::size_t taken = 0;
        auto error = file.ReadRest(rest, taken);
        if (!error) error = file.ForEachRun(run, [] {});
        ASSERT_TRUE(error) << what;
        EXPECT_EQ(error->where, expected->where) << what;
        EXPECT_EQ(error->what, expected->what) << what;
    }
}

}  // namespace
}  // namespace leaflux
