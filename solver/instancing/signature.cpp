#include "solver/instancing/signature.h"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <numeric>
#include <optional>
#include <span>
#include <sstream>

#include "solver/scene/topology.h"
#include "solver/scene/world_frames.h"
#include "solver/util/check.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

bool IsLeafOrgan(const Node& node) { return node.type() == NodeType::kLeaf && node.organ(); }

// Per node, by position in scene.nodes: the leaf organs in its subtree, each counted on
// the way down to it. `topology`: null for a scene InWalkOrder. 4 bytes a node: on a
// plantation's 4.3 M nodes, with the inclinations of every node beside them, 8 bytes each,
// the two made the setup's peak.
std::vector<std::uint32_t> LeavesUnder(const Scene& scene, const Topology* topology) {
    std::vector<std::uint32_t> leaves(scene.nodes.size(), 0);
    ForEachNodeDown(scene, topology, [&](std::uint32_t i, std::span<const std::uint32_t> above) {
        if (!IsLeafOrgan(scene.nodes[i])) return;
        ++leaves[i];
        for (const std::uint32_t a : above) ++leaves[a];
    });
    return leaves;
}

// The angle (degrees) between a frame's z and the world's up.
double Inclination(const glm::dmat4& worldFromLocal) {
    const glm::dvec3 z(worldFromLocal[2]);
    const double length = glm::length(z);
    return length > 0.0 ? glm::degrees(std::acos(std::clamp(z.z / length, -1.0, 1.0))) : 0.0;
}

// Bins `value` for one part of the signature; false (and the reason) when it has none.
bool AddPart(std::string& signature, std::string& unbinned, const Bins& bins,
             const std::string& label, const std::string& field, std::optional<double> value,
             int& bin) {
    if (!value) {
        unbinned = "has no attribute " + label + " (" + field + ")";
        return false;
    }
    bin = bins.BinOf(*value);
    if (bin < 0) {
        std::ostringstream text;
        text << label << " " << *value << " lies outside " << field;
        unbinned = text.str();
        return false;
    }
    if (!signature.empty()) signature += '|';
    signature += label + bins.Label(bin);
    return true;
}

StructureSignature Classify(const Node& node, std::int64_t leafCount, double inclination,
                            const InstancingPolicy& policy,
                            const std::vector<std::size_t>& attributesByName) {
    StructureSignature s;
    s.id = node.id;
    s.type = node.type();
    s.leafCount = leafCount;
    s.age = node.age();
    s.inclination = inclination;
    s.attributeBins.assign(policy.attributes.size(), -1);
    for (const AttributeBins& attribute : policy.attributes) {
        const auto found = node.attributes().find(attribute.name);
        s.attributes.push_back(
            found == node.attributes().end() ? std::nullopt : std::optional<double>(found->second));
    }
    const std::string typeName = NodeTypeName(node.type());
    if (const FixedFunction* cap = policy.FixedFor(node.type());
        cap && leafCount > cap->leafCountAbove) {
        // Soler 2003 §4.1: functions of large structures converge, one original per type.
        s.fixed = true;
        s.signature = typeName + "|large";
        return s;
    }
    std::string signature = policy.byType ? typeName : std::string();
    bool binned = true;
    if (policy.leafCount.Used()) {
        binned = AddPart(signature, s.unbinned, policy.leafCount, "leaves", "leaf_count",
                         static_cast<double>(leafCount), s.leafBin);
    }
    if (binned && policy.age.Used()) {
        binned = AddPart(signature, s.unbinned, policy.age, "age", "age", node.age(), s.ageBin);
    }
    if (binned && policy.inclination.Used()) {
        binned = AddPart(signature, s.unbinned, policy.inclination, "incl", "inclination",
                         inclination, s.inclinationBin);
    }
    // Attributes by name, so that their order in the policy file does not change signatures
    // (PolicyContentHash ignores that order too).
    for (std::size_t k = 0; binned && k < attributesByName.size(); ++k) {
        const std::size_t a = attributesByName[k];
        const AttributeBins& attribute = policy.attributes[a];
        binned = AddPart(signature, s.unbinned, attribute.bins, attribute.name,
                         "attributes[" + attribute.name + "]", s.attributes[a], s.attributeBins[a]);
    }
    if (binned) s.signature = std::move(signature);
    return s;
}

void ChooseRepresentative(SignatureGroup& group, const SceneSignatures& signatures) {
    std::vector<std::int64_t> counts;
    counts.reserve(group.members.size());
    for (const NodeId id : group.members) counts.push_back(signatures.Find(id)->leafCount);
    std::sort(counts.begin(), counts.end());
    const std::size_t m = counts.size() / 2;
    group.medianLeafCount = counts.size() % 2 == 1
                                ? static_cast<double>(counts[m])
                                : 0.5 * static_cast<double>(counts[m - 1] + counts[m]);
    double best = 0.0;
    for (std::size_t i = 0; i < group.members.size(); ++i) {
        // Members ascend: the first of equal distances has the smallest id.
        const NodeId id = group.members[i];
        const double distance =
            std::abs(static_cast<double>(signatures.Find(id)->leafCount) - group.medianLeafCount);
        if (i == 0 || distance < best) {
            best = distance;
            group.representative = id;
        }
    }
}

}  // namespace

const StructureSignature* SceneSignatures::Find(NodeId id) const {
    const auto found =
        std::lower_bound(structures.begin(), structures.end(), id,
                         [](const StructureSignature& s, NodeId value) { return s.id < value; });
    return found != structures.end() && found->id == id ? &*found : nullptr;
}

SceneSignatures ComputeSignatures(const Scene& scene, const InstancingPolicy& policy,
                                  bool unbinned) {
    ValidatePolicy(policy);
    std::vector<std::size_t> attributesByName(policy.attributes.size());
    std::iota(attributesByName.begin(), attributesByName.end(), std::size_t{0});
    std::sort(attributesByName.begin(), attributesByName.end(), [&](std::size_t a, std::size_t b) {
        return policy.attributes[a].name < policy.attributes[b].name;
    });

    const std::optional<Topology> topology = TopologyUnlessInWalkOrder(scene);
    const Topology* walk = topology ? &*topology : nullptr;
    const std::vector<std::uint32_t> leaves = LeavesUnder(scene, walk);
    SceneSignatures result;
    std::vector<bool> carried(policy.attributes.size(), false);
    const auto classify = [&](std::size_t i, double inclination) {
        const Node& node = scene.nodes[i];
        if (!policy.IsInstanceType(node.type())) return;
        for (std::size_t a = 0; a < policy.attributes.size(); ++a) {
            if (node.attributes().count(policy.attributes[a].name)) carried[a] = true;
        }
        if (leaves[i] == 0) return;  // nothing to light: never an instance
        StructureSignature s = Classify(node, leaves[i], inclination, policy, attributesByName);
        if (unbinned || !s.signature.empty()) result.structures.push_back(std::move(s));
    };
    if (policy.inclination.Used()) {
        ForEachWorldFrame(scene, walk, [&](const Node& node, const glm::dmat4& worldFromLocal) {
            classify(static_cast<std::size_t>(&node - scene.nodes.data()),
                     Inclination(worldFromLocal));
        });
    } else {
        for (std::size_t i = 0; i < scene.nodes.size(); ++i) classify(i, 0.0);
    }
    result.structures.shrink_to_fit();
    for (std::size_t a = 0; a < policy.attributes.size(); ++a) {
        if (!carried[a]) {
            throw InputError(ErrorCode::kNotFound,
                             "attributes[" + policy.attributes[a].name + "].name",
                             "no node of an instance type carries this attribute");
        }
    }
    std::sort(result.structures.begin(), result.structures.end(),
              [](const auto& a, const auto& b) { return a.id < b.id; });

    std::map<std::string, std::vector<NodeId>> members;
    for (const StructureSignature& s : result.structures) {
        if (!s.signature.empty()) members[s.signature].push_back(s.id);
    }
    for (auto& [signature, ids] : members) {
        SignatureGroup group;
        group.signature = signature;
        group.members = std::move(ids);
        ChooseRepresentative(group, result);
        result.groups.push_back(std::move(group));
    }
    // By type, then by bins in signature order, so a listing reads from small to large
    // (the strings alone would put "leaves[1001" before "leaves[101").
    const auto key = [&](const SignatureGroup& group) {
        const StructureSignature& s = *result.Find(group.members.front());
        std::vector<int> bins{static_cast<int>(s.type), s.fixed, s.leafBin, s.ageBin,
                              s.inclinationBin};
        for (const std::size_t a : attributesByName) bins.push_back(s.attributeBins[a]);
        return bins;
    };
    std::sort(result.groups.begin(), result.groups.end(), [&](const auto& a, const auto& b) {
        const auto ka = key(a), kb = key(b);
        return ka != kb ? ka < kb : a.signature < b.signature;
    });
    return result;
}

}  // namespace leaflux
