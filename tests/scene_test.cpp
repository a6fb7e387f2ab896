// Scene validation: every invalid input is rejected with a typed error naming the field
// or node, before anything reaches the ray engine.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "solver/error.h"
#include "solver/geometry.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

Scene ValidScene() {
    Scene scene = OneBandScene({{"leaf", Leaf(0.1, 0.05)}, {"soil", Opaque(0.2)}});
    Node plant;
    plant.id = 1;
    plant.type = NodeType::kPlant;
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
             for (int i = 0; i < 9; ++i) s.bands.push_back({"b" + std::to_string(i)});
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
        {"duplicate optics",
         [](Scene& s) { s.optics.push_back(s.optics[0]); },
         ErrorCode::kAlreadyExists,
         "optics[leaf]",
         {}},
        {"unknown optics", [](Scene& s) { s.nodes[1].organ->opticsId = "bark"; },
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
        {"NaN frame", [](Scene& s) { s.nodes[0].parentFromLocal[3][0] = kNan; },
         ErrorCode::kInvalidArgument, "frame", 1},
        {"singular frame", [](Scene& s) { s.nodes[0].parentFromLocal[2] = glm::dvec4(0.0); },
         ErrorCode::kDegenerate, "frame", 1},
        {"infinite age", [](Scene& s) { s.nodes[0].age = kInf; }, ErrorCode::kInvalidArgument,
         "age", 1},
        {"NaN attribute", [](Scene& s) { s.nodes[0].attributes["vigour"] = kNan; },
         ErrorCode::kInvalidArgument, "attributes[vigour]", 1},
        {"NaN vertex",
         [](Scene& s) {
             s.nodes[1].organ->mesh = MeshWith({{0, 0, 0}, {1, 0, kNan}, {0, 1, 0}}, {{0, 1, 2}});
         },
         ErrorCode::kInvalidArgument, "organ.mesh.positions[1]", 2},
        {"collapsed triangle",
         [](Scene& s) {
             s.nodes[1].organ->mesh = MeshWith({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {{0, 1, 2}});
         },
         ErrorCode::kDegenerate, "organ.mesh.triangles[0]", 2},
        {"repeated vertex",
         [](Scene& s) {
             s.nodes[1].organ->mesh = MeshWith({{0, 0, 0}, {1, 0, 0}}, {{0, 1, 1}});
         },
         ErrorCode::kDegenerate, "organ.mesh.triangles[0]", 2},
        {"index out of range",
         [](Scene& s) {
             s.nodes[1].organ->mesh = MeshWith({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 3}});
         },
         ErrorCode::kInvalidArgument, "organ.mesh.triangles[0]", 2},
        {"empty mesh", [](Scene& s) { s.nodes[1].organ->mesh = MeshWith({}, {}); },
         ErrorCode::kDegenerate, "organ.mesh.triangles", 2},
        {"frame collapses a leaf",
         [](Scene& s) {
             s.nodes[0].parentFromLocal = glm::dmat4(1.0);
             s.nodes[0].parentFromLocal[1] = glm::dvec4(1e-40, 0, 0, 0);
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

TEST(Scene, WorldFromLocalComposesParentsFirst) {
    Scene scene = ValidScene();
    scene.nodes[0].parentFromLocal = glm::dmat4(1.0);
    scene.nodes[0].parentFromLocal[3] = glm::dvec4(10, 0, 0, 1);  // plant at x = 10
    scene.nodes[1].parentFromLocal = glm::dmat4(2.0);             // leaf scaled ×2
    scene.nodes[1].parentFromLocal[3] = glm::dvec4(0, 1, 0, 1);
    const auto world = WorldFromLocal(scene);
    const glm::dvec3 p = glm::dvec3(world.at(2) * glm::dvec4(1, 0, 0, 1));
    EXPECT_EQ(p, glm::dvec3(12, 1, 0));
}

TEST(Flatten, KeepsMillimetresFarFromTheOrigin) {
    Scene scene = ValidScene();
    scene.nodes[0].parentFromLocal[3] = glm::dvec4(1e5, 1e5, 0, 1);
    scene.environment.clear();
    scene.nodes[1].organ->mesh = Rectangle(0.001, 0.001, 1.0);
    const FlatScene flat = Flatten(scene);
    ASSERT_EQ(flat.receivers.size(), 1u);
    // World coordinates near 1e5 m carry double rounding of ~1e-11 m: the area is exact
    // to that times the 1 mm edge.
    EXPECT_NEAR(flat.receivers[0].areaM2, 1e-6, 1e-13);
    // Local coordinates are centred: float precision is that of a 1 mm object.
    EXPECT_LT(glm::length(flat.triangles[0].a), 0.01);
    EXPECT_NEAR(flat.origin.x, 1e5, 1e-6);
}

}  // namespace
}  // namespace leaflux
