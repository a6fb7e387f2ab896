// WorldFrames, ForEachWorldFrame and ForEachFrameUnder: every node's frame in the world is
// the product of its ancestors' frames, whatever the order of the nodes and their ids;
// nodes whose parent links loop or lead nowhere have none.
#include "solver/scene/world_frames.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <glm/gtc/matrix_transform.hpp>
#include <set>
#include <stdexcept>

#include "solver/generate/generator.h"
#include "solver/scene/topology.h"

namespace leaflux {
namespace {

Node At(NodeId id, NodeId parent, const glm::dmat4& parentFromLocal) {
    Node node;
    node.id = id;
    node.parent = parent;
    node.Edit().parentFromLocal = parentFromLocal;
    return node;
}

// The frame by walking up from the node, one parent at a time.
glm::dmat4 ByWalkingUp(const Scene& scene, NodeId id) {
    glm::dmat4 frame(1.0);
    while (id != kNoParent) {
        const Node& node = *std::find_if(scene.nodes.begin(), scene.nodes.end(),
                                         [&](const Node& n) { return n.id == id; });
        frame = glm::dmat4(node.parentFromLocal()) * frame;
        id = node.parent;
    }
    return frame;
}

// Every element within `tolerance` (0: the same to the last bit but rounding, as
// EXPECT_DOUBLE_EQ takes it).
void ExpectFrame(const glm::dmat4& got, const glm::dmat4& expected, double tolerance, NodeId id) {
    for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) {
            if (tolerance == 0.0) {
                EXPECT_DOUBLE_EQ(got[c][r], expected[c][r]) << "node " << id;
            } else {
                EXPECT_NEAR(got[c][r], expected[c][r], tolerance) << "node " << id;
            }
        }
    }
}

TEST(WorldFrames, AreTheProductsOfTheAncestorsFramesInAnyOrder) {
    const glm::dmat4 lift = glm::translate(glm::dmat4(1.0), {0.0, 0.0, 1.0});
    const glm::dmat4 turn = glm::rotate(glm::dmat4(1.0), 0.3, glm::dvec3(1.0, 0.0, 0.0));
    const glm::dmat4 grow = glm::scale(glm::dmat4(1.0), glm::dvec3(2.0));
    Scene scene;
    // Children before their parents, ids falling and rising.
    scene.nodes = {At(7, 40, grow), At(40, 3, turn), At(3, kNoParent, lift), At(9, 3, grow)};
    const WorldFrames frames(scene);
    EXPECT_EQ(frames.size(), 4u);
    for (const Node& node : scene.nodes) {
        const glm::dmat4 expected = ByWalkingUp(scene, node.id), got = frames.at(node.id);
        ExpectFrame(got, expected, 0.0, node.id);
    }
    EXPECT_THROW(frames.at(8), std::out_of_range);
}

TEST(WorldFrames, OfAGeneratedTreeAreItsNodesWalkedUp) {
    Scene scene;
    TreeParameters tree;
    tree.leafCount = 60;
    AddTree(scene, tree, {1.0, 2.0, 0.0});
    std::reverse(scene.nodes.begin(), scene.nodes.end());  // ids falling
    const WorldFrames frames(scene);
    ASSERT_EQ(frames.size(), scene.nodes.size());
    for (const Node& node : scene.nodes) {
        const glm::dmat4 expected = ByWalkingUp(scene, node.id), got = frames.at(node.id);
        ExpectFrame(got, expected, 1e-12, node.id);
    }
}

TEST(WorldFrames, AWalkVisitsEachNodeOnceAfterItsParentWithItsFrame) {
    Scene scene;
    TreeParameters tree;
    tree.leafCount = 60;
    AddTree(scene, tree, {1.0, 2.0, 0.0});
    std::reverse(scene.nodes.begin(), scene.nodes.end());      // children before their parents
    scene.nodes.push_back(At(90001, 90002, glm::dmat4(1.0)));  // under a missing parent
    const WorldFrames frames(scene);
    std::set<NodeId> visited;
    ForEachWorldFrame(scene, [&](const Node& node, const glm::dmat4& frame) {
        EXPECT_TRUE(node.parent == kNoParent || visited.count(node.parent)) << node.id;
        EXPECT_TRUE(visited.insert(node.id).second) << node.id;
        ExpectFrame(frame, frames.at(node.id), 1e-12, node.id);
    });
    EXPECT_EQ(visited.size(), scene.nodes.size() - 1);
    EXPECT_FALSE(visited.count(90001));
}

// Nodes already in the walk's order, their ids rising (two generated trees), are walked
// without a topology, the whole scene and each subtree: the same nodes in the same order
// with the same frames, to the bit, as the walk over their topology gives.
TEST(WorldFrames, NodesInWalkOrderAreWalkedAsTheirTopologyWalksThem) {
    Scene scene;
    TreeParameters tree;
    tree.leafCount = 60;
    NodeId next = AddTree(scene, tree, {1.0, 2.0, 0.0});
    AddTree(scene, tree, {-3.0, 0.5, 0.0}, next);
    std::vector<std::pair<const Node*, glm::dmat4>> walked, topological;
    ForEachWorldFrame(scene, [&](const Node& node, const glm::dmat4& frame) {
        walked.push_back({&node, frame});
    });
    ForEachWorldFrame(scene, Topology(scene), [&](const Node& node, const glm::dmat4& frame) {
        topological.push_back({&node, frame});
    });
    ASSERT_EQ(walked.size(), scene.nodes.size());
    ASSERT_EQ(walked.size(), topological.size());
    for (std::size_t k = 0; k < walked.size(); ++k) {
        ASSERT_EQ(walked[k].first, topological[k].first) << k;
        EXPECT_EQ(walked[k].first, &scene.nodes[k]);  // in the nodes' order
        for (int c = 0; c < 4; ++c)
            EXPECT_EQ(walked[k].second[c], topological[k].second[c]) << walked[k].first->id;
    }
    // Every subtree too, in its root's frame.
    const Topology topology(scene);
    for (std::size_t root = 0; root < scene.nodes.size(); root += 7) {
        std::vector<std::pair<const Node*, glm::dmat4>> under, underTopology;
        ForEachFrameUnder(scene, nullptr, root, glm::dmat4(1.0),
                          [&](const Node& node, const glm::dmat4& f) {
                              under.push_back({&node, f});
                          });
        ForEachFrameUnder(scene, topology, root, glm::dmat4(1.0),
                          [&](const Node& node, const glm::dmat4& f) {
                              underTopology.push_back({&node, f});
                          });
        ASSERT_EQ(under.size(), underTopology.size()) << root;
        for (std::size_t k = 0; k < under.size(); ++k) {
            ASSERT_EQ(under[k].first, underTopology[k].first) << root;
            for (int c = 0; c < 4; ++c) EXPECT_EQ(under[k].second[c], underTopology[k].second[c]);
        }
    }
}

// A subtree walked in its root's own frame, then placed by the root's frame in the world,
// is where the world walk puts it: the frames compose (an instance's and its placement's).
TEST(WorldFrames, ASubtreeInItsRootsFramePlacedByTheRootsIsInTheWorld) {
    Scene scene;
    TreeParameters tree;
    tree.leafCount = 60;
    AddTree(scene, tree, {1.0, 2.0, 0.0});
    const WorldFrames frames(scene);
    const Topology topology(scene);
    // A node halfway down: an axis with nodes under it, not the root.
    std::size_t root = 0;
    for (std::size_t i = 0; i < scene.nodes.size(); ++i) {
        if (topology.Parent(i) != Topology::kNone && topology.Children(i).size() >= 2) root = i;
    }
    ASSERT_NE(root, 0u);
    const glm::dmat4 worldFromRoot = frames.at(scene.nodes[root].id);
    std::size_t visited = 0;
    ForEachFrameUnder(scene, topology, root, glm::dmat4(1.0),
                      [&](const Node& node, const glm::dmat4& rootFromNode) {
                          if (visited++ == 0) {
                              EXPECT_EQ(node.id, scene.nodes[root].id);
                              ExpectFrame(rootFromNode, glm::dmat4(1.0), 0.0, node.id);
                          }
                          ExpectFrame(worldFromRoot * rootFromNode, frames.at(node.id), 1e-12,
                                      node.id);
                      });
    EXPECT_GE(visited, 3u);
}

TEST(WorldFrames, NodesWhoseParentLinksLoopOrLeadNowhereHaveNone) {
    const glm::dmat4 one(1.0);
    Scene scene;
    scene.nodes = {At(1, kNoParent, one), At(2, 1, one),                 // a root and its child
                   At(3, 4, one),         At(4, 5, one), At(5, 3, one),  // a loop
                   At(6, 4, one),                                        // under the loop
                   At(7, 99, one),        At(8, 7, one)};                // under a missing parent
    const WorldFrames frames(scene);
    EXPECT_EQ(frames.size(), 2u);
    EXPECT_NO_THROW(frames.at(1));
    EXPECT_NO_THROW(frames.at(2));
    for (NodeId id : {3, 4, 5, 6, 7, 8}) EXPECT_THROW(frames.at(id), std::out_of_range) << id;
}

}  // namespace
}  // namespace leaflux
