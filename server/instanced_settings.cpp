#include "server/instanced_settings.h"

#include <filesystem>

#include "server/policy_proto.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

constexpr const char* kField = "settings.instanced";

// Runs `read`, its InputError's field put under `prefix`.
template <typename Read>
auto Under(const std::string& prefix, Read read) {
    try {
        return read();
    } catch (const InputError& e) {
        throw InputError(e.Code(), e.Field().empty() ? prefix : prefix + "." + e.Field(),
                         e.Message(), e.Node());
    }
}

// A policy name or species as a file name: letters, digits, '_', '-' and inner dots.
bool PlainName(const std::string& name) {
    if (name.empty() || name.size() > 128 || name.front() == '.') return false;
    for (const char c : name) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                        (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
        if (!ok) return false;
    }
    return name.find("..") == std::string::npos;
}

InstancingPolicy FindPolicy(const v1::InstancedSettings& in, const std::string& species,
                            const std::string& policyDir, std::string& source) {
    namespace fs = std::filesystem;
    switch (in.policy_case()) {
        case v1::InstancedSettings::kInlinePolicy:
            source = "inline";
            return Under(std::string(kField) + ".inline_policy",
                         [&] { return PolicyFromProto(in.inline_policy()); });
        case v1::InstancedSettings::kPolicyName: {
            const std::string field = std::string(kField) + ".policy_name";
            const std::string& name = in.policy_name();
            if (!PlainName(name)) {
                throw InputError(
                    ErrorCode::kInvalidArgument, field,
                    "must be a policy's name (letters, digits, '_', '-', '.'), got \"" + name +
                        "\"");
            }
            const fs::path file = fs::path(policyDir) / (name + ".txtpb");
            std::error_code error;
            if (policyDir.empty() || !fs::is_regular_file(file, error)) {
                throw InputError(ErrorCode::kNotFound, field,
                                 "names no policy the daemon knows (\"" + name + "\"; " +
                                     (policyDir.empty() ? std::string("it was started without "
                                                                      "--policy-dir")
                                                        : "no " + file.string()) +
                                     ")");
            }
            source = file.string();
            return LoadPolicyFile(file.string());
        }
        default:
            break;
    }
    if (!policyDir.empty() && PlainName(species)) {
        const fs::path file = fs::path(policyDir) / (species + ".txtpb");
        std::error_code error;
        if (fs::is_regular_file(file, error)) {
            source = file.string();
            return LoadPolicyFile(file.string());
        }
    }
    source = "default";
    return DefaultPolicy();
}

}  // namespace

InstancedRun InstancedRunFromProto(const v1::InstancedSettings& in, const std::string& species,
                                   const std::string& policyDir) {
    InstancedRun run;
    run.policy = FindPolicy(in, species, policyDir, run.policySource);
    if (!species.empty()) run.policy.species = species;
    if (in.has_phase())
        run.policy.phase = ResolutionFromProto(in.phase(), std::string(kField) + ".phase");
    if (in.has_transmittance()) {
        run.policy.transmittance =
            ResolutionFromProto(in.transmittance(), std::string(kField) + ".transmittance");
    }
    if (in.has_phase() || in.has_transmittance())
        Under(kField, [&] { ValidatePolicy(run.policy); });
    if (in.max_depth() < 0 || in.max_depth() > 64) {
        throw InputError(ErrorCode::kInvalidArgument, std::string(kField) + ".max_depth",
                         "must be in [0, 64]");
    }
    run.options.maxDepth = in.max_depth();
    if (in.output_level() != v1::NODE_TYPE_UNSPECIFIED) {
        const std::string field = std::string(kField) + ".output_level";
        if (in.max_depth() > 0)
            throw InputError(ErrorCode::kInvalidArgument, field, "excludes max_depth");
        switch (in.output_level()) {
            case v1::NODE_TYPE_PLANT:
                run.options.outputLevel = NodeType::kPlant;
                break;
            case v1::NODE_TYPE_AXIS:
                run.options.outputLevel = NodeType::kAxis;
                break;
            case v1::NODE_TYPE_PHYTOMER:
                run.options.outputLevel = NodeType::kPhytomer;
                break;
            default:
                throw InputError(ErrorCode::kInvalidArgument, field,
                                 "must be NODE_TYPE_PLANT, NODE_TYPE_AXIS or NODE_TYPE_PHYTOMER");
        }
    }
    run.singleValue = in.single_value();
    run.options.holdOutside = !in.per_bin();
    if (in.push_down() && in.max_depth() == 0 && in.output_level() == v1::NODE_TYPE_UNSPECIFIED) {
        throw InputError(ErrorCode::kInvalidArgument, std::string(kField) + ".push_down",
                         "needs max_depth or output_level: without them no structure is "
                         "solved whole");
    }
    run.options.pushDown = in.push_down();
    if (in.merge_triangles() < 0 ||
        (in.merge_triangles() > 0 && in.output_level() != v1::NODE_TYPE_UNSPECIFIED)) {
        throw InputError(ErrorCode::kInvalidArgument, std::string(kField) + ".merge_triangles",
                         in.merge_triangles() < 0 ? "must be 0 or more" : "excludes output_level");
    }
    run.options.mergeTriangles = in.merge_triangles();
    switch (in.shadows()) {
        case v1::INSTANCED_SHADOWS_UNSPECIFIED:
        case v1::INSTANCED_SHADOWS_GEOMETRY:
            run.shadowsByGeometry = true;
            break;
        case v1::INSTANCED_SHADOWS_TRANSMITTANCE:
            run.shadowsByGeometry = false;
            break;
        default:
            throw InputError(ErrorCode::kInvalidArgument, std::string(kField) + ".shadows",
                             "must be INSTANCED_SHADOWS_GEOMETRY or _TRANSMITTANCE");
    }
    return run;
}

}  // namespace leaflux
