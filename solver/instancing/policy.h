// An instantiation policy (Soler 2003 §4.1): which structures of a species may become
// instances, which of their attributes make the signature that decides which of them share
// one original, the bins over those attributes, the size beyond which a type uses one fixed
// original, and how finely the originals' functions are sampled (§4.2).
//
// A plain value: it is read from a file by the server (server/policy_proto.h), built in
// code by tests. ValidatePolicy checks it alone; the attribute names are checked against a
// scene when signatures are computed (signature.h), since only a scene says which exist.
// Field names in errors are the policy file's ("leaf_count.edges[2]").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "solver/instancing/directional.h"
#include "solver/scene/scene.h"

namespace leaflux {

// Bins over one value: edges e0 < e1 < … < en make [e0, e1), …, [en-1, en]. The last bin
// is closed so that a size cap equal to en leaves no gap before the fixed function.
struct Bins {
    std::vector<double> edges;  // empty: the value is not part of the signature

    bool Used() const { return !edges.empty(); }
    int Count() const { return edges.empty() ? 0 : static_cast<int>(edges.size()) - 1; }
    // The bin holding `value`; -1 when it lies outside [e0, en] (or is NaN).
    int BinOf(double value) const;
    // "[10,100)", or "[1000,10000]" for the last bin.
    std::string Label(int bin) const;
};

struct AttributeBins {
    std::string name;  // a key of Node::attributes
    Bins bins;
};

// Structures of `type` with more than `leafCountAbove` leaves all share one original.
struct FixedFunction {
    NodeType type = NodeType::kAxis;
    std::int64_t leafCountAbove = 0;
};

// A function's kind and its direction set (DirectionSet level 0..4: 4, 10, 34, 130, 514
// directions). A constant function has no direction set: its level is ignored.
struct FunctionResolution {
    PhaseKind kind = PhaseKind::kMonoDirectional;
    int level = 3;
};

struct InstancingPolicy {
    std::string species;
    std::vector<NodeType> instanceTypes;  // the types whose structures may be instances
    bool byType = true;                   // the node type is part of the signature
    Bins leafCount;                       // leaf organs in the structure's subtree
    Bins age;                             // the node's physiological age
    // The angle (degrees) between the structure's frame's z and the world's up (+z).
    Bins inclination;
    std::vector<AttributeBins> attributes;
    std::vector<FixedFunction> fixed;  // at most one per instance type
    FunctionResolution phase;
    FunctionResolution transmittance;  // constant or mono-directional

    bool IsInstanceType(NodeType type) const;
    // The fixed original's cap of `type`; nullptr when it has none.
    const FixedFunction* FixedFor(NodeType type) const;
};

// Throws InputError naming the field ("species", "leaf_count.edges[2]",
// "attributes[order].edges[0]", "fixed[1].type", "phase.level") when the policy is not
// usable: no species or instance type, a signature of nothing, bins with fewer than two
// edges, edges that are not finite or not strictly increasing (an empty or overlapping
// bin), duplicate attributes or caps, a cap for a type that is never an instance, a
// direction level outside 0..4, a bi-directional transmittance.
void ValidatePolicy(const InstancingPolicy& policy);

// A content hash of the policy's canonical form (types and caps sorted, attributes by
// name, a constant function's level dropped): what the phase-function database keys on.
// Equal for policies that mean the same, whatever order or layout their file had.
std::string PolicyContentHash(const InstancingPolicy& policy);

}  // namespace leaflux
