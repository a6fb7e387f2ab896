// Exact copies and shared structures: the generator's copies are exact in their axis or
// plant frame, an instanced scene file reads back as the scene it was written from (node by
// node, triangle by triangle), it grows with the placements only, and every bad reference
// in it is an InputError naming the field.
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <map>
#include <set>
#include <unordered_map>

#include "server/scene_proto.h"
#include "solver/generate/generator.h"
#include "solver/scene/geometry.h"
#include "solver/scene/world_frames.h"
#include "solver/util/error.h"
#include "tests/temp_file.h"

namespace leaflux {
namespace {

// A digest of the default 500-leaf tree's ids, parents and frames, taken from the generator
// (first before copies existed; again when frames came to keep their linear part in single
// precision): the tree every table was measured on.
constexpr std::uint64_t kDefaultTreeDigest = 9561633741689640137ull;

Scene Empty() {
    Scene scene;
    scene.bands = {{"PAR"}};
    scene.optics = {{"leaf", {{0.1, 0.1, 0.05, 0.05}}}, {"stem", {{0.1, 0.1, 0, 0}}}};
    scene.sources.skies.push_back({SkyModel::kUniform, {100.0}, SkyDiscretization::kTurtle46});
    return scene;
}

Scene Plantation(int trees, bool copies, int leaves = 300) {
    Scene scene = Empty();
    PlantationParameters p;
    p.tree.leafCount = leaves;
    p.tree.copies = copies;
    p.rows = 1;
    p.columns = trees;
    p.prototypes = 2;
    AddPlantation(scene, p, "");
    return scene;
}

std::string Text(const Scene& scene, SceneWriting writing) {
    std::string text;
    google::protobuf::TextFormat::PrintToString(ToProto(scene, writing), &text);
    return text;
}

Scene RoundTrip(const Scene& scene, SceneWriting writing, const std::string& name) {
    const std::string path = testing::TempPath(name);
    SaveSceneFile(scene, path, writing);
    return LoadSceneFile(path);
}

bool SameBits(const glm::dmat4& a, const glm::dmat4& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

// Node by node: every field, frames bit for bit, meshes by content.
void ExpectSameNodes(const Scene& a, const Scene& b) {
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    for (std::size_t i = 0; i < a.nodes.size(); ++i) {
        const Node &x = a.nodes[i], &y = b.nodes[i];
        ASSERT_EQ(x.id, y.id) << "node " << i;
        EXPECT_EQ(x.parent, y.parent) << "node " << x.id;
        EXPECT_EQ(x.type(), y.type()) << "node " << x.id;
        EXPECT_EQ(x.name(), y.name()) << "node " << x.id;
        EXPECT_TRUE(SameBits(x.parentFromLocal(), y.parentFromLocal())) << "node " << x.id;
        EXPECT_EQ(x.age(), y.age()) << "node " << x.id;
        EXPECT_EQ(x.attributes(), y.attributes()) << "node " << x.id;
        ASSERT_EQ(x.organ().has_value(), y.organ().has_value()) << "node " << x.id;
        if (!x.organ()) continue;
        EXPECT_EQ(x.organ()->opticsId, y.organ()->opticsId);
        EXPECT_EQ(x.organ()->mesh->positions, y.organ()->mesh->positions) << "node " << x.id;
        EXPECT_EQ(x.organ()->mesh->triangles, y.organ()->mesh->triangles) << "node " << x.id;
    }
}

void ExpectSameTriangles(const Scene& a, const Scene& b) {
    const FlatScene fa = Flatten(a), fb = Flatten(b);
    ASSERT_EQ(fa.triangles.size(), fb.triangles.size());
    ASSERT_EQ(fa.receivers.size(), fb.receivers.size());
    for (std::size_t t = 0; t < fa.triangles.size(); ++t) {
        ASSERT_EQ(fa.triangles[t].a, fb.triangles[t].a) << t;
        ASSERT_EQ(fa.triangles[t].b, fb.triangles[t].b) << t;
        ASSERT_EQ(fa.triangles[t].c, fb.triangles[t].c) << t;
        ASSERT_EQ(fa.triangles[t].receiver, fb.triangles[t].receiver) << t;
    }
}

// What hangs below `top`, in depth-first order: each organ's frame in top's frame (the
// product of the local frames below top), its mesh and optics; each node's type and
// attributes. Two subtrees are exact copies when these are equal bit for bit.
struct Below {
    std::vector<NodeType> types;
    std::vector<Attributes> attributes;
    std::vector<glm::dmat4> topFromOrgan;
    std::vector<const Mesh*> meshes;
};

Below Describe(const Scene& scene, NodeId top) {
    std::unordered_map<NodeId, std::vector<const Node*>> children;
    for (const Node& node : scene.nodes) children[node.parent].push_back(&node);
    Below below;
    std::vector<std::pair<const Node*, glm::dmat4>> stack;
    for (auto it = children[top].rbegin(); it != children[top].rend(); ++it) {
        stack.push_back({*it, glm::dmat4((*it)->parentFromLocal())});
    }
    while (!stack.empty()) {
        const auto [node, topFromLocal] = stack.back();
        stack.pop_back();
        below.types.push_back(node->type());
        below.attributes.push_back(node->attributes());
        if (node->organ()) {
            below.topFromOrgan.push_back(topFromLocal);
            below.meshes.push_back(node->organ()->mesh.get());
        }
        const auto& c = children[node->id];
        for (auto it = c.rbegin(); it != c.rend(); ++it) {
            stack.push_back({*it, topFromLocal * glm::dmat4((*it)->parentFromLocal())});
        }
    }
    return below;
}

bool ExactCopies(const Below& a, const Below& b) {
    if (a.types != b.types || a.attributes != b.attributes || a.meshes != b.meshes) return false;
    for (std::size_t i = 0; i < a.topFromOrgan.size(); ++i) {
        if (!SameBits(a.topFromOrgan[i], b.topFromOrgan[i])) return false;
    }
    return true;
}

// Axes of order ≥ 1 by (order, leaves below them).
std::map<std::pair<int, std::size_t>, std::vector<NodeId>> AxesByClass(const Scene& scene) {
    std::map<std::pair<int, std::size_t>, std::vector<NodeId>> classes;
    for (const Node& node : scene.nodes) {
        if (node.type() != NodeType::kAxis || node.attributes().at("order") < 1) continue;
        std::size_t leaves = 0;
        for (NodeType type : Describe(scene, node.id).types) leaves += type == NodeType::kLeaf;
        classes[{static_cast<int>(node.attributes().at("order")), leaves}].push_back(node.id);
    }
    return classes;
}

TEST(GeneratorCopies, LateralAxesOfOneOrderAndSizeAreExactCopies) {
    Scene scene = Empty();
    TreeParameters tree;
    tree.leafCount = 2000;
    tree.copies = true;
    AddTree(scene, tree, {1, 2, 0});
    scene.Validate();
    std::size_t leaves = 0;
    for (const Node& node : scene.nodes) leaves += node.type() == NodeType::kLeaf;
    EXPECT_EQ(leaves, 2000u);
    const auto frames = WorldFromLocal(scene);
    std::size_t compared = 0;
    for (const auto& [key, axes] : AxesByClass(scene)) {
        const Below prototype = Describe(scene, axes.front());
        for (std::size_t k = 1; k < axes.size(); ++k) {
            EXPECT_TRUE(ExactCopies(prototype, Describe(scene, axes[k])))
                << "order " << key.first << ", " << key.second << " leaves, axis " << axes[k];
            EXPECT_FALSE(SameBits(frames.at(axes.front()), frames.at(axes[k])));
            ++compared;
        }
    }
    EXPECT_GT(compared, 100u);
}

TEST(GeneratorCopies, DefaultAxesAreNotCopies) {
    // The check above can fail: without copies, axes of one class differ.
    Scene scene = Empty();
    TreeParameters tree;
    tree.leafCount = 2000;
    AddTree(scene, tree, {0, 0, 0});
    std::size_t copies = 0, compared = 0;
    for (const auto& [key, axes] : AxesByClass(scene)) {
        for (std::size_t k = 1; k < axes.size(); ++k, ++compared) {
            copies += ExactCopies(Describe(scene, axes.front()), Describe(scene, axes[k]));
        }
    }
    EXPECT_GT(compared, 100u);
    EXPECT_EQ(copies, 0u);
}

TEST(GeneratorCopies, KeepsTheLeafCountAndTheDefaultTree) {
    for (int count : {1, 7, 10, 99, 1000, 4321}) {
        Scene scene = Empty();
        TreeParameters tree;
        tree.leafCount = count;
        tree.copies = true;
        AddTree(scene, tree, {0, 0, 0});
        scene.Validate();
        int leaves = 0;
        for (const Node& node : scene.nodes) leaves += node.type() == NodeType::kLeaf;
        EXPECT_EQ(leaves, count);
    }
    // The default tree, as every table was measured on: a digest of its nodes' frames.
    Scene scene = Empty();
    TreeParameters tree;
    tree.leafCount = 500;
    AddTree(scene, tree, {0, 0, 0});
    std::uint64_t digest = 1469598103934665603ull;  // FNV-1a over ids, parents and frames
    for (const Node& node : scene.nodes) {
        auto mix = [&](const void* data, std::size_t size) {
            for (std::size_t i = 0; i < size; ++i) {
                digest = (digest ^ static_cast<const unsigned char*>(data)[i]) * 1099511628211ull;
            }
        };
        mix(&node.id, sizeof node.id);
        mix(&node.parent, sizeof node.parent);
        const glm::dmat4 frame(node.parentFromLocal());  // as the digest was first taken
        mix(&frame, sizeof frame);
    }
    EXPECT_EQ(scene.nodes.size(), 1173u);
    EXPECT_EQ(digest, kDefaultTreeDigest);
}

TEST(GeneratorCopies, PlantationTreesAreCopiesOfPrototypes) {
    const Scene scene = Plantation(5, true);
    scene.Validate();
    std::vector<NodeId> plants;
    for (const Node& node : scene.nodes) {
        if (node.type() == NodeType::kPlant) plants.push_back(node.id);
    }
    ASSERT_EQ(plants.size(), 5u);
    const Below first = Describe(scene, plants[0]), second = Describe(scene, plants[1]);
    EXPECT_FALSE(ExactCopies(first, second));  // two prototypes
    EXPECT_TRUE(ExactCopies(first, Describe(scene, plants[2])));
    EXPECT_TRUE(ExactCopies(first, Describe(scene, plants[4])));
    EXPECT_TRUE(ExactCopies(second, Describe(scene, plants[3])));
}

TEST(InstancedSceneFile, RoundTripsAPlantationOfCopiesNodeByNode) {
    const Scene scene = Plantation(6, true);
    const v1::Scene message = ToProto(scene, SceneWriting::kInstanced);
    EXPECT_GE(message.structures_size(), 3);  // two trees, their axes
    EXPECT_EQ(message.placements_size(), 6);  // every tree a placement of one of two
    EXPECT_EQ(message.nodes_size(), 0);
    const Scene back = RoundTrip(scene, SceneWriting::kInstanced, "copies.scene.txtpb");
    ExpectSameNodes(scene, back);
    ExpectSameTriangles(scene, back);
    auto meshes = [](const Scene& s) {
        std::set<const Mesh*> distinct;
        for (const Node& node : s.nodes) {
            if (node.organ()) distinct.insert(node.organ()->mesh.get());
        }
        return distinct.size();
    };
    EXPECT_EQ(meshes(scene), 4u);  // each prototype tree's leaf and internode meshes
    EXPECT_EQ(meshes(back), 4u);   // stay shared by every copy
}

TEST(InstancedSceneFile, RoundTripsTheDefaultPlantationAndAHandMadeScene) {
    const Scene scene = Plantation(3, false);
    const Scene back = RoundTrip(scene, SceneWriting::kInstanced, "default.scene.txtpb");
    ExpectSameNodes(scene, back);
    ExpectSameTriangles(scene, back);
    // Ids not in depth-first order and literal names: copies are still found and kept.
    Scene hand = Empty();
    auto leaf = std::make_shared<Mesh>();
    leaf->positions = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}};
    leaf->triangles = {{0, 1, 2}};
    for (NodeId plant : {50, 10}) {
        Node p;
        p.id = plant;
        p.Edit().type = NodeType::kPlant;
        p.Edit().name = "tree";
        p.Edit().parentFromLocal = glm::translate(glm::dmat4(1.0), glm::dvec3(plant * 0.1, 0, 0));
        hand.nodes.push_back(p);
        for (NodeId k : {3, 1, 2}) {
            Node l;
            l.id = plant - k;
            l.parent = plant;
            l.Edit().type = NodeType::kLeaf;
            l.Edit().name = "leaf" + std::to_string(l.id);
            l.Edit().parentFromLocal = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, 0.1 * k));
            l.Edit().organ = Organ{leaf, "leaf"};
            hand.nodes.push_back(l);
        }
    }
    hand.Validate();
    const v1::Scene message = ToProto(hand, SceneWriting::kInstanced);
    EXPECT_EQ(message.structures_size(), 1);
    Scene sorted = hand;
    std::stable_sort(sorted.nodes.begin(), sorted.nodes.end(),
                     [](const Node& a, const Node& b) { return a.id < b.id; });
    ExpectSameNodes(sorted, RoundTrip(hand, SceneWriting::kInstanced, "hand.scene.txtpb"));
}

TEST(InstancedSceneFile, GrowsByThePlacementsOnly) {
    // Measured, not timed: 4 trees of copies against 40 (two prototypes each time).
    const std::size_t flat4 = Text(Plantation(4, true), SceneWriting::kFlat).size();
    const std::size_t flat40 = Text(Plantation(40, true), SceneWriting::kFlat).size();
    const std::size_t instanced4 = Text(Plantation(4, true), SceneWriting::kInstanced).size();
    const std::size_t instanced40 = Text(Plantation(40, true), SceneWriting::kInstanced).size();
    const double perTreeFlat = (flat40 - flat4) / 36.0;
    const double perTreeInstanced = (instanced40 - instanced4) / 36.0;
    std::printf(
        "scene file bytes: flat %zu → %zu (%.0f a tree), instanced %zu → %zu (%.0f a tree)\n",
        flat4, flat40, perTreeFlat, instanced4, instanced40, perTreeInstanced);
    // A placement: a structure name, a frame of 12 numbers, an id offset.
    EXPECT_LT(perTreeInstanced, 400.0);
    EXPECT_GT(perTreeFlat, 500.0 * perTreeInstanced);
    EXPECT_LT(instanced40, flat4);
}

// ---- Bad references -----------------------------------------------------------------

const char* kHeader = R"(
bands { name: "PAR" }
optics { id: "leaf" bands { key: "PAR" value { rho_upper: 0.1 rho_lower: 0.1 tau_upper: 0.05 tau_lower: 0.05 } } }
meshes { key: "blade" value { positions: [0, 0, 0, 0.1, 0, 0, 0, 0.1, 0] triangles: [0, 1, 2] } }
structures { key: "shoot" value {
  nodes { id: 1 type: NODE_TYPE_AXIS name: "shoot{id}" }
  nodes { id: 2 parent: 1 type: NODE_TYPE_LEAF name: "leaf{id}" frame { m: [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0.2] }
          attributes { key: "length_m" value: 0.1 } organ { mesh_ref: "blade" optics: "leaf" } }
} }
structures { key: "plant" value {
  nodes { id: 1 type: NODE_TYPE_PLANT name: "plant{id}" }
  placements { structure: "shoot" parent: 1 id_offset: 1 }
  placements { structure: "shoot" parent: 1 id_offset: 3 frame { m: [0, -1, 0, 0,  1, 0, 0, 0,  0, 0, 1, 0.5] } }
  placements { structure: "shoot" id_offset: 5 frame { m: [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 1] } }
} }
)";

Scene Load(const std::string& text) {
    const std::string path = testing::TempPath("structures.scene.txtpb");
    std::ofstream(path) << text;
    return LoadSceneFile(path);
}

TEST(InstancedSceneFile, ExpandsNestedPlacementsWithIdsNamesAndFrames) {
    const Scene scene = Load(std::string(kHeader) + R"(
nodes { id: 1 type: NODE_TYPE_OTHER name: "field" }
placements { structure: "plant" parent: 1 id_offset: 100 frame { m: [1, 0, 0, 5,  0, 1, 0, 0,  0, 0, 1, 0] } }
placements { structure: "plant" id_offset: 200 }
)");
    ASSERT_EQ(scene.nodes.size(), 1u + 2u * 7u);
    std::map<NodeId, const Node*> byId;
    for (const Node& node : scene.nodes) byId[node.id] = &node;
    ASSERT_TRUE(byId.count(101) && byId.count(103) && byId.count(206));
    EXPECT_EQ(byId[101]->parent, 1u);
    EXPECT_EQ(byId[101]->name(), "plant101");
    EXPECT_EQ(byId[104]->parent, 101u);
    EXPECT_EQ(byId[105]->name(), "leaf105");
    EXPECT_EQ(byId[105]->parent, 104u);
    EXPECT_EQ(byId[106]->parent, 1u);  // parent 0 in "plant": hangs where the plant does
    EXPECT_EQ(byId[201]->parent, 0u);
    const auto world = WorldFromLocal(scene);
    EXPECT_LT(glm::length(glm::dvec3(world.at(103)[3]) - glm::dvec3(5, 0, 0.2)), 1e-12);
    EXPECT_LT(glm::length(glm::dvec3(world.at(105)[3]) - glm::dvec3(5, 0, 0.7)), 1e-12);
    EXPECT_LT(glm::length(glm::dvec3(world.at(106)[3]) - glm::dvec3(5, 0, 1)),
              1e-12);  // frames composed
    EXPECT_LT(glm::length(glm::dvec3(world.at(104)[0]) - glm::dvec3(0, 1, 0)),
              1e-12);                                               // turned by its placement
    EXPECT_EQ(byId[105]->organ()->mesh, byId[205]->organ()->mesh);  // meshes stay shared
}

TEST(InstancedSceneFile, PlacedCopiesShareTheirNodesBodiesUntilOneChanges) {
    Scene scene = Load(std::string(kHeader) + R"(
placements { structure: "plant" id_offset: 100 frame { m: [1, 0, 0, 5,  0, 1, 0, 0,  0, 0, 1, 0] } }
placements { structure: "plant" id_offset: 200 }
)");
    std::map<NodeId, Node*> byId;
    for (Node& node : scene.nodes) byId[node.id] = &node;
    for (const NodeId id : {101, 104, 105, 106, 201, 204, 205, 206}) ASSERT_TRUE(byId.count(id));
    EXPECT_TRUE(byId[105]->SharesBodyWith(*byId[205]));   // the leaf: held once
    EXPECT_FALSE(byId[101]->SharesBodyWith(*byId[201]));  // a root moved by its placement
    // A shoot placed inside the plant: the same root at the same frame in both copies.
    EXPECT_TRUE(byId[104]->SharesBodyWith(*byId[204]));
    // A shoot placed at the plant's root: moved by each plant's placement.
    EXPECT_FALSE(byId[106]->SharesBodyWith(*byId[206]));
    EXPECT_NE(glm::dmat4(byId[106]->parentFromLocal()), glm::dmat4(byId[206]->parentFromLocal()));
    const glm::dmat4 before(byId[205]->parentFromLocal());
    byId[105]->Edit().parentFromLocal = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, 9));
    byId[105]->Edit().organ->opticsId = "bark";
    EXPECT_FALSE(byId[105]->SharesBodyWith(*byId[205]));
    EXPECT_EQ(glm::dmat4(byId[205]->parentFromLocal()), before);
    EXPECT_EQ(byId[205]->organ()->opticsId.str(), "leaf");
    EXPECT_EQ(byId[105]->organ()->mesh, byId[205]->organ()->mesh);
    EXPECT_EQ(byId[105]->parentFromLocal().At(3, 2), 9.0);
}

struct BadFile {
    const char* text;
    ErrorCode code;
    const char* field;
};

TEST(InstancedSceneFile, NamesTheFieldOfEveryBadReference) {
    const BadFile cases[] = {
        {"placements { structure: \"tree\" }", ErrorCode::kNotFound, "placements[0].structure"},
        {"structures { key: \"a\" value { placements { structure: \"b\" } } }\n"
         "placements { structure: \"a\" }",
         ErrorCode::kNotFound, "structures[a].placements[0].structure"},
        {"structures { key: \"a\" value { nodes { id: 1 } placements { structure: \"b\" } } }\n"
         "structures { key: \"b\" value { nodes { id: 1 } placements { structure: \"a\" } } }\n"
         "placements { structure: \"a\" }",
         ErrorCode::kCycle, "structures[b].placements[0].structure"},
        {"structures { key: \"a\" value { nodes { id: 1 } placements { structure: \"a\" } } }\n"
         "placements { structure: \"a\" }",
         ErrorCode::kCycle, "structures[a].placements[0].structure"},
        {"placements { structure: \"shoot\" id_offset: 10 }\n"
         "placements { structure: \"shoot\" id_offset: 11 }",
         ErrorCode::kAlreadyExists, ".id_offset"},
        {"nodes { id: 12 }\nplacements { structure: \"shoot\" id_offset: 10 }",
         ErrorCode::kAlreadyExists, "placements[0].id_offset"},
        {"placements { structure: \"plant\" id_offset: 18446744073709551614 }",
         ErrorCode::kInvalidArgument, ".id_offset"},
        {"structures { key: \"a\" value { nodes { id: 1 } nodes { id: 2 parent: 7 } } }\n"
         "placements { structure: \"a\" }",
         ErrorCode::kNotFound, "structures[a].nodes.parent"},
        {"structures { key: \"a\" value { nodes { id: 1 } nodes { id: 1 } } }\n"
         "placements { structure: \"a\" }",
         ErrorCode::kAlreadyExists, "structures[a].nodes.id"},
        {"structures { key: \"a\" value { nodes { id: 1 }\n"
         "  placements { structure: \"shoot\" parent: 3 } } }\n"
         "placements { structure: \"a\" id_offset: 10 }",
         ErrorCode::kNotFound, "structures[a].placements[0].parent"},
        {"structures { key: \"a\" value { nodes { id: 1 organ { mesh_ref: \"none\" } } } }\n"
         "placements { structure: \"a\" }",
         ErrorCode::kNotFound, "structures[a].nodes.organ.mesh_ref"},
        {"placements { structure: \"shoot\" parent: 99 }", ErrorCode::kNotFound, "parent"},
        {"placements { structure: \"shoot\" frame { m: [1, 2] } }", ErrorCode::kInvalidArgument,
         "placements[0].frame"},
    };
    for (const BadFile& c : cases) {
        try {
            Load(std::string(kHeader) + c.text);
            ADD_FAILURE() << "accepted: " << c.text;
        } catch (const InputError& e) {
            EXPECT_EQ(e.Code(), c.code) << c.text << "\n" << e.what();
            EXPECT_NE(e.Field().find(c.field), std::string::npos)
                << c.text << "\nfield: " << e.Field() << " — " << e.what();
        }
    }
}

TEST(InstancedSceneFile, CountsPlacedNodesAgainstTheLimitBeforeExpanding) {
    // A nest of placements doubling at each level: 2^40 nodes from a few lines.
    std::string text =
        std::string(kHeader) + "structures { key: \"s0\" value { nodes { id: 1 } } }\n";
    for (int level = 1; level <= 40; ++level) {
        text += "structures { key: \"s" + std::to_string(level) +
                "\" value { placements { structure: \"s" + std::to_string(level - 1) +
                "\" } placements { structure: \"s" + std::to_string(level - 1) +
                "\" id_offset: " + std::to_string(1ull << (level - 1)) + " } } }\n";
    }
    text += "placements { structure: \"s40\" }\n";
    v1::Scene message;
    ASSERT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &message));
    EXPECT_THROW(FromProto(message, ""), TooLarge);
    SceneLimits limits;
    limits.maxNodes = 100;
    message.clear_placements();
    message.add_placements()->set_structure("s7");  // 128 nodes
    EXPECT_THROW(FromProto(message, "", limits), TooLarge);
    message.mutable_placements(0)->set_structure("s6");  // 64 nodes
    EXPECT_EQ(FromProto(message, "", limits).nodes.size(), 64u);
}

}  // namespace
}  // namespace leaflux
