// Scenes of copies of one generated tree, instantiated at their plants, and their
// flattened solve: what the instanced solver's tests compare.
#pragma once

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "solver/generate/generator.h"
#include "solver/instancing/instanced.h"
#include "solver/solve.h"
#include "tests/scene_builders.h"

namespace leaflux::testing {

// `copies` identical trees of `leaves` leaves in a row, each turned about its own axis.
inline Scene Copies(int copies, int leaves, double spacing = 1.2) {
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
        root.Edit().parentFromLocal =
            glm::rotate(glm::translate(glm::dmat4(1.0), {spacing * c, 0.25 * spacing * c, 0.0}),
                        0.9 * c, glm::dvec3(0, 0, 1)) *
            glm::dmat4(root.parentFromLocal());
    }
    Sun sun = SunAt(55.0, 140.0, 500.0);
    sun.normalIrradianceWm2 = {500.0, 450.0};
    scene.sources.suns.push_back(sun);
    Sky sky;
    sky.horizontalIrradianceWm2 = {90.0, 70.0};
    scene.sources.skies.push_back(sky);
    scene.Validate();
    return scene;
}

inline InstancingPolicy Plants() {
    InstancingPolicy policy;
    policy.species = "copies";
    policy.instanceTypes = {NodeType::kPlant};
    policy.leafCount.edges = {1, 1e7};
    policy.phase = {PhaseKind::kMonoDirectional, 3};
    policy.transmittance = {PhaseKind::kMonoDirectional, 3};
    return policy;
}

inline Solution Hrc(const PreparedScene& prepared, double epsilon) {
    SolverSettings settings;
    settings.kind = SolverKind::kHrc;
    settings.hrc.epsilon = epsilon;
    return Solve(prepared, settings);
}

// `scene` instantiated at its plants at ε, from an empty phase-function database.
inline InstancedSolution PlantsInstanced(const Scene& scene, const PreparedScene& prepared,
                                         double epsilon) {
    PhaseDatabase database({});
    InstancedOptions options;
    options.hrc.epsilon = epsilon;
    return SolveInstanced(scene, prepared.Flat(), &prepared.Rays(), Plants(), database, options);
}

}  // namespace leaflux::testing
