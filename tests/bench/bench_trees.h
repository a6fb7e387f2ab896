// The generated trees the directional-function benchmarks measure: the same two bands and
// optics everywhere, so that their tables compare.
#pragma once

#include <cstdint>

#include "solver/generate/generator.h"
#include "solver/scene/scene.h"

namespace leaflux {

// PAR and NIR; leaves that scatter NIR strongly, opaque stems.
inline void SetBenchOptics(Scene& scene) {
    scene.bands = {{"PAR"}, {"NIR"}};
    scene.optics = {{"leaf", {{0.08, 0.06, 0.05, 0.05}, {0.45, 0.4, 0.45, 0.45}}},
                    {"stem", {{0.1, 0.1, 0.0, 0.0}, {0.3, 0.3, 0.0, 0.0}}}};
}

// One generated tree of `leaves` leaves at the origin.
inline Scene Tree(int leaves, std::uint64_t seed = 1) {
    Scene scene;
    SetBenchOptics(scene);
    TreeParameters tree;
    tree.leafCount = leaves;
    tree.seed = seed;
    AddTree(scene, tree, {0, 0, 0});
    return scene;
}

}  // namespace leaflux
