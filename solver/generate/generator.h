// Procedural plants for tests, benchmarks and examples: a poplar-like tree with a real
// botanical hierarchy and self-similarity, and plantations of such trees.
//
// A tree is a trunk (order 0) of phytomers bearing lateral axes, whose phytomers bear
// axes of the next order, down to leafy shoots: every axis is a smaller copy of its
// parent's form (the self-similarity the paper's instantiation exploits, Soler 2003 §4.1).
// Node types: plant → axis → phytomer → (internode, leaf, axis). Leaves share one
// prototype mesh and internodes another; each organ is placed, turned and scaled by its
// node's frame (z along the structure's main axis), so the output is instancing data.
//
// With `copies`, the self-similarity is made exact: the lateral axes of one order and one
// leaf count are copies of one prototype (the same nodes, frames and organs below the axis,
// in the axis's frame), placed by their axis frame alone; a plantation's trees are then
// copies of a few prototype trees. Such a scene is what instancing == flattening is tested
// on, and what `SceneWriting::kInstanced` writes small.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "solver/scene/scene.h"

namespace leaflux {

struct TreeParameters {
    int leafCount = 1000;  // exact number of leaves, 1 to 10⁷
    std::uint64_t seed = 1;
    int leavesPerShoot = 10;           // leaves on a terminal shoot
    int maxBranching = 10;             // lateral axes per axis, at most
    double leafLengthM = 0.10;         // mean rhombic blade length; width is 0.6 of it
    double branchAngleDeg = 50.0;      // insertion angle of lateral axes
    double leafInclinationDeg = 35.0;  // mean angle of the blade to the horizontal
    bool internodes = true;            // give internodes geometry (opaque prisms), but on the
                                       // leafy shoots, whose twigs stay bare topology
    // Lateral axes of one order and leaf count are exact copies of one prototype (its nodes'
    // ids contiguous, like every subtree the generator makes). Off: every axis drawn anew,
    // the default tree unchanged.
    bool copies = false;
    std::string leafOptics = "leaf";
    std::string stemOptics = "stem";
};

// Adds one tree to `scene` with its base at `base`, node ids from `firstId` on; returns
// the next free id. The scene's optics must define the two optics ids.
NodeId AddTree(Scene& scene, const TreeParameters& parameters, const glm::dvec3& base,
               NodeId firstId = 1);

struct PlantationParameters {
    TreeParameters tree;
    int rows = 1, columns = 1;
    int trees = 0;  // only the first trees of the grid, row by row (0: every position)
    double rowSpacingM = 5.0, columnSpacingM = 5.0;
    double jitterM = 0.5;        // uniform random offset of each tree, in x and y
    double rowAzimuthDeg = 0.0;  // direction of the rows, from north clockwise
    // With tree.copies: the trees are exact copies of this many prototype trees (tree i of
    // prototype i mod prototypes), each copy turned about z by a random azimuth.
    int prototypes = 4;
    // Called with the fraction of the trees placed (0 to 1), when set: a progress bar.
    std::function<void(double)> progress;
};

// rows × columns trees (each seeded from the tree seed and its position; with tree.copies,
// copies of `prototypes` trees), centred on the
// origin, on a ground rectangle of the plantation's extent (optics `groundOptics`; none
// when empty). Returns the scene's bands and optics untouched: the caller declares them.
void AddPlantation(Scene& scene, const PlantationParameters& parameters,
                   const std::string& groundOptics);

// A greenhouse compartment at night: a plantation of small plants on a floor (optics
// `floorOptics`) 20 cm wider than the plants on every side, four walls round it
// (`wallOptics`, upper sides facing in) `wallHeightM` high, no roof (a glass roof lets scattered
// light out), and above each row a bar of lamps facing down: 80 % of the row's length, `lampWidthM`
// wide, at `lampHeightM`, emitting `lampExitanceWm2` per band (black: they absorb what they get).
struct GreenhouseParameters {
    PlantationParameters plantation;
    double wallHeightM = 3.0;
    double lampHeightM = 2.4;
    double lampWidthM = 0.15;
    std::vector<double> lampExitanceWm2;  // per band of the scene
    std::string floorOptics = "floor";
    std::string wallOptics = "wall";
};
void AddGreenhouse(Scene& scene, const GreenhouseParameters& parameters);

// A random canopy: square leaves of spherical angle distribution (normals uniform on the
// sphere), centres uniform over a width × width square and between two heights, sized for
// the leaf area index; leaves named "leaf<i>", optics `leafOptics`.
struct CanopyParameters {
    int leaves = 500;
    double leafAreaIndex = 3.0;
    double widthM = 2.0;
    double bottomM = 0.5, topM = 1.5;
    std::uint64_t seed = 1;
    std::string leafOptics = "leaf";
};
void AddRandomCanopy(Scene& scene, const CanopyParameters& parameters);

}  // namespace leaflux
