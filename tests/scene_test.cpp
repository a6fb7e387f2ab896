// Scene validation: every invalid input is rejected with a typed error naming the field
// or node, before anything reaches the ray engine.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>

#include "solver/generate/generator.h"
#include "solver/scene/geometry.h"
#include "solver/scene/scene_store.h"
#include "solver/scene/subtrees.h"
#include "solver/scene/world_frames.h"
#include "solver/util/error.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

Scene ValidScene() {
    Scene scene = OneBandScene({{"leaf", Leaf(0.1, 0.05)}, {"soil", Opaque(0.2)}});
    Node plant;
    plant.id = 1;
    plant.Edit().type = NodeType::kPlant;
    scene.nodes.push_back(plant);
    scene.nodes.push_back(OrganNode(2, "leaf2", Rectangle(0.1, 0.05, 1.0), "leaf", 1));
    scene.environment.push_back({"ground", Rectangle(4, 4, 0), "soil"});
    scene.sources.suns.push_back(SunAt(45, 180, 1000));
    return scene;
}

struct BadInput {
    const char* what;
    std::function<void(Scene&)> spoil;
    ErrorCode code;
    std::string field;  // expected substring of the field path
    std::optional<NodeId> node;
};

std::shared_ptr<const Mesh> MeshWith(std::vector<glm::dvec3> positions,
                                     std::vector<glm::uvec3> triangles) {
    auto mesh = std::make_shared<Mesh>();
    mesh->positions = std::move(positions);
    mesh->triangles = std::move(triangles);
    return mesh;
}

const double kNan = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

std::vector<BadInput> BadInputs() {
    return {
        {"no band", [](Scene& s) { s.bands.clear(); }, ErrorCode::kInvalidArgument, "bands", {}},
        {"duplicate band",
         [](Scene& s) { s.bands.push_back({"PAR"}); },
         ErrorCode::kAlreadyExists,
         "bands[PAR]",
         {}},
        {"too many bands",
         [](Scene& s) {
             for (int i = 0; i < kMaxBands; ++i) s.bands.push_back({"b" + std::to_string(i)});
         },
         ErrorCode::kInvalidArgument,
         "bands",
         {}},
        {"rho + tau > 1",
         [](Scene& s) {
             s.optics[0].bands[0] = {0.6, 0.1, 0.5, 0.0};
         },
         ErrorCode::kInvalidArgument,
         "optics[leaf].bands[PAR]",
         {}},
        {"lower rho + tau > 1",
         [](Scene& s) {
             s.optics[0].bands[0] = {0.1, 0.7, 0.0, 0.4};
         },
         ErrorCode::kInvalidArgument,
         "optics[leaf].bands[PAR]",
         {}},
        {"negative rho",
         [](Scene& s) { s.optics[0].bands[0].rhoUpper = -0.1; },
         ErrorCode::kInvalidArgument,
         "optics[leaf].bands[PAR].rho_upper",
         {}},
        {"NaN tau",
         [](Scene& s) { s.optics[0].bands[0].tauLowerToUpper = kNan; },
         ErrorCode::kInvalidArgument,
         "optics[leaf].bands[PAR].tau_lower",
         {}},
        {"optics missing a band",
         [](Scene& s) { s.optics[0].bands.clear(); },
         ErrorCode::kNotFound,
         "optics[leaf].bands",
         {}},
        {"too many optics",
         [](Scene& s) {
             for (int i = 0; i < kMaxOptics; ++i) {
                 s.optics.push_back(s.optics[0]);
                 s.optics.back().id = "o" + std::to_string(i);
             }
         },
         ErrorCode::kInvalidArgument,
         "optics",
         {}},
        {"duplicate optics",
         [](Scene& s) { s.optics.push_back(s.optics[0]); },
         ErrorCode::kAlreadyExists,
         "optics[leaf]",
         {}},
        {"unknown optics", [](Scene& s) { s.nodes[1].Edit().organ->opticsId = "bark"; },
         ErrorCode::kNotFound, "organ.optics", 2},
        {"unknown parent", [](Scene& s) { s.nodes[1].parent = 99; }, ErrorCode::kNotFound, "parent",
         2},
        {"duplicate id", [](Scene& s) { s.nodes[1].id = 1; }, ErrorCode::kAlreadyExists, "nodes.id",
         1},
        {"zero id",
         [](Scene& s) { s.nodes[0].id = 0; },
         ErrorCode::kInvalidArgument,
         "nodes.id",
         {}},
        {"cycle", [](Scene& s) { s.nodes[0].parent = 2; }, ErrorCode::kCycle, "parent", {}},
        {"self parent", [](Scene& s) { s.nodes[0].parent = 1; }, ErrorCode::kCycle, "parent", 1},
        {"NaN frame",
         [](Scene& s) {
             s.nodes[0].Edit().parentFromLocal =
                 glm::translate(glm::dmat4(1.0), glm::dvec3(kNan, 0, 0));
         },
         ErrorCode::kInvalidArgument, "frame", 1},
        {"singular frame",
         [](Scene& s) {
             s.nodes[0].Edit().parentFromLocal = glm::scale(glm::dmat4(1.0), {1, 1, 0});
         },
         ErrorCode::kDegenerate, "frame", 1},
        {"infinite age", [](Scene& s) { s.nodes[0].Edit().age = kInf; },
         ErrorCode::kInvalidArgument, "age", 1},
        {"NaN attribute", [](Scene& s) { s.nodes[0].Edit().attributes["vigour"] = kNan; },
         ErrorCode::kInvalidArgument, "attributes[vigour]", 1},
        {"NaN vertex",
         [](Scene& s) {
             s.nodes[1].Edit().organ->mesh =
                 MeshWith({{0, 0, 0}, {1, 0, kNan}, {0, 1, 0}}, {{0, 1, 2}});
         },
         ErrorCode::kInvalidArgument, "organ.mesh.positions[1]", 2},
        {"collapsed triangle",
         [](Scene& s) {
             s.nodes[1].Edit().organ->mesh =
                 MeshWith({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {{0, 1, 2}});
         },
         ErrorCode::kDegenerate, "organ.mesh.triangles[0]", 2},
        {"repeated vertex",
         [](Scene& s) {
             s.nodes[1].Edit().organ->mesh = MeshWith({{0, 0, 0}, {1, 0, 0}}, {{0, 1, 1}});
         },
         ErrorCode::kDegenerate, "organ.mesh.triangles[0]", 2},
        {"index out of range",
         [](Scene& s) {
             s.nodes[1].Edit().organ->mesh =
                 MeshWith({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 3}});
         },
         ErrorCode::kInvalidArgument, "organ.mesh.triangles[0]", 2},
        {"empty mesh", [](Scene& s) { s.nodes[1].Edit().organ->mesh = MeshWith({}, {}); },
         ErrorCode::kDegenerate, "organ.mesh.triangles", 2},
        {"frame collapses a leaf",
         [](Scene& s) {
             glm::dmat4 frame(1.0);
             frame[1] = glm::dvec4(1e-40, 0, 0, 0);
             s.nodes[0].Edit().parentFromLocal = frame;
         },
         ErrorCode::kDegenerate, "frame", 1},
        {"duplicate organ name",
         [](Scene& s) { s.nodes.push_back(OrganNode(3, "leaf2", Rectangle(1, 1, 2), "leaf")); },
         ErrorCode::kAlreadyExists, "name", 3},
        {"environment unknown optics",
         [](Scene& s) { s.environment[0].opticsId = "mud"; },
         ErrorCode::kNotFound,
         "environment[ground].optics",
         {}},
        {"environment without name",
         [](Scene& s) { s.environment[0].name = ""; },
         ErrorCode::kInvalidArgument,
         "environment[0].name",
         {}},
        {"sun not unit",
         [](Scene& s) {
             s.sources.suns[0].towardSun = {0, 0, 2};
         },
         ErrorCode::kInvalidArgument,
         "suns[0].direction",
         {}},
        {"sun NaN irradiance",
         [](Scene& s) { s.sources.suns[0].normalIrradianceWm2 = {kNan}; },
         ErrorCode::kInvalidArgument,
         "suns[0].normal_irradiance[PAR]",
         {}},
        // A leaf scaled far past the world's range is refused for its coordinates, whatever
        // the scale: never lit with overflowing areas.
        {"leaf scaled by 1e15",
         [](Scene& s) {
             s.nodes[1].Edit().parentFromLocal = glm::scale(glm::dmat4(1.0), glm::dvec3(1e15));
         },
         ErrorCode::kInvalidArgument, "organ.mesh.triangles[0]", 2},
        {"leaf scaled by 1e20",
         [](Scene& s) {
             s.nodes[1].Edit().parentFromLocal = glm::scale(glm::dmat4(1.0), glm::dvec3(1e20));
         },
         ErrorCode::kInvalidArgument, "organ.mesh.triangles[0]", 2},
        // Past single precision's range (3.4e38), where a frame keeps its scale, the frame
        // itself is refused as not finite.
        {"leaf scaled by 1e300",
         [](Scene& s) {
             s.nodes[1].Edit().parentFromLocal = glm::scale(glm::dmat4(1.0), glm::dvec3(1e300));
         },
         ErrorCode::kInvalidArgument, "frame", 2},
        {"sun of 1e308 W/m²",
         [](Scene& s) { s.sources.suns[0].normalIrradianceWm2 = {1e308}; },
         ErrorCode::kInvalidArgument,
         "suns[0].normal_irradiance[PAR]",
         {}},
        {"sun negative irradiance",
         [](Scene& s) { s.sources.suns[0].normalIrradianceWm2 = {-5}; },
         ErrorCode::kInvalidArgument,
         "suns[0].normal_irradiance[PAR]",
         {}},
        {"sun missing band",
         [](Scene& s) { s.sources.suns[0].normalIrradianceWm2 = {}; },
         ErrorCode::kInvalidArgument,
         "suns[0].normal_irradiance",
         {}},
        {"huge sun disc",
         [](Scene& s) { s.sources.suns[0].angularRadiusRad = 1.0; },
         ErrorCode::kInvalidArgument,
         "suns[0].angular_radius_deg",
         {}},
        {"sky negative",
         [](Scene& s) {
             s.sources.skies.push_back({SkyModel::kUniform, {-1.0}});
         },
         ErrorCode::kInvalidArgument,
         "sky.horizontal_irradiance[PAR]",
         {}},
        {"lamp unknown optics",
         [](Scene& s) {
             s.sources.emitters.push_back({"lamp", Rectangle(1, 1, 3, true), {10}, "glass"});
         },
         ErrorCode::kNotFound,
         "emitters[lamp].optics",
         {}},
        {"lamp NaN exitance",
         [](Scene& s) {
             s.sources.emitters.push_back({"lamp", Rectangle(1, 1, 3, true), {kNan}, ""});
         },
         ErrorCode::kInvalidArgument,
         "emitters[lamp].exitance[PAR]",
         {}},
        {"lamp named like an organ",
         [](Scene& s) {
             s.sources.emitters.push_back({"leaf2", Rectangle(1, 1, 3, true), {1}, ""});
         },
         ErrorCode::kAlreadyExists,
         "emitters[leaf2].name",
         {}},
        {"empty periodic domain",
         [](Scene& s) {
             s.periodic = PeriodicDomain{0, 0, 0, 1};
         },
         ErrorCode::kInvalidArgument,
         "periodic",
         {}},
    };
}

class RejectsBadInput : public ::testing::TestWithParam<int> {};

TEST_P(RejectsBadInput, WithTypedErrorNamingTheField) {
    const BadInput bad = BadInputs()[GetParam()];
    SCOPED_TRACE(bad.what);
    Scene scene = ValidScene();
    ASSERT_NO_THROW(scene.Validate());
    bad.spoil(scene);
    try {
        scene.Validate();
        FAIL() << "accepted: " << bad.what;
    } catch (const InputError& e) {
        EXPECT_EQ(e.Code(), bad.code) << e.what();
        EXPECT_NE(e.Field().find(bad.field), std::string::npos) << e.what();
        if (bad.node) {
            EXPECT_EQ(e.Node(), bad.node) << e.what();
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Scene, RejectsBadInput,
                         ::testing::Range(0, static_cast<int>(BadInputs().size())));

// A frame keeps its translation in double and its rotation and scale in single precision:
// a plant 100 km out keeps its place to the nanometre, its orientation within 1e-7.
TEST(Frame, KeepsTheTranslationExactAndTheRotationInSinglePrecision) {
    glm::dmat4 m = glm::rotate(glm::dmat4(1.0), 0.3, glm::normalize(glm::dvec3(1, 2, 3)));
    m[3] = glm::dvec4(1e5 + 1e-9, -2e5, 3.25e-7, 1.0);
    const Frame frame = m;
    const glm::dmat4 back = frame;
    EXPECT_EQ(back[3], m[3]);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(back[c][3], 0.0);
        for (int r = 0; r < 3; ++r) {
            EXPECT_NEAR(back[c][r], m[c][r], 1e-7) << c << ' ' << r;
            EXPECT_EQ(frame.At(c, r), back[c][r]);
        }
    }
    EXPECT_EQ(Frame(), Frame(glm::dmat4(1.0)));
    EXPECT_EQ(glm::dmat4(Frame()), glm::dmat4(1.0));
}

TEST(Scene, NamesTheFirstFailingOrganInTheNodesOrder) {
    // The organs' meshes are checked where they are placed, walking down from the roots, and
    // their names apart: of several failing, the error names the first in the nodes' order,
    // whichever the walk meets first. Leaf 3 comes first but hangs from plant 1, a root the
    // walk takes after leaf 4, a root before it.
    const std::shared_ptr<const Mesh> flat =
        MeshWith({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {{0, 1, 2}});  // no area
    const auto errorOf = [](const Scene& scene) -> std::pair<ErrorCode, std::optional<NodeId>> {
        try {
            scene.Validate();
        } catch (const InputError& e) {
            return {e.Code(), e.Node()};
        }
        ADD_FAILURE() << "no error";
        return {};
    };
    Scene scene = ValidScene();
    scene.nodes.erase(scene.nodes.begin() + 1);  // the plant alone
    scene.nodes.insert(scene.nodes.begin(), OrganNode(4, "leaf4", flat, "leaf"));
    scene.nodes.insert(scene.nodes.begin(), OrganNode(3, "leaf3", flat, "leaf", 1));
    EXPECT_EQ(errorOf(scene), std::pair(ErrorCode::kDegenerate, std::optional<NodeId>(3)));
    // Leaf 3 whole again and leaf 5 named as leaf 4: leaf 4's mesh comes before the name.
    scene.nodes[0].Edit().organ->mesh = Rectangle(0.1, 0.05, 1.0);
    scene.nodes.push_back(OrganNode(5, "leaf4", Rectangle(0.1, 0.05, 2.0), "leaf"));
    EXPECT_EQ(errorOf(scene), std::pair(ErrorCode::kDegenerate, std::optional<NodeId>(4)));
    // Leaf 4 whole: the name.
    scene.nodes[1].Edit().organ->mesh = Rectangle(0.1, 0.05, 3.0);
    EXPECT_EQ(errorOf(scene), std::pair(ErrorCode::kAlreadyExists, std::optional<NodeId>(5)));
    scene.nodes[3].Edit().name = "leaf5";
    EXPECT_NO_THROW(scene.Validate());
}

TEST(Scene, WorldFromLocalComposesParentsFirst) {
    Scene scene = ValidScene();
    scene.nodes[0].Edit().parentFromLocal =
        glm::translate(glm::dmat4(1.0), glm::dvec3(10, 0, 0));  // plant at x = 10
    glm::dmat4 leaf(2.0);                                       // leaf scaled ×2
    leaf[3] = glm::dvec4(0, 1, 0, 1);
    scene.nodes[1].Edit().parentFromLocal = leaf;
    const auto world = WorldFromLocal(scene);
    const glm::dvec3 p = glm::dvec3(world.at(2) * glm::dvec4(1, 0, 0, 1));
    EXPECT_EQ(p, glm::dvec3(12, 1, 0));
}

TEST(Flatten, KeepsMillimetresFarFromTheOrigin) {
    Scene scene = ValidScene();
    scene.nodes[0].Edit().parentFromLocal =
        glm::translate(glm::dmat4(1.0), glm::dvec3(1e5, 1e5, 0));
    scene.environment.clear();
    scene.nodes[1].Edit().organ->mesh = Rectangle(0.001, 0.001, 1.0);
    const FlatScene flat = Flatten(scene);
    ASSERT_EQ(flat.receivers.size(), 1u);
    // World coordinates near 1e5 m carry double rounding of ~1e-11 m: the area is exact
    // to that times the 1 mm edge.
    EXPECT_NEAR(flat.receivers[0].areaM2, 1e-6, 1e-13);
    // Local coordinates are centred: float precision is that of a 1 mm object.
    EXPECT_LT(glm::length(flat.triangles[0].a), 0.01);
    EXPECT_NEAR(flat.origin.x, 1e5, 1e-6);
}

// A 200-leaf generated tree (leaves on phytomers that carry no mesh) over a ground.
Scene GrownTree() {
    Scene scene = OneBandScene({{"leaf", Leaf(0.1, 0.05)}, {"stem", Opaque(0.3)}});
    TreeParameters tree;
    tree.leafCount = 200;
    tree.seed = 5;
    AddTree(scene, tree, {0, 0, 0});
    scene.environment.push_back({"ground", Rectangle(4, 4, 0), "stem"});
    scene.sources.suns.push_back(SunAt(45, 180, 1000));
    return scene;
}

const Node& FindNode(const Scene& scene, std::function<bool(const Node&)> which) {
    const auto it = std::find_if(scene.nodes.begin(), scene.nodes.end(), which);
    if (it == scene.nodes.end()) throw std::logic_error("no such node in the test scene");
    return *it;
}

void ExpectSameFlat(const FlatScene& kept, const FlatScene& fresh) {
    EXPECT_EQ(kept.origin, fresh.origin);
    EXPECT_EQ(kept.boundsMin, fresh.boundsMin);
    EXPECT_EQ(kept.boundsMax, fresh.boundsMax);
    ASSERT_EQ(kept.receivers.size(), fresh.receivers.size());
    for (std::size_t r = 0; r < kept.receivers.size(); ++r) {
        EXPECT_EQ(kept.receivers[r].kind, fresh.receivers[r].kind);
        EXPECT_EQ(kept.receivers[r].declared, fresh.receivers[r].declared);
        EXPECT_EQ(kept.receivers[r].node, fresh.receivers[r].node);
        EXPECT_EQ(kept.receivers[r].areaM2, fresh.receivers[r].areaM2);
        EXPECT_EQ(kept.receivers[r].firstTriangle, fresh.receivers[r].firstTriangle);
    }
    ASSERT_EQ(kept.triangles.size(), fresh.triangles.size());
    for (std::size_t t = 0; t < kept.triangles.size(); ++t) {
        const Triangle &a = kept.triangles[t], &b = fresh.triangles[t];
        ASSERT_TRUE(a.a == b.a && a.b == b.b && a.c == b.c && a.normal == b.normal &&
                    a.areaM2 == b.areaM2 && a.receiver == b.receiver)
            << "triangle " << t;
    }
}

// Cycle after cycle — a branch cut, a phytomer bent (moving the leaves above it), a leaf
// given a new blade, leaves added, a new sun — the kept triangles flatten to what the
// whole scene flattens to, bit for bit.
TEST(SceneStore, FlattensAsTheWholeSceneAfterEachChange) {
    const Scene start = GrownTree();
    SceneStore store(start);
    ExpectSameFlat(store.Flat(), Flatten(store.Get()));
    const auto isAxis = [](const Node& n) {
        return n.type() == NodeType::kAxis && n.attributes().at("order") == 1.0;  // a branch
    };
    const auto isPhytomer = [](const Node& n) { return n.type() == NodeType::kPhytomer; };
    const auto isLeaf = [](const Node& n) { return n.type() == NodeType::kLeaf; };

    SceneChange cut;
    cut.removed.push_back(FindNode(store.Get(), isAxis).id);
    store.Apply(cut);
    EXPECT_LT(store.Get().nodes.size(), start.nodes.size());
    ExpectSameFlat(store.Flat(), Flatten(store.Get()));

    SceneChange bend;
    Node phytomer = FindNode(store.Get(), isPhytomer);
    phytomer.Edit().parentFromLocal =
        glm::rotate(glm::dmat4(phytomer.parentFromLocal()), 0.3, glm::dvec3(1, 0, 0));
    bend.updated.push_back(phytomer);
    Node leaf = FindNode(store.Get(), isLeaf);
    leaf.Edit().organ->mesh = Rectangle(0.2, 0.1, 0.0);
    bend.updated.push_back(leaf);
    store.Apply(bend);
    ExpectSameFlat(store.Flat(), Flatten(store.Get()));

    SceneChange grow;
    NodeId next = 0;
    for (const Node& n : store.Get().nodes) next = std::max(next, n.id);
    for (int k = 1; k <= 5; ++k) {
        grow.added.push_back(OrganNode(next + k, "new" + std::to_string(k),
                                       Rectangle(0.05, 0.03, 0.1 * k), "leaf", phytomer.id));
    }
    grow.suns = std::vector<Sun>{SunAt(30, 90, 800)};
    store.Apply(grow);
    ExpectSameFlat(store.Flat(), Flatten(store.Get()));
    EXPECT_EQ(store.Get().sources.suns.at(0).normalIrradianceWm2, std::vector<double>{800.0});
}

// An organ the change leaves alone is still checked where the change moved it: shrinking
// the phytomer under a leaf a billion times makes the leaf, not the phytomer, degenerate.
// The store is then as it was.
TEST(SceneStore, ChecksTheOrgansAChangeMoves) {
    SceneStore store(GrownTree());
    const Node& leaf =
        FindNode(store.Get(), [](const Node& n) { return n.type() == NodeType::kLeaf; });
    Node phytomer = FindNode(store.Get(), [&](const Node& n) { return n.id == leaf.parent; });
    ASSERT_FALSE(phytomer.organ().has_value());
    phytomer.Edit().parentFromLocal =
        glm::scale(glm::dmat4(phytomer.parentFromLocal()), glm::dvec3(1e-9));
    SceneChange shrink;
    shrink.updated.push_back(phytomer);
    try {
        store.Apply(shrink);
        ADD_FAILURE() << "the shrunk leaf was not checked";
    } catch (const InputError& e) {
        EXPECT_EQ(e.Code(), ErrorCode::kDegenerate);
        EXPECT_EQ(e.Node(), std::optional<std::uint64_t>(leaf.id));
    }
    ExpectSameFlat(store.Flat(), Flatten(GrownTree()));
}

// What whole validation finds in the scene a change makes, the store finds in the change:
// a parent that does not exist or was removed, a loop, a name taken, an id used twice.
TEST(SceneStore, RejectsWhatWholeValidationRejects) {
    const Scene start = GrownTree();
    SceneStore store(start);
    const Node& leaf = FindNode(start, [](const Node& n) { return n.type() == NodeType::kLeaf; });
    const Node& axis = FindNode(start, [](const Node& n) { return n.type() == NodeType::kAxis; });
    const Node& branch = FindNode(
        start, [&](const Node& n) { return n.type() == NodeType::kAxis && n.id != axis.id; });
    const auto expect = [&](SceneChange change, ErrorCode code, NodeId node) {
        Scene whole = start;  // the same change, made to a copy and validated whole
        std::erase_if(whole.nodes, [&](const Node& n) {
            return std::count(change.removed.begin(), change.removed.end(), n.id) > 0;
        });
        for (const Node& u : change.updated) {
            for (Node& n : whole.nodes) {
                if (n.id == u.id) n = u;
            }
        }
        whole.nodes.insert(whole.nodes.end(), change.added.begin(), change.added.end());
        EXPECT_THROW(whole.Validate(), InputError);
        try {
            store.Apply(change);
            ADD_FAILURE() << "accepted";
        } catch (const InputError& e) {
            EXPECT_EQ(e.Code(), code) << e.what();
            EXPECT_EQ(e.Node(), std::optional<std::uint64_t>(node)) << e.what();
        }
        ExpectSameFlat(store.Flat(), Flatten(start));
    };
    SceneChange orphan;
    orphan.added.push_back(OrganNode(9001, "orphan", Rectangle(0.1, 0.1, 1), "leaf", 8999));
    expect(orphan, ErrorCode::kNotFound, 9001);
    SceneChange loop;  // the trunk under one of its own branches
    Node trunk = axis;
    trunk.parent = branch.id;
    loop.updated.push_back(trunk);
    expect(loop, ErrorCode::kCycle, axis.id);
    SceneChange taken;
    taken.added.push_back(
        OrganNode(9001, start.NodeName(leaf), Rectangle(0.1, 0.1, 1), "leaf", leaf.parent));
    expect(taken, ErrorCode::kAlreadyExists, 9001);
    SceneChange twice;
    twice.added.push_back(OrganNode(9001, "a", Rectangle(0.1, 0.1, 1), "leaf", leaf.parent));
    twice.added.push_back(OrganNode(9001, "b", Rectangle(0.1, 0.1, 1), "leaf", leaf.parent));
    expect(twice, ErrorCode::kAlreadyExists, 9001);
}

// Undo takes a change back whole: nodes, their order, the suns and the placed triangles.
// A change that removes a node and updates one placed after it: the updated organ keeps its
// name, which no other may take afterwards, and the names the removed one gave up are free.
TEST(SceneStore, KeepsTheNamesOfOrgansUpdatedWhereNodesAreRemoved) {
    Scene start = OneBandScene({{"leaf", Leaf(0.1, 0.05)}});
    for (NodeId id = 1; id <= 4; ++id) {
        start.nodes.push_back(OrganNode(id, "leaf" + std::to_string(id),
                                        Rectangle(0.1, 0.1, 0.2 * static_cast<double>(id)),
                                        "leaf"));
    }
    SceneStore store(start);
    SceneChange change;
    change.removed.push_back(1);
    Node moved = start.nodes[2];  // leaf3, raised
    moved.Edit().organ->mesh = Rectangle(0.1, 0.1, 2.0);
    change.updated.push_back(moved);
    store.Apply(change);
    SceneChange taken;
    taken.added.push_back(OrganNode(5, "leaf3", Rectangle(0.1, 0.1, 3.0), "leaf"));
    try {
        store.Apply(taken);
        ADD_FAILURE() << "a second organ named leaf3 was accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.Code(), ErrorCode::kAlreadyExists) << e.what();
        EXPECT_EQ(e.Node(), std::optional<std::uint64_t>(5)) << e.what();
    }
    SceneChange free;
    free.added.push_back(OrganNode(5, "leaf1", Rectangle(0.1, 0.1, 3.0), "leaf"));
    EXPECT_NO_THROW(store.Apply(free));
}

TEST(SceneStore, UndoRestoresTheSceneBefore) {
    const Scene start = GrownTree();
    SceneStore store(start);
    const auto nth = [&](NodeType type, int k) {
        std::vector<const Node*> found;
        for (const Node& n : store.Get().nodes) {
            if (n.type() == type) found.push_back(&n);
        }
        return *found.at(k);
    };
    SceneChange change;
    change.removed.push_back(nth(NodeType::kAxis, 3).id);
    Node bent = nth(NodeType::kPhytomer, 1);
    bent.Edit().parentFromLocal =
        glm::rotate(glm::dmat4(bent.parentFromLocal()), 0.2, glm::dvec3(0, 1, 0));
    change.updated.push_back(bent);
    Node renamed = nth(NodeType::kLeaf, 0);
    renamed.Edit().name = "renamed";
    change.updated.push_back(renamed);
    change.added.push_back(OrganNode(9001, "new", Rectangle(0.1, 0.1, 1), "leaf", bent.id));
    change.suns = std::vector<Sun>{SunAt(20, 0, 300)};
    store.Apply(change);
    ASSERT_NE(store.Get().nodes.size(), start.nodes.size());
    store.Undo();
    ASSERT_EQ(store.Get().nodes.size(), start.nodes.size());
    for (std::size_t i = 0; i < start.nodes.size(); ++i) {
        EXPECT_EQ(store.Get().nodes[i].id, start.nodes[i].id);
        EXPECT_EQ(store.Get().nodes[i].name(), start.nodes[i].name());
        EXPECT_EQ(store.Get().nodes[i].parentFromLocal(), start.nodes[i].parentFromLocal());
    }
    EXPECT_EQ(store.Get().sources.suns.at(0).towardSun, start.sources.suns.at(0).towardSun);
    ExpectSameFlat(store.Flat(), Flatten(start));
    // And the store goes on from there as if the change had never come.
    store.Apply(change);
    Scene whole = store.Get();
    ExpectSameFlat(store.Flat(), Flatten(whole));
}

// NodesUnder: a root's whole subtree, however deep and in whatever order the nodes are
// listed, and nothing of its siblings or parent.
TEST(NodesUnder, TakesEachRootsWholeSubtreeAndNothingElse) {
    Scene scene;
    const auto add = [&](NodeId id, NodeId parent) {
        Node node;
        node.id = id;
        node.parent = parent;
        scene.nodes.push_back(node);
    };
    add(5, 2);  // listed before its parent
    add(1, kNoParent);
    add(2, 1);
    add(3, 1);
    add(4, 3);
    add(6, 5);
    add(7, kNoParent);
    add(8, 7);
    EXPECT_EQ(NodesUnder(scene, {2}), (std::unordered_set<NodeId>{2, 5, 6}));
    EXPECT_EQ(NodesUnder(scene, {3, 7}), (std::unordered_set<NodeId>{3, 4, 7, 8}));
    EXPECT_EQ(NodesUnder(scene, {1}), (std::unordered_set<NodeId>{1, 2, 3, 4, 5, 6}));
    EXPECT_EQ(NodesUnder(scene, {}), std::unordered_set<NodeId>{});
}

}  // namespace
}  // namespace leaflux
