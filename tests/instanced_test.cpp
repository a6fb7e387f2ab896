// The instanced solver (Soler 2003 §3.2–3.5) against the flattened scene: exact copies of
// one structure, instantiated, light their leaves as HRC on the whole scene does.
#include "solver/instancing/instanced.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "solver/generate/generator.h"
#include "solver/results/accuracy.h"
#include "solver/solve.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {

// `copies` identical trees of `leaves` leaves in a row, each turned about its own axis.
Scene Copies(int copies, int leaves, double spacing = 1.2) {
    Scene scene;
    scene.bands = {{"PAR"}, {"NIR"}};
    scene.optics = {{"leaf", {{0.08, 0.06, 0.05, 0.05}, {0.45, 0.4, 0.45, 0.45}}},
                    {"stem", {{0.1, 0.1, 0.0, 0.0}, {0.3, 0.3, 0.0, 0.0}}}};
    TreeParameters tree;
    tree.leafCount = leaves;
    NodeId next = 1;
    for (int c = 0; c < copies; ++c) {
        const std::size_t first = scene.nodes.size();
        next = AddTree(scene, tree, {0.0, 0.0, 0.0}, next);
        Node& root = scene.nodes[first];
        EXPECT_EQ(root.parent, kNoParent);
        root.parentFromLocal =
            glm::rotate(glm::translate(glm::dmat4(1.0), {spacing * c, 0.25 * spacing * c, 0.0}), 0.9 * c,
                        glm::dvec3(0, 0, 1)) *
            root.parentFromLocal;
    }
    Sun sun = testing::SunAt(55.0, 140.0, 500.0);
    sun.normalIrradianceWm2 = {500.0, 450.0};
    scene.sources.suns.push_back(sun);
    Sky sky;
    sky.horizontalIrradianceWm2 = {90.0, 70.0};
    scene.sources.skies.push_back(sky);
    scene.Validate();
    return scene;
}

InstancingPolicy Plants() {
    InstancingPolicy policy;
    policy.species = "copies";
    policy.instanceTypes = {NodeType::kPlant};
    policy.leafCount.edges = {1, 1e7};
    policy.phase = {PhaseKind::kMonoDirectional, 3};
    policy.transmittance = {PhaseKind::kMonoDirectional, 3};
    return policy;
}

TEST(Instanced, ExactCopiesLightTheirLeavesAsTheFlattenedScene) {
    const Scene scene = Copies(4, 120, std::getenv("SPACING") ? std::atof(std::getenv("SPACING")) : 1.2);
    const PreparedScene prepared(scene);
    SolverSettings flat;
    flat.kind = SolverKind::kHrc;
    flat.hrc.epsilon = 1e-4;
    const Solution hrc = Solve(prepared, flat);
    PhaseDatabase database({});
    InstancedOptions options;
    options.hrc = flat.hrc;
    const InstancedSolution instanced =
        SolveInstanced(scene, prepared.Flat(), std::getenv("TAU") ? nullptr : &prepared.Rays(), Plants(), database, options);
    EXPECT_EQ(instanced.stats.originalsComputed, 1);
    ASSERT_EQ(instanced.stats.depths.size(), 2u);
    EXPECT_EQ(instanced.stats.depths[1].instances, 4);
    EXPECT_EQ(instanced.stats.depths[1].opened, 4);
    SolverSettings mcSettings;
    mcSettings.monteCarlo.samplesPerReceiver = 4096;
    const Solution mc = Solve(prepared, mcSettings);
    for (const BandAccuracy& band : CompareLeaves(scene, prepared.Flat(), mc, hrc))
        std::printf("hrc vs mc: L2 %.3f %% mean rel %.3f %% floor %.3f\n", band.l2PctOfMax, band.meanRelativePct, band.referenceFloorPct);
    for (const BandAccuracy& band : CompareLeaves(scene, prepared.Flat(), mc, instanced.solution))
        std::printf("inst vs mc: L2 %.3f %% mean rel %.3f %%\n", band.l2PctOfMax, band.meanRelativePct);
    const auto accuracy = CompareLeaves(scene, prepared.Flat(), hrc, instanced.solution);
    for (const BandAccuracy& band : accuracy) {
        std::printf("vs hrc: L2 %.3f %% mean rel %.3f %%\n", band.l2PctOfMax, band.meanRelativePct);
    }
    for (std::size_t b = 0; b < scene.bands.size(); ++b) {
        std::printf("balance hrc %g %g %g  inst %g %g %g\n", hrc.balance[b].incidentW,
                    hrc.balance[b].absorbedW, hrc.balance[b].escapedW,
                    instanced.solution.balance[b].incidentW,
                    instanced.solution.balance[b].absorbedW,
                    instanced.solution.balance[b].escapedW);
    }
}

}  // namespace
}  // namespace leaflux
namespace leaflux {
TEST(InstancedExplore, Tree) {
    if (!std::getenv("LEAVES")) GTEST_SKIP();
    Scene scene;
    scene.bands = {{"PAR"}, {"NIR"}};
    scene.optics = {{"leaf", {{0.08, 0.06, 0.05, 0.05}, {0.45, 0.4, 0.45, 0.45}}},
                    {"stem", {{0.1, 0.1, 0.0, 0.0}, {0.3, 0.3, 0.0, 0.0}}}};
    TreeParameters tree;
    tree.leafCount = std::atoi(std::getenv("LEAVES"));
    AddTree(scene, tree, {0, 0, 0});
    Sun sun = testing::SunAt(55.0, 140.0, 500.0);
    sun.normalIrradianceWm2 = {500.0, 450.0};
    scene.sources.suns.push_back(sun);
    Sky sky;
    sky.horizontalIrradianceWm2 = {90.0, 70.0};
    scene.sources.skies.push_back(sky);
    scene.Validate();
    const PreparedScene prepared(scene);
    SolverSettings flat;
    flat.kind = SolverKind::kHrc;
    flat.hrc.epsilon = std::getenv("EPS") ? std::atof(std::getenv("EPS")) : 1e-4;
    const Solution hrc = Solve(prepared, flat);
    PhaseDatabase database({});
    InstancedOptions options;
    options.hrc = flat.hrc;
    InstancingPolicy policy;
    policy.species = "t";
    policy.instanceTypes = {NodeType::kAxis};
    if (std::getenv("PLANT")) policy.instanceTypes.push_back(NodeType::kPlant);
    policy.leafCount.edges = {1, 10, 100, 1000, 10000, 1e7};
    policy.phase = {PhaseKind::kMonoDirectional, 3};
    policy.transmittance = {PhaseKind::kMonoDirectional, 3};
    const InstancedSolution instanced = SolveInstanced(scene, prepared.Flat(), std::getenv("TAU") ? nullptr : &prepared.Rays(), policy, database, options);
    SolverSettings mcSettings;
    mcSettings.monteCarlo.samplesPerReceiver = 1024;
    const Solution mc = Solve(prepared, mcSettings);
    for (const BandAccuracy& band : CompareLeaves(scene, prepared.Flat(), mc, hrc))
        std::printf("hrc vs mc: L2 %.3f %% mean rel %.3f %% floor %.3f  %.2fs\n", band.l2PctOfMax, band.meanRelativePct, band.referenceFloorPct, hrc.stats.wallSeconds);
    for (const BandAccuracy& band : CompareLeaves(scene, prepared.Flat(), mc, instanced.solution))
        std::printf("inst vs mc: L2 %.3f %% mean rel %.3f %% %.2fs (orig %.2f)\n", band.l2PctOfMax, band.meanRelativePct, instanced.solution.stats.wallSeconds, instanced.stats.originalSeconds);
    for (std::size_t d = 0; d < instanced.stats.depths.size(); ++d)
        std::printf("depth %zu: %d instances\n", d, instanced.stats.depths[d].instances);
    std::printf("originals %d\n", instanced.stats.originalsComputed);
}
}  // namespace leaflux
namespace leaflux {
TEST(InstancedExplore, SingleVsDirectional) {
    const Scene scene = Copies(4, 120, 1.2);
    const PreparedScene prepared(scene);
    PhaseDatabase database({});
    InstancedOptions options;
    options.hrc.epsilon = 1e-4;
    const InstancedSolution a = SolveInstanced(scene, prepared.Flat(), &prepared.Rays(), Plants(), database, options);
    options.hrc.directionalInstances = false;
    const InstancedSolution b = SolveInstanced(scene, prepared.Flat(), &prepared.Rays(), Plants(), database, options);
    double d = 0;
    for (std::size_t r = 0; r < a.solution.light.size(); ++r) d = std::max(d, std::abs(a.solution.light[r][1].irradianceUpperWm2 - b.solution.light[r][1].irradianceUpperWm2));
    std::printf("max diff %g\n", d);
    for (auto& p : a.stats.problems) std::printf("problem depth %d tri %lld closed %lld elements %lld links %lld\n", p.depth, (long long)p.triangles, (long long)p.closed, (long long)p.elements, (long long)p.links);
}
}
