#include "solver/scene/organ_receivers.h"

#include <gtest/gtest.h>

#include <vector>

#include "tests/scene_builders.h"

namespace leaflux {
namespace {

// A plant (no organ) holding leaves 10, 20, …, and a ground after the organs.
Scene Plant(const std::vector<NodeId>& leaves) {
    Scene scene = testing::OneBandScene({{"leaf", testing::Leaf(0.1, 0.05)}});
    Node plant;
    plant.id = 5;
    plant.Edit().type = NodeType::kPlant;
    scene.nodes.push_back(plant);
    for (const NodeId id : leaves) {
        scene.nodes.push_back(testing::OrganNode(
            id, "leaf" + std::to_string(id), testing::Rectangle(0.1, 0.1, 0.01 * id), "leaf", 5));
    }
    scene.environment.push_back({"ground", testing::Rectangle(1.0, 1.0, 0.0), "leaf"});
    return scene;
}

void ExpectEachOrganFound(const std::vector<NodeId>& leaves) {
    const Scene scene = Plant(leaves);
    const FlatScene flat = ReceiversOf(scene);
    const OrganReceivers organs(flat);
    ASSERT_EQ(organs.Count(), leaves.size());
    ASSERT_EQ(flat.receivers.size(), leaves.size() + 1);  // and the ground
    std::uint32_t triangles = 0;
    for (std::uint32_t r = 0; r < organs.Count(); ++r) {
        EXPECT_EQ(organs.Of(flat.receivers[r].node), r) << "node " << flat.receivers[r].node;
        triangles += flat.receivers[r].triangleCount;
    }
    EXPECT_EQ(organs.Triangles(), triangles);
    EXPECT_EQ(organs.Of(5), OrganReceivers::kNone);  // the plant: no organ
    for (const NodeId missing : {NodeId{0}, NodeId{15}, NodeId{1000}})
        EXPECT_EQ(organs.Of(missing), OrganReceivers::kNone) << "node " << missing;
}

TEST(OrganReceivers, FindsEachOrganByItsNodeInIdOrderOrNot) {
    ExpectEachOrganFound({10, 20, 30, 40});  // searched in place
    ExpectEachOrganFound({40, 10, 30, 20});  // through the index
    ExpectEachOrganFound({});
}

}  // namespace
}  // namespace leaflux
