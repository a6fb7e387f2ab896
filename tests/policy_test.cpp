// Instantiation policies (Soler 2003 §4.1): the shipped files parse and validate, every
// mistake is an InputError naming the field or file:line:column, the content hash follows
// the meaning and not the layout, and the signatures of a generated tree group structures
// of one type and bins, whatever the order of the scene's nodes.
#include "solver/instancing/policy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <unordered_map>

#include "server/policy_proto.h"
#include "solver/generate/generator.h"
#include "solver/instancing/signature.h"
#include "solver/scene/topology.h"
#include "solver/util/error.h"
#include "tests/scene_builders.h"
#include "tests/temp_file.h"

namespace leaflux {
namespace {

using testing::Leaf;
using testing::OneBandScene;
using testing::Opaque;

std::string PolicyPath(const std::string& name) {
    return std::string(LEAFLUX_SOURCE_DIR) + "/proto/policies/" + name;
}

using testing::TempPath;
using testing::WriteTempFile;

const char* kMinimal = R"(species: "test"
instance_types: [NODE_TYPE_AXIS]
by_type: true
leaf_count { edges: [1, 10, 100] }
phase { kind: FUNCTION_KIND_MONO direction_count: 130 }
transmittance { kind: FUNCTION_KIND_MONO level: 3 }
)";

// The error a policy text (kMinimal followed by `extra`, or `text` alone) raises.
InputError FileError(const std::string& text) {
    const std::string path = WriteTempFile("bad_policy.txtpb", text);
    try {
        LoadPolicyFile(path);
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "accepted:\n" << text;
    return InputError(ErrorCode::kInvalidArgument, "", "");
}

InputError PolicyError(const InstancingPolicy& policy) {
    try {
        ValidatePolicy(policy);
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "accepted a bad policy";
    return InputError(ErrorCode::kInvalidArgument, "", "");
}

InstancingPolicy Minimal() {
    InstancingPolicy policy;
    policy.species = "test";
    policy.instanceTypes = {NodeType::kPlant, NodeType::kAxis};
    policy.leafCount.edges = {1, 10, 100, 1000};
    policy.age.edges = {0, 1, 2, 8};
    policy.attributes = {{"order", {{0, 1, 8}}}};
    policy.fixed = {{NodeType::kAxis, 1000}};
    return policy;
}

Scene GeneratedTree(int leaves, std::uint64_t seed = 3) {
    Scene scene = OneBandScene({{"leaf", Leaf(0.1, 0.05)}, {"stem", Opaque(0.3)}});
    TreeParameters tree;
    tree.leafCount = leaves;
    tree.seed = seed;
    AddTree(scene, tree, {0, 0, 0});
    scene.Validate();
    return scene;
}

TEST(PolicyFile, ShippedPoliciesParseAndValidate) {
    for (const char* name : {"default.txtpb", "every_structure.txtpb", "generated_tree.txtpb",
                             "no_inclination.txtpb"}) {
        SCOPED_TRACE(name);
        const InstancingPolicy policy = LoadPolicyFile(PolicyPath(name));
        EXPECT_NO_THROW(ValidatePolicy(policy));
        EXPECT_TRUE(policy.IsInstanceType(NodeType::kPlant));
        EXPECT_TRUE(policy.IsInstanceType(NodeType::kAxis));
        EXPECT_TRUE(policy.leafCount.Used());
        EXPECT_EQ(policy.phase.kind, PhaseKind::kBiDirectional);
        EXPECT_EQ(policy.phase.level, 3);  // 130 directions
        EXPECT_EQ(policy.transmittance.level, 3);
    }
    const InstancingPolicy general = LoadPolicyFile(PolicyPath("default.txtpb"));
    // Structures of 10 leaves or fewer are left to the structure that holds them; the
    // policy of every structure bins them too.
    const std::vector<double> steps{11,  16,  23,  32,  45,  64,   91,   128,
                                    181, 256, 362, 512, 724, 1000, 10000};
    EXPECT_EQ(general.leafCount.edges, steps);
    std::vector<double> every{1, 2, 3, 4, 6, 8};
    every.insert(every.end(), steps.begin(), steps.end());
    EXPECT_EQ(LoadPolicyFile(PolicyPath("every_structure.txtpb")).leafCount.edges, every);
    ASSERT_NE(general.FixedFor(NodeType::kAxis), nullptr);
    EXPECT_EQ(general.FixedFor(NodeType::kAxis)->leafCountAbove, 10000);
    EXPECT_NE(PolicyContentHash(general),
              PolicyContentHash(LoadPolicyFile(PolicyPath("generated_tree.txtpb"))));
    // The default bins the structures' inclination in steps of 30°; the policy without
    // those bins is the default otherwise.
    EXPECT_EQ(general.inclination.edges, (std::vector<double>{0, 30, 60, 90, 120, 150, 180}));
    const InstancingPolicy upright = LoadPolicyFile(PolicyPath("no_inclination.txtpb"));
    EXPECT_EQ(upright.leafCount.edges, steps);
    EXPECT_FALSE(upright.inclination.Used());
    EXPECT_EQ(DefaultPolicy().inclination.edges, general.inclination.edges);
}

TEST(PolicyFile, UnknownFieldNamesFileLineAndColumn) {
    const std::string text = std::string(kMinimal) + "leaf_counts { edges: [1, 2] }\n";
    const std::string path = WriteTempFile("bad_policy.txtpb", text);
    const InputError e = FileError(text);
    EXPECT_EQ(e.Code(), ErrorCode::kParse);
    // Line 7; protobuf's tokenizer reports the column of the token after the unknown name.
    EXPECT_EQ(e.Field(), path + ":7:13") << e.what();
    EXPECT_NE(std::string(e.what()).find("leaf_counts"), std::string::npos) << e.what();
}

TEST(PolicyFile, SyntaxErrorNamesFileLineAndColumn) {
    const std::string text = "species: \"test\"\ninstance_types: [NODE_TYPE_AXIS\n";
    const InputError e = FileError(text);
    EXPECT_EQ(e.Code(), ErrorCode::kParse);
    EXPECT_EQ(e.Field().rfind(TempPath("bad_policy.txtpb") + ":3:", 0), 0u) << e.Field();
}

TEST(PolicyFile, MissingFileIsAnIoError) {
    try {
        LoadPolicyFile(::testing::TempDir() + "no_such_policy.txtpb");
        FAIL() << "loaded a missing file";
    } catch (const InputError& e) {
        EXPECT_EQ(e.Code(), ErrorCode::kIo);
        EXPECT_EQ(e.Field(), ::testing::TempDir() + "no_such_policy.txtpb");
    }
}

TEST(PolicyFile, SchemaMistakesNameTheField) {
    const auto field = [](const std::string& extra) {
        return FileError(std::string(kMinimal) + extra).Field();
    };
    EXPECT_EQ(field("age { }\n"), "age.edges");  // stated bins without edges
    EXPECT_EQ(field("fixed { leaf_count_above: 10 }\n"), "fixed[0].type");
    EXPECT_EQ(FileError("species: \"t\" instance_types: [NODE_TYPE_AXIS] by_type: true "
                        "phase { kind: FUNCTION_KIND_MONO direction_count: 100 } "
                        "transmittance { kind: FUNCTION_KIND_CONSTANT }")
                  .Field(),
              "phase.direction_count");
    EXPECT_EQ(FileError("species: \"t\" instance_types: [NODE_TYPE_AXIS] by_type: true "
                        "phase { kind: FUNCTION_KIND_MONO } "
                        "transmittance { kind: FUNCTION_KIND_CONSTANT }")
                  .Field(),
              "phase");
    EXPECT_EQ(FileError("species: \"t\" instance_types: [NODE_TYPE_AXIS] by_type: true "
                        "phase { level: 2 } transmittance { kind: FUNCTION_KIND_CONSTANT }")
                  .Field(),
              "phase.kind");
    EXPECT_EQ(FileError("species: \"t\" instance_types: [NODE_TYPE_UNSPECIFIED] by_type: true "
                        "phase { kind: FUNCTION_KIND_CONSTANT } "
                        "transmittance { kind: FUNCTION_KIND_CONSTANT }")
                  .Field(),
              "instance_types[0]");
    EXPECT_EQ(FileError("species: \"t\" instance_types: [NODE_TYPE_AXIS] by_type: true "
                        "transmittance { kind: FUNCTION_KIND_CONSTANT }")
                  .Field(),
              "phase");
    // A semantic mistake in a file is ValidatePolicy's, naming the field, not the line.
    const InputError overlap = FileError(std::string(kMinimal) + "age { edges: [0, 2, 1] }\n");
    EXPECT_EQ(overlap.Code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(overlap.Field(), "age.edges[2]");
}

TEST(PolicyValidation, EmptyBinsAreRefused) {
    InstancingPolicy policy = Minimal();
    policy.leafCount.edges = {10};
    EXPECT_EQ(PolicyError(policy).Field(), "leaf_count.edges");
    policy = Minimal();
    policy.leafCount.edges = {1, 10, 10, 100};  // [10, 10) holds nothing
    const InputError e = PolicyError(policy);
    EXPECT_EQ(e.Code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(e.Field(), "leaf_count.edges[2]");
    policy = Minimal();
    policy.attributes[0].bins.edges.clear();
    EXPECT_EQ(PolicyError(policy).Field(), "attributes[order].edges");
}

TEST(PolicyValidation, OverlappingBinsAreRefused) {
    InstancingPolicy policy = Minimal();
    policy.leafCount.edges = {1, 100, 10, 1000};
    EXPECT_EQ(PolicyError(policy).Field(), "leaf_count.edges[2]");
    policy = Minimal();
    policy.age.edges = {0, 3, 2};
    EXPECT_EQ(PolicyError(policy).Field(), "age.edges[2]");
    policy = Minimal();
    policy.attributes[0].bins.edges = {0, 1, 0.5};
    EXPECT_EQ(PolicyError(policy).Field(), "attributes[order].edges[2]");
    policy = Minimal();
    policy.leafCount.edges = {-1, 10};
    EXPECT_EQ(PolicyError(policy).Field(), "leaf_count.edges[0]");
    policy = Minimal();
    policy.age.edges = {0, std::numeric_limits<double>::infinity()};
    EXPECT_EQ(PolicyError(policy).Field(), "age.edges[1]");
    policy = Minimal();
    policy.inclination.edges = {0, 90, 200};  // an angle from the world's up: 0 to 180
    EXPECT_EQ(PolicyError(policy).Field(), "inclination.edges[2]");
    policy.inclination.edges = {-10, 90};
    EXPECT_EQ(PolicyError(policy).Field(), "inclination.edges[0]");
}

TEST(PolicyValidation, BadLevelsAndKindsAreRefused) {
    InstancingPolicy policy = Minimal();
    policy.phase.level = 5;
    EXPECT_EQ(PolicyError(policy).Field(), "phase.level");
    policy = Minimal();
    policy.transmittance.level = -1;
    EXPECT_EQ(PolicyError(policy).Field(), "transmittance.level");
    policy = Minimal();
    policy.transmittance.kind = PhaseKind::kBiDirectional;
    EXPECT_EQ(PolicyError(policy).Field(), "transmittance.kind");
    policy = Minimal();
    policy.phase.kind = PhaseKind::kBiDirectional;
    policy.phase.level = 4;
    EXPECT_NO_THROW(ValidatePolicy(policy));
}

TEST(PolicyValidation, NamesAndTypesAreChecked) {
    InstancingPolicy policy = Minimal();
    policy.species.clear();
    EXPECT_EQ(PolicyError(policy).Field(), "species");
    policy = Minimal();
    policy.instanceTypes.clear();
    EXPECT_EQ(PolicyError(policy).Field(), "instance_types");
    policy = Minimal();
    policy.instanceTypes.push_back(NodeType::kAxis);
    EXPECT_EQ(PolicyError(policy).Code(), ErrorCode::kAlreadyExists);
    EXPECT_EQ(PolicyError(policy).Field(), "instance_types[2]");
    policy = Minimal();
    policy.instanceTypes.push_back(NodeType::kLeaf);
    EXPECT_EQ(PolicyError(policy).Field(), "instance_types[2]");
    policy = Minimal();
    policy.attributes.push_back({"order", {{0, 1}}});
    EXPECT_EQ(PolicyError(policy).Code(), ErrorCode::kAlreadyExists);
    EXPECT_EQ(PolicyError(policy).Field(), "attributes[order].name");
    policy = Minimal();
    policy.attributes.push_back({"rank|order", {{0, 1}}});
    EXPECT_EQ(PolicyError(policy).Field(), "attributes[rank|order].name");
    policy = Minimal();
    policy.attributes.push_back({"", {{0, 1}}});
    EXPECT_EQ(PolicyError(policy).Field(), "attributes[1].name");
    policy = Minimal();
    policy.fixed.push_back({NodeType::kPhytomer, 10});
    EXPECT_EQ(PolicyError(policy).Code(), ErrorCode::kNotFound);
    EXPECT_EQ(PolicyError(policy).Field(), "fixed[1].type");
    policy = Minimal();
    policy.fixed.push_back({NodeType::kAxis, 10});
    EXPECT_EQ(PolicyError(policy).Field(), "fixed[1].type");
    policy = Minimal();
    policy.fixed[0].leafCountAbove = 0;
    EXPECT_EQ(PolicyError(policy).Field(), "fixed[0].leaf_count_above");
    policy = Minimal();
    policy.byType = false;
    policy.leafCount.edges.clear();
    policy.age.edges.clear();
    policy.attributes.clear();
    EXPECT_EQ(PolicyError(policy).Field(), "by_type");
}

TEST(PolicyValidation, UnknownAttributeIsRefusedAgainstTheScene) {
    const Scene scene = GeneratedTree(300);
    InstancingPolicy policy = Minimal();
    EXPECT_NO_THROW(ComputeSignatures(scene, policy));
    policy.attributes.push_back({"ordre", {{0, 1, 8}}});
    try {
        ComputeSignatures(scene, policy);
        FAIL() << "accepted an attribute no structure carries";
    } catch (const InputError& e) {
        EXPECT_EQ(e.Code(), ErrorCode::kNotFound);
        EXPECT_EQ(e.Field(), "attributes[ordre].name");
    }
    // Leaves carry length_m, structures do not: an attribute of another type is unknown too.
    policy.attributes.back().name = "length_m";
    EXPECT_THROW(ComputeSignatures(scene, policy), InputError);
}

TEST(PolicyBins, HalfOpenButTheLastClosed) {
    const Bins bins{{1, 10, 100}};
    EXPECT_EQ(bins.Count(), 2);
    EXPECT_EQ(bins.BinOf(0.5), -1);
    EXPECT_EQ(bins.BinOf(1), 0);
    EXPECT_EQ(bins.BinOf(9.99), 0);
    EXPECT_EQ(bins.BinOf(10), 1);
    EXPECT_EQ(bins.BinOf(100), 1);
    EXPECT_EQ(bins.BinOf(100.5), -1);
    EXPECT_EQ(bins.BinOf(std::nan("")), -1);
    EXPECT_EQ(bins.Label(0), "[1,10)");
    EXPECT_EQ(bins.Label(1), "[10,100]");
    EXPECT_EQ((Bins{{0.5, 1e6}}).Label(0), "[0.5,1e+06]");
}

TEST(PolicyHash, ChangesWithEveryField) {
    const InstancingPolicy base = Minimal();
    std::vector<std::function<void(InstancingPolicy&)>> changes = {
        [](auto& p) { p.species = "poplar"; },
        [](auto& p) { p.instanceTypes.push_back(NodeType::kPhytomer); },
        [](auto& p) {
            p.instanceTypes = {NodeType::kPlant, NodeType::kPhytomer};
        },
        [](auto& p) { p.byType = false; },
        [](auto& p) { p.leafCount.edges.back() = 2000; },
        [](auto& p) { p.leafCount.edges.push_back(5000); },
        [](auto& p) { p.leafCount.edges.clear(); },
        [](auto& p) { p.age.edges[1] = 1.5; },
        [](auto& p) { p.age.edges.clear(); },
        [](auto& p) {
            p.inclination.edges = {0, 90, 180};
        },
        [](auto& p) {
            p.inclination.edges = {0, 60, 180};
        },
        [](auto& p) { p.attributes[0].name = "rank"; },
        [](auto& p) { p.attributes[0].bins.edges[1] = 2; },
        [](auto& p) {
            p.attributes.push_back({"rank", {{0, 1}}});
        },
        [](auto& p) { p.fixed[0].leafCountAbove = 999; },
        [](auto& p) { p.fixed[0].type = NodeType::kPlant; },
        [](auto& p) {
            p.fixed.push_back({NodeType::kPlant, 1000});
        },
        [](auto& p) { p.phase.kind = PhaseKind::kBiDirectional; },
        [](auto& p) { p.phase.level = 2; },
        [](auto& p) { p.transmittance.kind = PhaseKind::kConstant; },
        [](auto& p) { p.transmittance.level = 4; },
    };
    std::set<std::string> hashes{PolicyContentHash(base)};
    for (std::size_t i = 0; i < changes.size(); ++i) {
        InstancingPolicy changed = base;
        changes[i](changed);
        EXPECT_TRUE(hashes.insert(PolicyContentHash(changed)).second) << "change " << i;
    }
    // What does not change the meaning does not change the hash: order of types, caps and
    // attributes, and the level of a constant function.
    InstancingPolicy same = base;
    std::reverse(same.instanceTypes.begin(), same.instanceTypes.end());
    EXPECT_EQ(PolicyContentHash(same), PolicyContentHash(base));
    InstancingPolicy constant = base, constantOtherLevel = base;
    constant.phase.kind = constantOtherLevel.phase.kind = PhaseKind::kConstant;
    constantOtherLevel.phase.level = 1;
    EXPECT_EQ(PolicyContentHash(constant), PolicyContentHash(constantOtherLevel));
}

TEST(PolicyHash, IgnoresLayoutAndComments) {
    const InstancingPolicy shipped = LoadPolicyFile(PolicyPath("default.txtpb"));
    const std::string path = WriteTempFile("relaid_policy.txtpb", R"(
# the default policy again, laid out otherwise
species:"default"   version:PROTOCOL_VERSION_CURRENT
instance_types: NODE_TYPE_AXIS   # one at a time, in another order
instance_types: NODE_TYPE_PLANT
by_type: true
leaf_count {
  edges: 11 edges: 16 edges: 23 edges: 32
  edges: [45, 64, 91, 128, 181, 256, 362, 512, 724, 1000, 1e4]
}
inclination { edges: [0, 30.0, 60, 90, 120, 150, 1.8e2] }
fixed { type: NODE_TYPE_AXIS leaf_count_above: 10000 }
fixed { type: NODE_TYPE_PLANT leaf_count_above: 10000 }
transmittance { direction_count: 130 kind: FUNCTION_KIND_MONO }
phase { level: 3 kind: FUNCTION_KIND_BI }
)");
    EXPECT_EQ(PolicyContentHash(LoadPolicyFile(path)), PolicyContentHash(shipped));
    const std::string changed = WriteTempFile("changed_policy.txtpb", R"(
species: "default" instance_types: [NODE_TYPE_PLANT, NODE_TYPE_AXIS] by_type: true
leaf_count { edges: [11, 16, 23, 32, 45, 64, 91, 128, 181, 256, 362, 512, 724, 1000, 10000] }
fixed { type: NODE_TYPE_PLANT leaf_count_above: 10000 }
fixed { type: NODE_TYPE_AXIS leaf_count_above: 10001 }
phase { kind: FUNCTION_KIND_BI direction_count: 130 }
transmittance { kind: FUNCTION_KIND_MONO direction_count: 130 }
)");
    EXPECT_NE(PolicyContentHash(LoadPolicyFile(changed)), PolicyContentHash(shipped));
}

// Leaf organs below each node, by walking up from every leaf: the slow way, to check the
// one-pass count against.
std::unordered_map<NodeId, std::int64_t> LeavesByWalkingUp(const Scene& scene) {
    std::unordered_map<NodeId, const Node*> byId;
    for (const Node& node : scene.nodes) byId[node.id] = &node;
    std::unordered_map<NodeId, std::int64_t> leaves;
    for (const Node& node : scene.nodes) {
        if (node.type() != NodeType::kLeaf || !node.organ()) continue;
        for (const Node* n = &node; n; n = n->parent ? byId.at(n->parent) : nullptr) {
            ++leaves[n->id];
        }
    }
    return leaves;
}

TEST(SignatureOnGeneratedTree, EveryLeafBearingStructureHasOne) {
    const Scene scene = GeneratedTree(1000);
    const InstancingPolicy policy = LoadPolicyFile(PolicyPath("generated_tree.txtpb"));
    const SceneSignatures signatures = ComputeSignatures(scene, policy);
    const auto leaves = LeavesByWalkingUp(scene);
    std::size_t instantiable = 0;
    for (const Node& node : scene.nodes) {
        const auto found = leaves.find(node.id);
        const StructureSignature* s = signatures.Find(node.id);
        if (!policy.IsInstanceType(node.type()) || found == leaves.end()) {
            EXPECT_EQ(s, nullptr) << scene.NodeName(node);
            continue;
        }
        ++instantiable;
        ASSERT_NE(s, nullptr) << scene.NodeName(node);
        EXPECT_EQ(s->leafCount, found->second) << scene.NodeName(node);
        EXPECT_FALSE(s->signature.empty()) << scene.NodeName(node) << ": " << s->unbinned;
    }
    EXPECT_EQ(signatures.structures.size(), instantiable);
    // 1 plant, its trunk, 10 branches of 100 leaves and their 100 shoots of 10.
    EXPECT_EQ(instantiable, 112u);
    EXPECT_LT(signatures.groups.size(), instantiable / 4) << "hardly any sharing";
}

TEST(SignatureOnGeneratedTree, MembersShareTypeAndBinsAndTheRepresentativeIsOne) {
    const Scene scene = GeneratedTree(2345, 7);
    const InstancingPolicy policy = LoadPolicyFile(PolicyPath("generated_tree.txtpb"));
    const SceneSignatures signatures = ComputeSignatures(scene, policy);
    std::size_t grouped = 0;
    for (const SignatureGroup& group : signatures.groups) {
        SCOPED_TRACE(group.signature);
        ASSERT_FALSE(group.members.empty());
        EXPECT_TRUE(std::is_sorted(group.members.begin(), group.members.end()));
        const StructureSignature& first = *signatures.Find(group.members.front());
        for (const NodeId id : group.members) {
            const StructureSignature& s = *signatures.Find(id);
            EXPECT_EQ(s.signature, group.signature);
            EXPECT_EQ(s.type, first.type);
            EXPECT_EQ(s.leafBin, first.leafBin);
            EXPECT_EQ(s.ageBin, first.ageBin);
            EXPECT_EQ(s.attributeBins, first.attributeBins);
        }
        grouped += group.members.size();
        const auto& m = group.members;
        ASSERT_TRUE(std::binary_search(m.begin(), m.end(), group.representative));
        // Nearest the median leaf count, the smallest id among equals.
        const auto distance = [&](NodeId id) {
            return std::abs(static_cast<double>(signatures.Find(id)->leafCount) -
                            group.medianLeafCount);
        };
        for (const NodeId id : m) {
            EXPECT_GE(distance(id), distance(group.representative));
            if (distance(id) == distance(group.representative)) {
                EXPECT_GE(id, group.representative);
            }
        }
    }
    std::size_t binned = 0;
    for (const auto& s : signatures.structures) binned += !s.signature.empty();
    EXPECT_EQ(grouped, binned);
}

TEST(SignatureOnGeneratedTree, IndependentOfNodeOrder) {
    const Scene scene = GeneratedTree(1500, 11);
    const InstancingPolicy policy = LoadPolicyFile(PolicyPath("default.txtpb"));
    const SceneSignatures ordered = ComputeSignatures(scene, policy);
    Scene shuffled = scene;
    std::mt19937_64 random(42);
    std::shuffle(shuffled.nodes.begin(), shuffled.nodes.end(), random);
    // The one walked without a topology, the other through it.
    ASSERT_TRUE(InWalkOrder(scene));
    ASSERT_FALSE(InWalkOrder(shuffled));
    const SceneSignatures reordered = ComputeSignatures(shuffled, policy);
    ASSERT_EQ(reordered.groups.size(), ordered.groups.size());
    for (std::size_t g = 0; g < ordered.groups.size(); ++g) {
        EXPECT_EQ(reordered.groups[g].signature, ordered.groups[g].signature);
        EXPECT_EQ(reordered.groups[g].members, ordered.groups[g].members);
        EXPECT_EQ(reordered.groups[g].representative, ordered.groups[g].representative);
    }
    ASSERT_EQ(reordered.structures.size(), ordered.structures.size());
    for (std::size_t i = 0; i < ordered.structures.size(); ++i) {
        EXPECT_EQ(reordered.structures[i].id, ordered.structures[i].id);
        EXPECT_EQ(reordered.structures[i].leafCount, ordered.structures[i].leafCount);
        EXPECT_EQ(reordered.structures[i].inclination, ordered.structures[i].inclination);
    }
}

TEST(SignatureOnGeneratedTree, GroupsSpanThePlantsOfAPlantation) {
    Scene scene = OneBandScene({{"leaf", Leaf(0.1, 0.05)}, {"stem", Opaque(0.3)}});
    PlantationParameters plantation;
    plantation.tree.leafCount = 1000;
    plantation.columns = 3;
    AddPlantation(scene, plantation, "");
    scene.Validate();
    const SceneSignatures signatures =
        ComputeSignatures(scene, LoadPolicyFile(PolicyPath("generated_tree.txtpb")));
    std::map<std::string, std::size_t> sizes;
    for (const auto& group : signatures.groups) sizes[group.signature] = group.members.size();
    // Each tree as alone (EveryLeafBearingStructureHasOne), three times over.
    EXPECT_EQ(sizes, (std::map<std::string, std::size_t>{{"plant|leaves[500,1001)|age[0,1)", 3},
                                                         {"axis|leaves[500,1001)|age[0,1)", 3},
                                                         {"axis|leaves[50,101)|age[1,2)", 30},
                                                         {"axis|leaves[5,11)|age[2,3)", 300}}));
}

TEST(SignatureOnGeneratedTree, FixedSignatureBeyondTheSizeCap) {
    const Scene scene = GeneratedTree(1000);
    InstancingPolicy policy = Minimal();
    policy.attributes.clear();  // plants have no `order`
    policy.fixed = {{NodeType::kAxis, 50}};
    const SceneSignatures signatures = ComputeSignatures(scene, policy);
    int large = 0;
    for (const StructureSignature& s : signatures.structures) {
        const bool beyond = s.type == NodeType::kAxis && s.leafCount > 50;
        EXPECT_EQ(s.fixed, beyond) << s.id;
        if (beyond) {
            EXPECT_EQ(s.signature, "axis|large");
            ++large;
        } else {
            EXPECT_NE(s.signature, "axis|large");
        }
        if (s.type == NodeType::kPlant) {
            EXPECT_EQ(s.signature.rfind("plant|leaves[", 0), 0u);
        }
    }
    EXPECT_EQ(large, 11);  // the trunk and its 10 branches of 100 leaves
    const auto group = std::find_if(signatures.groups.begin(), signatures.groups.end(),
                                    [](const auto& g) { return g.signature == "axis|large"; });
    ASSERT_NE(group, signatures.groups.end());
    EXPECT_EQ(group->members.size(), 11u);
}

TEST(SignatureOnGeneratedTree, ReadableSignaturesAndUnbinnedStructures) {
    const Scene scene = GeneratedTree(1000);
    InstancingPolicy policy = Minimal();
    policy.fixed.clear();
    policy.leafCount.edges = {1, 10, 100};  // the 1000-leaf trunk and plant fall outside
    const SceneSignatures signatures = ComputeSignatures(scene, policy);
    std::set<std::string> names;
    for (const auto& group : signatures.groups) names.insert(group.signature);
    EXPECT_EQ(names, (std::set<std::string>{"axis|leaves[10,100]|age[1,2)|order[1,8]",
                                            "axis|leaves[10,100]|age[2,8]|order[1,8]"}));
    int unbinned = 0;
    for (const auto& s : signatures.structures) {
        if (s.signature.empty()) {
            ++unbinned;
            EXPECT_FALSE(s.unbinned.empty());
        }
    }
    EXPECT_EQ(unbinned, 2);  // the plant and its trunk
}

// The inclination is each structure's frame's z against the world's up, its frames
// composed from the root: the same for the tree turned about the vertical, 180° less
// itself for the tree upside down.
TEST(SignatureOnGeneratedTree, InclinationIsEachStructuresAngleFromTheWorldsUp) {
    const Scene scene = GeneratedTree(1000);
    InstancingPolicy policy = Minimal();
    policy.inclination.edges = {0, 30, 60, 90, 120, 150, 180};
    const SceneSignatures base = ComputeSignatures(scene, policy);
    const auto turned = [&](const glm::dmat4& motion) {
        Scene moved = scene;
        for (Node& node : moved.nodes) {
            if (node.parent == kNoParent)
                node.Edit().parentFromLocal = motion * glm::dmat4(node.parentFromLocal());
        }
        return ComputeSignatures(moved, policy);
    };
    const SceneSignatures about = turned(glm::rotate(glm::dmat4(1.0), 1.1, {0.0, 0.0, 1.0}));
    const SceneSignatures over =
        turned(glm::rotate(glm::dmat4(1.0), std::numbers::pi, {1.0, 0.0, 0.0}));
    std::set<int> bins;
    ASSERT_EQ(about.structures.size(), base.structures.size());
    for (std::size_t i = 0; i < base.structures.size(); ++i) {
        const StructureSignature& s = base.structures[i];
        EXPECT_NEAR(about.structures[i].inclination, s.inclination, 1e-4);
        EXPECT_EQ(about.structures[i].signature, s.signature);
        EXPECT_NEAR(over.structures[i].inclination, 180.0 - s.inclination, 1e-4);
        bins.insert(s.inclinationBin);
    }
    EXPECT_NEAR(base.structures.front().inclination, 0.0, 1e-6);  // the plant stands upright
    EXPECT_GE(bins.size(), 3u) << "its branches and shoots lean every way";
}

}  // namespace
}  // namespace leaflux
