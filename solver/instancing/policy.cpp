#include "solver/instancing/policy.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>

#include "solver/util/content_hash.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

[[noreturn]] void Fail(ErrorCode code, const std::string& field, const std::string& message) {
    throw InputError(code, field, message);
}

// The shortest text that reads back as `value` ("10", "0.5", "1e+06"): bin labels are part
// of signatures, which the database stores, so they must not depend on a stream's state.
std::string ShortestText(double value) {
    char text[32];
    const auto result = std::to_chars(text, text + sizeof text, value);
    return std::string(text, result.ptr);
}

// `field` names the bins ("leaf_count", "attributes[order]"). Leaf counts are counts, so
// their edges may not be negative; ages and attributes may be.
void ValidateBins(const Bins& bins, const std::string& field, bool nonNegative) {
    if (bins.edges.size() == 1) {
        Fail(ErrorCode::kInvalidArgument, field + ".edges",
             "has one edge: a bin needs two (leave the bins out to keep the value out of the "
             "signature)");
    }
    for (std::size_t i = 0; i < bins.edges.size(); ++i) {
        const std::string edge = field + ".edges[" + std::to_string(i) + "]";
        const double value = bins.edges[i];
        if (!std::isfinite(value)) Fail(ErrorCode::kInvalidArgument, edge, "must be finite");
        if (nonNegative && value < 0.0) {
            Fail(ErrorCode::kInvalidArgument, edge,
                 "is negative: no structure has fewer than 0 leaves");
        }
        if (i == 0) continue;
        const double previous = bins.edges[i - 1];
        if (value == previous) {
            Fail(ErrorCode::kInvalidArgument, edge,
                 "equals the edge before it: the bin [" + ShortestText(previous) + ", " +
                     ShortestText(value) + ") is empty");
        }
        if (value < previous) {
            Fail(ErrorCode::kInvalidArgument, edge,
                 "is below the edge before it (" + ShortestText(previous) +
                     "): its bin would overlap the one before; edges must increase");
        }
    }
}

void ValidateResolution(const FunctionResolution& resolution, const std::string& field) {
    if (resolution.kind != PhaseKind::kConstant && resolution.kind != PhaseKind::kMonoDirectional &&
        resolution.kind != PhaseKind::kBiDirectional) {
        Fail(ErrorCode::kInvalidArgument, field + ".kind", "must be constant, mono or bi");
    }
    if (resolution.level < 0 || resolution.level > 4) {
        Fail(ErrorCode::kInvalidArgument, field + ".level",
             "must be 0..4 (4, 10, 34, 130 or 514 directions), got " +
                 std::to_string(resolution.level));
    }
}

// A resolution as the solver will use it: a constant function has no direction set.
int EffectiveLevel(const FunctionResolution& resolution) {
    return resolution.kind == PhaseKind::kConstant ? 0 : resolution.level;
}

void AddBins(ContentHash& hash, const Bins& bins) {
    hash.Add(static_cast<std::uint64_t>(bins.edges.size()));
    hash.Add(std::span<const double>(bins.edges));
}

}  // namespace

int Bins::BinOf(double value) const {
    if (edges.size() < 2 || !(value >= edges.front()) || !(value <= edges.back())) return -1;
    // The first edge above the value closes its bin; the last edge closes the last bin.
    const auto above = std::upper_bound(edges.begin(), edges.end(), value);
    const int bin = static_cast<int>(above - edges.begin()) - 1;
    return std::min(bin, Count() - 1);
}

std::string Bins::Label(int bin) const {
    return "[" + ShortestText(edges[bin]) + "," + ShortestText(edges[bin + 1]) +
           (bin == Count() - 1 ? "]" : ")");
}

bool InstancingPolicy::IsInstanceType(NodeType type) const {
    return std::find(instanceTypes.begin(), instanceTypes.end(), type) != instanceTypes.end();
}

const FixedFunction* InstancingPolicy::FixedFor(NodeType type) const {
    for (const FixedFunction& cap : fixed) {
        if (cap.type == type) return &cap;
    }
    return nullptr;
}

void ValidatePolicy(const InstancingPolicy& policy) {
    if (policy.species.empty()) {
        Fail(ErrorCode::kInvalidArgument, "species", "must name the species the policy is for");
    }
    if (policy.instanceTypes.empty()) {
        Fail(ErrorCode::kInvalidArgument, "instance_types",
             "names no node type: no structure could be an instance");
    }
    std::set<NodeType> types;
    for (std::size_t i = 0; i < policy.instanceTypes.size(); ++i) {
        const NodeType type = policy.instanceTypes[i];
        const std::string field = "instance_types[" + std::to_string(i) + "]";
        // A leaf is the organ instances are made of (§4.3), not a structure of organs.
        if (type == NodeType::kLeaf) {
            Fail(ErrorCode::kInvalidArgument, field, "a leaf is an organ, not a structure");
        }
        if (!types.insert(type).second) {
            Fail(ErrorCode::kAlreadyExists, field,
                 std::string("names ") + NodeTypeName(type) + " twice");
        }
    }
    ValidateBins(policy.leafCount, "leaf_count", true);
    ValidateBins(policy.age, "age", false);
    ValidateBins(policy.inclination, "inclination", false);
    for (std::size_t i = 0; i < policy.inclination.edges.size(); ++i) {
        if (policy.inclination.edges[i] < 0.0 || policy.inclination.edges[i] > 180.0) {
            Fail(ErrorCode::kInvalidArgument, "inclination.edges[" + std::to_string(i) + "]",
                 "lies outside 0 to 180 degrees: an angle from the world's up");
        }
    }
    std::set<std::string> names;
    for (std::size_t i = 0; i < policy.attributes.size(); ++i) {
        const AttributeBins& attribute = policy.attributes[i];
        if (attribute.name.empty()) {
            Fail(ErrorCode::kInvalidArgument, "attributes[" + std::to_string(i) + "].name",
                 "must name a node attribute");
        }
        const std::string field = "attributes[" + attribute.name + "]";
        // Names stand in signatures ("order[1,2)"): no separators or brackets in them.
        if (attribute.name.find_first_of("|[](), \t\n") != std::string::npos) {
            Fail(ErrorCode::kInvalidArgument, field + ".name",
                 "may not hold '|', brackets, parentheses, commas or spaces: it is part of "
                 "signatures");
        }
        if (!names.insert(attribute.name).second) {
            Fail(ErrorCode::kAlreadyExists, field + ".name", "is binned twice");
        }
        if (!attribute.bins.Used()) {
            Fail(ErrorCode::kInvalidArgument, field + ".edges",
                 "is empty: a named attribute needs its bins");
        }
        ValidateBins(attribute.bins, field, false);
    }
    if (!policy.byType && !policy.leafCount.Used() && !policy.age.Used() &&
        !policy.inclination.Used() && policy.attributes.empty()) {
        Fail(ErrorCode::kInvalidArgument, "by_type",
             "is false and no value is binned: the signature would be made of nothing");
    }
    std::set<NodeType> capped;
    for (std::size_t i = 0; i < policy.fixed.size(); ++i) {
        const FixedFunction& cap = policy.fixed[i];
        const std::string field = "fixed[" + std::to_string(i) + "]";
        if (!policy.IsInstanceType(cap.type)) {
            Fail(ErrorCode::kNotFound, field + ".type",
                 std::string(NodeTypeName(cap.type)) + " is not one of instance_types");
        }
        if (!capped.insert(cap.type).second) {
            Fail(ErrorCode::kAlreadyExists, field + ".type",
                 std::string("caps ") + NodeTypeName(cap.type) + " twice");
        }
        if (cap.leafCountAbove < 1) {
            Fail(ErrorCode::kInvalidArgument, field + ".leaf_count_above",
                 "must be at least 1, got " + std::to_string(cap.leafCountAbove));
        }
    }
    ValidateResolution(policy.phase, "phase");
    ValidateResolution(policy.transmittance, "transmittance");
    // τ(ω) is a function of one direction (§4.2.1): there is no bi-directional one.
    if (policy.transmittance.kind == PhaseKind::kBiDirectional) {
        Fail(ErrorCode::kInvalidArgument, "transmittance.kind",
             "must be constant or mono: a transmittance depends on one direction");
    }
}

std::string PolicyContentHash(const InstancingPolicy& policy) {
    ContentHash hash;
    hash.Add(std::string_view("leaflux.InstancingPolicy.1"));
    hash.Add(std::string_view(policy.species));
    std::vector<int> types;
    for (const NodeType type : policy.instanceTypes) types.push_back(static_cast<int>(type));
    std::sort(types.begin(), types.end());
    hash.Add(static_cast<std::uint64_t>(types.size()));
    for (const int type : types) hash.Add(type);
    hash.Add(static_cast<int>(policy.byType));
    AddBins(hash, policy.leafCount);
    AddBins(hash, policy.age);
    if (policy.inclination.Used()) AddBins(hash, policy.inclination);  // older policies' hash kept
    std::vector<const AttributeBins*> attributes;
    for (const AttributeBins& attribute : policy.attributes) attributes.push_back(&attribute);
    std::sort(attributes.begin(), attributes.end(),
              [](const auto* a, const auto* b) { return a->name < b->name; });
    hash.Add(static_cast<std::uint64_t>(attributes.size()));
    for (const AttributeBins* attribute : attributes) {
        hash.Add(std::string_view(attribute->name));
        AddBins(hash, attribute->bins);
    }
    std::vector<std::pair<int, std::int64_t>> caps;
    for (const FixedFunction& cap : policy.fixed) {
        caps.emplace_back(static_cast<int>(cap.type), cap.leafCountAbove);
    }
    std::sort(caps.begin(), caps.end());
    hash.Add(static_cast<std::uint64_t>(caps.size()));
    for (const auto& [type, leaves] : caps) hash.Add(type).Add(leaves);
    for (const FunctionResolution* resolution : {&policy.phase, &policy.transmittance}) {
        hash.Add(static_cast<int>(resolution->kind)).Add(EffectiveLevel(*resolution));
    }
    return hash.Hex();
}

}  // namespace leaflux
