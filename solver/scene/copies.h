// Plants that are exact copies of another plant of the scene, moved: the same meshes (the
// same shared Mesh objects) under the same frames below their roots, in the same order, as
// a plantation of placed structures is (leaflux.v1.Scene.placements), whatever wrote it. A
// ray engine then holds the original's triangles once and each copy as a transform of
// them (SceneRays): on the paper's plantation of 233 copies of 4 trees, 4 trees' worth of
// hierarchy where the whole plantation's took about a quarter of the solve's memory.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "solver/scene/geometry.h"
#include "solver/scene/scene.h"

namespace leaflux {

struct PlantCopy {
    // The copy's organs: the flat scene's receivers [firstReceiver, firstReceiver + receivers),
    // one after the other as the original's [original, original + receivers) are, each the
    // same mesh as its counterpart there.
    std::uint32_t firstReceiver = 0;
    std::uint32_t receivers = 0;
    std::uint32_t original = 0;
    // The copy's world from the original's: its root's frame times the inverse of the
    // original's root frame.
    glm::dmat4 moved{1.0};
};

// The copies among the plants (topology roots) of a validated scene, in the order of their
// receivers; `flat` is the scene's flat scene or ReceiversOf it. An original is the first
// plant of its kind in the receivers' order and copies nothing; a plant whose organs are not
// consecutive receivers is no copy and no original. Equal frames are equal to the bit:
// copies are exact, never merely close.
std::vector<PlantCopy> FindCopies(const Scene& scene, const FlatScene& flat);

}  // namespace leaflux
