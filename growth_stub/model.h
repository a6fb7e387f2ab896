// leaflux-grow's plant model: a small functional-structural model in the GreenLab line,
// simple enough to read in one sitting. It knows nothing of light transport: each cycle
// it is told the light every leaf received and answers with the plants it grew.
//
// Structure. A plant is axes of phytomers; a phytomer is an internode, a leaf at its top
// and an axillary bud in the leaf's axil. Topology sent to leafluxd:
//     plant → axis → phytomer → phytomer → …   (each phytomer is the child of the one below)
//                     ├ internode, leaf         (organs, children of their phytomer)
//                     └ axis (a branch from its axillary bud) → phytomer → …
// Frames chain the same way, so an internode that lengthens moves everything above it by
// changing one frame, and a bend at one phytomer tilts the rest of the axis.
//
// Function, each cycle:
// 1. production: Q = RUE · (PAR absorbed by the plant's leaves) · light hours;
// 2. organogenesis, if last cycle's supply / demand ≥ min_supply_demand: every growing
//    apex makes a phytomer, turned towards the light vector of its axis's young leaves
//    (phototropism); a dormant bud whose leaf receives ≥ bud_break_par_wm2 breaks into a
//    new axis;
// 3. allocation (common pool): Q plus what is left is shared among expanding organs in
//    proportion to their sink strengths;
// 4. allometry: leaf area = SLA · biomass; an internode is a cylinder of fixed
//    length / radius and density;
// 5. shedding (a switch): a leaf in deep shade for shade_cycles cycles falls.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <string>
#include <vector>

#include "scenario.pb.h"

namespace leaflux::grow {

using NodeId = std::uint64_t;
using Scenario = leaflux::scenario::v1::Scenario;
using SpeciesTraits = leaflux::scenario::v1::Species;
using Placement = leaflux::scenario::v1::Placement;
using Stand = leaflux::scenario::v1::Stand;
using Turning = leaflux::scenario::v1::Turning;
using Room = leaflux::scenario::v1::Room;

// The PAR one leaf received in a cycle.
struct LeafLight {
    double absorbedW = 0.0;
    double irradianceWm2 = 0.0;  // upper + lower side: all that reaches the blade
    glm::dvec3 vector{0.0};      // light vector (world), towards where light comes from
};

struct PlantSummary {
    NodeId id = 0;
    int leaves = 0;
    double leafAreaM2 = 0.0;
    double biomassG = 0.0;         // everything the plant has built, seed included
    double absorbedParW = 0.0;     // filled by the caller, who knows the light
    glm::dvec3 leafCentroid{0.0};  // leaf-area weighted, world
};

// A triangle of the plants in world coordinates, and the organ it belongs to.
struct WorldTriangle {
    glm::dvec3 a, b, c;
    NodeId organ = 0;
};

class GrowthModel {
  public:
    // Throws std::invalid_argument naming the field when the scenario cannot grow.
    explicit GrowthModel(const Scenario& scenario);

    // The plants as leafluxd should see them now, by id.
    std::map<NodeId, leaflux::v1::Node> Nodes() const;
    // The shared meshes the organs refer to ("leaf", "internode"), for the session's scene.
    static std::map<std::string, leaflux::v1::Mesh> Meshes();
    // Environment surfaces the scenario builds (the room), to add to the session's scene.
    std::vector<leaflux::v1::Surface> Environment() const;

    // One cycle of growth from the light of the last one (a leaf absent from `light` had
    // none). Turns the pots when the scenario says so.
    void Grow(const std::map<NodeId, LeafLight>& light);

    int Cycle() const { return cycle_; }
    std::vector<PlantSummary> Summaries() const;
    struct LeafInfo {
        NodeId leaf = 0, axis = 0, plant = 0;
        double areaM2 = 0.0;
        // Its axis and the axes bearing it, to the main axis.
        std::vector<NodeId> axes;
    };
    std::vector<LeafInfo> Leaves() const;
    // Every phytomer by its topological address, the same in two runs of one scenario
    // however their ids differ: "<plant>:<axis>/<rank>", the main axis "0", a branch its
    // bearer's axis and rank ("0.3" grew from the 4th phytomer of the main axis), rank
    // from 0 at the base. For comparing plants grown under other light (paper Fig. 15).
    struct PhytomerSize {
        std::string address;
        double internodeG = 0.0;
        double leafG = 0.0;  // 0 once the leaf has fallen
    };
    std::vector<PhytomerSize> Phytomers() const;
    // Every plant triangle, for pictures.
    std::vector<WorldTriangle> Triangles() const;

  private:
    enum class Bud { kDormant, kBroken, kDead };
    struct Phytomer {
        NodeId id = 0, internode = 0, leaf = 0;  // leaf 0: fallen
        int axis = 0;
        int age = 0;
        double internodeG = 0.0, leafG = 0.0;
        glm::dmat3 turn{1.0};  // rotation at its base, relative to what bears it
        Bud bud = Bud::kDormant;
        int shadedCycles = 0;
        LeafLight light;
    };
    struct Axis {
        NodeId id = 0;
        int order = 0;
        int bearer = -1;  // the phytomer whose bud it grew from; -1: the main axis
        std::vector<int> phytomers;
        bool growing = true;
    };
    struct Plant {
        NodeId id = 0;
        Placement placement;
        double turnedDeg = 0.0;
        std::vector<Axis> axes;
        std::vector<Phytomer> phytomers;
        double poolG = 0.0, builtG = 0.0;
        double supplyDemand = 1.0;  // g per unit of sink strength, last cycle
    };

    void AddPhytomer(Plant& plant, int axis, const glm::dmat3& turn);
    void Allocate(Plant& plant, double supplyG);
    glm::dmat3 TurnTowardsLight(const Plant& plant, const Axis& axis,
                                const std::map<NodeId, glm::dmat4>& world) const;
    double InternodeLength(const Phytomer& p) const;
    glm::dmat4 LeafFrame(const Phytomer& p) const;
    std::map<NodeId, glm::dmat4> WorldFrames() const;

    const SpeciesTraits& Species() const { return scenario_.species(); }

    Scenario scenario_;
    std::vector<Plant> plants_;
    NodeId nextId_ = 1;
    int cycle_ = 0;
};

// What leafluxd needs to go from `before` to `after`: nodes added, updated (anything in
// them changed) and removed (only the topmost of a removed subtree).
leaflux::v1::TopologyDelta Diff(const std::map<NodeId, leaflux::v1::Node>& before,
                                const std::map<NodeId, leaflux::v1::Node>& after);

}  // namespace leaflux::grow
