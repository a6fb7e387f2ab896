// InstanceTree: the parts of a scene are the same whatever the order of its nodes, walked
// without a topology when they are in the walk's order and through one when not.
#include "solver/instancing/instance_tree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>

#include "server/policy_proto.h"
#include "solver/generate/generator.h"
#include "solver/scene/topology.h"

namespace leaflux {
namespace {

// Each part by its root's id: its nodes' ids, the ids of the roots of its instances.
struct PartById {
    const InstanceTree::Part* part;
    std::vector<NodeId> nodes, instances;
};

std::map<NodeId, PartById> ById(const Scene& scene, const InstanceTree& tree) {
    std::map<NodeId, PartById> parts;
    for (const InstanceTree::Part& part : tree.Parts()) {
        PartById& p = parts[part.root];
        p.part = &part;
        for (std::uint32_t i : part.nodes) p.nodes.push_back(scene.nodes[i].id);
        for (std::uint32_t q : part.instances) p.instances.push_back(tree[q].root);
        std::sort(p.nodes.begin(), p.nodes.end());
        std::sort(p.instances.begin(), p.instances.end());
    }
    return parts;
}

TEST(InstanceTree, ItsPartsAreTheSameWhateverTheOrderOfTheNodes) {
    Scene scene;
    TreeParameters tree;
    tree.leafCount = 400;
    const NodeId next = AddTree(scene, tree, {0.0, 0.0, 0.0});
    AddTree(scene, tree, {2.0, 0.5, 0.0}, next);
    Scene shuffled = scene;
    std::mt19937_64 random(7);
    std::shuffle(shuffled.nodes.begin(), shuffled.nodes.end(), random);
    ASSERT_TRUE(InWalkOrder(scene));
    ASSERT_FALSE(InWalkOrder(shuffled));
    const InstancingPolicy policy = DefaultPolicy();
    const InstanceTree walked(scene, ComputeSignatures(scene, policy));
    const InstanceTree topological(shuffled, ComputeSignatures(shuffled, policy));
    ASSERT_GT(walked.Parts().size(), 4u);  // plants holding axes
    EXPECT_EQ(walked.Depth(), topological.Depth());
    const std::map<NodeId, PartById> a = ById(scene, walked), b = ById(shuffled, topological);
    ASSERT_EQ(a.size(), b.size());
    for (const auto& [root, p] : a) {
        const PartById& q = b.at(root);
        EXPECT_EQ(p.nodes, q.nodes) << root;
        EXPECT_EQ(p.instances, q.instances) << root;
        EXPECT_EQ(p.part->depth, q.part->depth) << root;
        EXPECT_EQ(p.part->signature, q.part->signature) << root;
        EXPECT_EQ(p.part->triangles, q.part->triangles) << root;
        if (root == kNoParent) continue;  // the top has no box
        // The box is a bound, the same whatever the order; the areas sums, within rounding.
        EXPECT_EQ(p.part->boxMin, q.part->boxMin) << root;
        EXPECT_EQ(p.part->boxMax, q.part->boxMax) << root;
        EXPECT_NEAR(p.part->leafAreaM2, q.part->leafAreaM2, 1e-12 * q.part->leafAreaM2) << root;
        ASSERT_TRUE(p.part->area && q.part->area) << root;
        for (int c = 0; c < AreaGrid::kCount; ++c)
            EXPECT_NEAR(p.part->area->share[c], q.part->area->share[c], 1e-6) << root;
    }
}

}  // namespace
}  // namespace leaflux
