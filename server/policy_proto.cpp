#include "server/policy_proto.h"

#include <google/protobuf/text_format.h>

#include <array>

#include "server/default_policy.h"
#include "server/scene_proto.h"
#include "server/text_format.h"
#include "solver/util/check.h"
#include "solver/util/directions.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

[[noreturn]] void Fail(ErrorCode code, const std::string& field, const std::string& message) {
    throw InputError(code, field, message);
}

// The inverse of TypeToProto; NODE_TYPE_UNSPECIFIED names no type.
NodeType TypeFromPolicy(int type, const std::string& field) {
    constexpr std::array kTypes{NodeType::kPlant, NodeType::kAxis,      NodeType::kPhytomer,
                                NodeType::kLeaf,  NodeType::kInternode, NodeType::kFruit,
                                NodeType::kOther};
    for (const NodeType candidate : kTypes) {
        if (TypeToProto(candidate) == type) return candidate;
    }
    Fail(ErrorCode::kInvalidArgument, field, "must name a node type (NODE_TYPE_PLANT, …)");
}

// Bins that are stated must hold edges: `leaf_count {}` is an empty set of bins, not a
// way to leave the leaf count out of the signature (leaving the field out is).
Bins BinsFromProto(bool stated, const v1::Bins& bins, const std::string& field) {
    if (stated && bins.edges().empty()) {
        Fail(ErrorCode::kInvalidArgument, field + ".edges", "is empty: state the bins' edges");
    }
    return Bins{std::vector<double>(bins.edges().begin(), bins.edges().end())};
}

}  // namespace

FunctionResolution ResolutionFromProto(const v1::FunctionResolution& in, const std::string& field) {
    FunctionResolution out;
    switch (in.kind()) {
        case v1::FUNCTION_KIND_CONSTANT:
            out.kind = PhaseKind::kConstant;
            break;
        case v1::FUNCTION_KIND_MONO:
            out.kind = PhaseKind::kMonoDirectional;
            break;
        case v1::FUNCTION_KIND_BI:
            out.kind = PhaseKind::kBiDirectional;
            break;
        default:
            Fail(ErrorCode::kInvalidArgument, field + ".kind",
                 "must be FUNCTION_KIND_CONSTANT, FUNCTION_KIND_MONO or FUNCTION_KIND_BI");
    }
    switch (in.directions_case()) {
        case v1::FunctionResolution::kLevel:
            out.level = in.level();  // ValidatePolicy checks its range
            break;
        case v1::FunctionResolution::kDirectionCount:
            out.level = DirectionSet::LevelWithCount(in.direction_count());
            if (out.level < 0) {
                Fail(ErrorCode::kInvalidArgument, field + ".direction_count",
                     "must be 4, 10, 34, 130 or 514, got " + std::to_string(in.direction_count()));
            }
            break;
        default:
            if (out.kind != PhaseKind::kConstant) {
                Fail(ErrorCode::kInvalidArgument, field,
                     "states no level or direction_count for a directional function");
            }
            out.level = 0;
    }
    return out;
}

InstancingPolicy PolicyFromProto(const v1::InstancingPolicy& message) {
    if (message.version() > v1::PROTOCOL_VERSION_CURRENT) {
        Fail(ErrorCode::kUnsupported, "version", "is newer than this leaflux understands");
    }
    if (message.version() < 0) {
        Fail(ErrorCode::kInvalidArgument, "version",
             "must be PROTOCOL_VERSION_CURRENT (1) or unset");
    }
    InstancingPolicy policy;
    policy.species = message.species();
    for (int i = 0; i < message.instance_types_size(); ++i) {
        policy.instanceTypes.push_back(
            TypeFromPolicy(message.instance_types(i), "instance_types[" + std::to_string(i) + "]"));
    }
    policy.byType = message.by_type();
    policy.leafCount = BinsFromProto(message.has_leaf_count(), message.leaf_count(), "leaf_count");
    policy.age = BinsFromProto(message.has_age(), message.age(), "age");
    policy.inclination =
        BinsFromProto(message.has_inclination(), message.inclination(), "inclination");
    for (const v1::AttributeBins& attribute : message.attributes()) {
        policy.attributes.push_back(
            {attribute.name(), Bins{{attribute.edges().begin(), attribute.edges().end()}}});
    }
    for (int i = 0; i < message.fixed_size(); ++i) {
        const v1::FixedFunction& cap = message.fixed(i);
        const std::string field = "fixed[" + std::to_string(i) + "]";
        policy.fixed.push_back(
            {TypeFromPolicy(cap.type(), field + ".type"), cap.leaf_count_above()});
    }
    if (!message.has_phase()) Fail(ErrorCode::kInvalidArgument, "phase", "must be stated");
    if (!message.has_transmittance()) {
        Fail(ErrorCode::kInvalidArgument, "transmittance", "must be stated");
    }
    policy.phase = ResolutionFromProto(message.phase(), "phase");
    policy.transmittance = ResolutionFromProto(message.transmittance(), "transmittance");
    ValidatePolicy(policy);
    return policy;
}

InstancingPolicy LoadPolicyFile(const std::string& path) {
    v1::InstancingPolicy message;
    if (const auto error = ReadTextFormat(path, message)) {
        Fail(error->unreadable ? ErrorCode::kIo : ErrorCode::kParse, error->where,
             error->unreadable ? "cannot open the policy file" : error->what);
    }
    return PolicyFromProto(message);
}

InstancingPolicy DefaultPolicy() {
    v1::InstancingPolicy message;
    LEAFLUX_CHECK(google::protobuf::TextFormat::ParseFromString(kDefaultPolicyText, &message));
    return PolicyFromProto(message);
}

}  // namespace leaflux
