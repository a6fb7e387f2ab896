// Plants found as exact copies of one another (FindCopies), and a ray engine holding them as
// instances of their originals (SceneRays), against the flat scene's engine.
#include "solver/scene/copies.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "server/policy_proto.h"
#include "solver/generate/generator.h"
#include "solver/instancing/instanced.h"
#include "solver/raytrace/raytrace.h"
#include "solver/scene/world_frames.h"
#include "solver/util/sampling.h"
#include "tests/random_rays.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {
using namespace leaflux::testing;

// Six trees of 60 leaves in two rows, copies of two prototypes each turned about z, on a
// ground: trees 2 and 4 copy tree 0, trees 3 and 5 tree 1.
Scene CopiedTrees() {
    Scene scene = OneBandScene({{"leaf", Leaf(0.1, 0.05)}, {"stem", Opaque(0.2)}});
    PlantationParameters p;
    p.tree.leafCount = 60;
    p.tree.leafOptics = "leaf";
    p.tree.stemOptics = "stem";
    p.tree.copies = true;
    p.rows = 2;
    p.columns = 3;
    p.prototypes = 2;
    AddPlantation(scene, p, "stem");
    scene.Validate();
    return scene;
}

TEST(Copies, ThePlantsThatRepeatAreFoundMovedAndNoOthers) {
    Scene scene = CopiedTrees();
    const FlatScene receivers = ReceiversOf(scene);
    const std::vector<PlantCopy> copies = FindCopies(scene, receivers);
    ASSERT_EQ(copies.size(), 4u);
    const WorldFrames world(scene);
    for (const PlantCopy& copy : copies) {
        EXPECT_LT(copy.original, copy.firstReceiver);
        for (std::uint32_t k = 0; k < copy.receivers; ++k) {
            const Receiver& mine = receivers.receivers[copy.firstReceiver + k];
            const Receiver& theirs = receivers.receivers[copy.original + k];
            ASSERT_EQ(mine.kind, ReceiverKind::kOrgan);
            EXPECT_EQ(ReceiverMesh(scene, mine).positions, ReceiverMesh(scene, theirs).positions);
            // The copy's organ is the original's moved.
            const glm::dmat4 moved = copy.moved * world.at(scene.nodes[theirs.declared].id);
            const glm::dmat4 placed = world.at(scene.nodes[mine.declared].id);
            for (int c = 0; c < 4; ++c) {
                for (int r = 0; r < 3; ++r) EXPECT_NEAR(moved[c][r], placed[c][r], 1e-12);
            }
        }
    }
    // A leaf of one copy moved by a micrometre, and another copy's leaf given a mesh of its
    // own (equal, but not the shared one): those two trees are no longer copies.
    const auto leafOf = [&](const PlantCopy& copy) -> Node& {
        return scene.nodes[receivers.receivers[copy.firstReceiver + copy.receivers / 2].declared];
    };
    Node& shifted = leafOf(copies[0]);
    glm::dmat4 frame = shifted.parentFromLocal();
    frame[3].x += 1e-6;
    shifted.Edit().parentFromLocal = frame;
    Node& own = leafOf(copies[3]);
    own.Edit().organ->mesh = std::make_shared<const Mesh>(*own.organ()->mesh);
    scene.Validate();
    const std::vector<PlantCopy> left = FindCopies(scene, ReceiversOf(scene));
    ASSERT_EQ(left.size(), 2u);
    EXPECT_EQ(left[0].firstReceiver, copies[1].firstReceiver);
    EXPECT_EQ(left[1].firstReceiver, copies[2].firstReceiver);
}

TEST(Copies, OnePlantOrNoneRepeatedHasNoCopies) {
    Scene scene = OneBandScene({{"leaf", Leaf(0.1, 0.05)}, {"stem", Opaque(0.2)}});
    TreeParameters tree;
    tree.leafCount = 60;
    AddTree(scene, tree, {0.0, 0.0, 0.0});
    scene.Validate();
    EXPECT_TRUE(FindCopies(scene, ReceiversOf(scene)).empty());
    tree.seed = 2;  // a second tree, drawn anew
    AddTree(scene, tree, {3.0, 0.0, 0.0}, 100000);
    scene.Validate();
    EXPECT_TRUE(FindCopies(scene, ReceiversOf(scene)).empty());
}

TEST(Copies, TheOriginalIsTheFirstInTheReceiversOrder) {
    // Plant 1 comes first among the roots, but its leaf after plant 2's among the receivers:
    // plant 2 is the original, so that the ray engine holds it before its copy.
    Scene scene = OneBandScene({{"leaf", Leaf(0.1, 0.05)}});
    const std::shared_ptr<const Mesh> blade = Rectangle(0.1, 0.05, 0.0);
    for (const NodeId root : {1, 2}) {
        Node plant;
        plant.id = root;
        plant.Edit().type = NodeType::kPlant;
        plant.Edit().parentFromLocal = glm::translate(glm::dmat4(1.0), glm::dvec3(root, 0.0, 0.0));
        scene.nodes.push_back(plant);
    }
    scene.nodes.push_back(OrganNode(20, "leaf20", blade, "leaf", 2));
    scene.nodes.push_back(OrganNode(10, "leaf10", blade, "leaf", 1));
    scene.Validate();
    const FlatScene flat = Flatten(scene);
    const std::vector<PlantCopy> copies = FindCopies(scene, flat);
    ASSERT_EQ(copies.size(), 1u);
    EXPECT_EQ(copies[0].original, 0u);
    EXPECT_EQ(copies[0].firstReceiver, 1u);
    const std::unique_ptr<RayScene> rays = SceneRays(scene, ReceiversOf(scene), true);
    for (std::uint32_t t = 0; t < flat.triangles.size(); ++t) {
        const std::array<glm::dvec3, 3> corners = rays->Corners(t);
        EXPECT_LT(glm::length(corners[0] - flat.triangles[t].a), 1e-6) << t;
    }
}

TEST(RayScene, CopiesHeldAsInstancesTraceAsTheirTriangles) {
    // The plantation's rays in an engine that holds each copy as an instance of its
    // original, against the flat scene's engine, ray by ray. A copy's vertices are the
    // original's moved in single precision, within a micrometre here of where the flat
    // scene puts them, so a ray that grazes an edge closer than that may fall on either
    // side: a few rays in ten thousand.
    const Scene scene = CopiedTrees();
    const FlatScene flat = Flatten(scene);
    const FlatScene receivers = ReceiversOf(scene);
    const RayScene whole(flat, std::nullopt);
    const std::unique_ptr<RayScene> copied = SceneRays(scene, receivers, true);
    std::uint32_t organTriangles = 0;
    for (const Receiver& r : flat.receivers)
        organTriangles += r.kind == ReceiverKind::kOrgan ? r.triangleCount : 0;
    for (std::uint32_t t = 0; t < flat.triangles.size(); ++t) {
        const Triangle& tri = flat.triangles[t];
        const std::array<glm::dvec3, 3> corners = copied->Corners(t);
        const glm::dvec3 expected[] = {tri.a, tri.b, tri.c};
        for (int k = 0; k < 3; ++k) ASSERT_LT(glm::length(corners[k] - expected[k]), 2e-6) << t;
    }
    Random random(11);
    const int rays = 10000;
    int hits = 0, blocked = 0, differing = 0;
    for (int i = 0; i < rays; ++i) {
        const auto [start, direction] = RandomRay(random, flat, organTriangles, i % 2 == 1);
        const bool occluded = whole.Occluded(start, direction);
        const bool byOrgans = whole.OccludedByFirst(start, direction, INFINITY, organTriangles);
        const RayHit first = whole.Trace(start, direction);
        const RayHit hit = copied->Trace(start, direction);
        blocked += byOrgans;
        hits += first.fate == RayFate::kHit;
        const bool same =
            copied->Occluded(start, direction) == occluded &&
            copied->OccludedByFirst(start, direction, INFINITY, organTriangles) == byOrgans &&
            hit.fate == first.fate && hit.triangle == first.triangle &&
            (first.fate != RayFate::kHit || std::abs(hit.distance - first.distance) < 1e-5);
        differing += !same;
    }
    EXPECT_GT(blocked, rays / 10);  // the rays meet the trees and the ground
    EXPECT_GT(hits - blocked, rays / 10);
    EXPECT_LE(differing, 5);
}

TEST(Instanced, CopiesHeldOnceShadeTheLeavesAsTheWholeEngine) {
    // The CLI's instanced solve of the plantation, shadows by the scene's triangles in one
    // hierarchy and with the copies held once (--shadows geometry-compact): the same light
    // but where a sun-map pixel or a ray grazes an edge within the copies' single-precision
    // move. One sample of a triangle's sun map is 1/2048 of its sun (256 pixels, 8
    // directions over the disc), 5e-4 of the brightest leaf's light here: measured, the
    // largest difference is 2.5e-4 of it, and the totals agree within 1e-8.
    Scene scene = CopiedTrees();
    scene.sources.suns.push_back(SunAt(50.0, 150.0, 500.0));
    Sky sky;
    sky.horizontalIrradianceWm2 = {90.0};
    scene.sources.skies.push_back(sky);
    scene.Validate();
    const FlatScene receivers = ReceiversOf(scene);
    const auto solve = [&](bool copies) {
        const std::unique_ptr<RayScene> shadows = SceneRays(scene, receivers, copies);
        PhaseDatabase database({});
        InstancedOptions options;
        options.hrc.epsilon = 1e-3;
        return SolveInstanced(scene, receivers, shadows.get(), DefaultPolicy(), database, options);
    };
    const InstancedSolution whole = solve(false), copied = solve(true);
    ASSERT_EQ(FindCopies(scene, receivers).size(), 4u);
    double brightest = 0.0, worst = 0.0;
    for (std::size_t r = 0; r < receivers.receivers.size(); ++r) {
        const BandLight& a = whole.solution.light[r][0];
        const BandLight& b = copied.solution.light[r][0];
        brightest = std::max(brightest, a.irradianceUpperWm2 + a.irradianceLowerWm2);
        worst = std::max({worst, std::abs(a.irradianceUpperWm2 - b.irradianceUpperWm2),
                          std::abs(a.irradianceLowerWm2 - b.irradianceLowerWm2)});
    }
    EXPECT_GT(brightest, 0.0);
    EXPECT_LT(worst, 1e-3 * brightest);
    const EnergyBalance &a = whole.solution.balance[0], &b = copied.solution.balance[0];
    EXPECT_NEAR(b.absorbedW, a.absorbedW, 1e-6 * a.absorbedW);
    EXPECT_NEAR(b.incidentW, a.incidentW, 1e-6 * a.incidentW);
}

}  // namespace
}  // namespace leaflux
