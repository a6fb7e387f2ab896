// Shared structures in scene files (leaflux.v1.Scene.structures and .placements): a subtree
// of nodes defined once and placed many times by a transform and an id offset, so that a
// plantation of copies is written as its prototypes and their placements.
//
// Reading expands every placement into ordinary nodes, each copy's nodes carrying the
// structure's types, attributes, organs (meshes stay shared) and frames, with ids offset;
// references that cannot resolve (an unknown structure, a parent outside the structure, a
// structure placing itself, a placed id already used) are InputErrors naming the field and
// node. Writing finds the exact copies in a Scene (equal subtrees in their roots' frames,
// ids in the same pattern) and writes each once.
#pragma once

#include <cstddef>
#include <vector>

#include "leaflux.pb.h"
#include "server/scene_proto.h"
#include "solver/scene/scene.h"

namespace leaflux {

// The nodes `message`'s placements make, counted before any is made: throws InputError on an
// unknown structure or a structure that places itself, and TooLarge when the count (with
// `topLevelNodes`) passes limits.maxNodes.
std::size_t CountPlacedNodes(const v1::Scene& message, std::size_t topLevelNodes,
                             const SceneLimits& limits);

// Appends the nodes of every placement of `message` to `nodes` (which holds the scene's
// own nodes), then puts all of them in id order. Needs CountPlacedNodes to have passed.
void ExpandPlacements(const v1::Scene& message, const MeshLibrary& meshes,
                      std::vector<Node>& nodes);

// Writes `scene`'s nodes into `message`: subtrees of two or more nodes that occur more than
// once as exact copies become `structures`, placed by `placements`; the rest are `nodes`.
// Meshes used by more than one organ go to `meshes`, once each.
void WriteInstancedNodes(const Scene& scene, v1::Scene& message);

// The same nodes written one by one (no structures), meshes shared as above.
void WriteFlatNodes(const Scene& scene, v1::Scene& message);

}  // namespace leaflux
