#include "server/policy_cli.h"

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <ostream>
#include <unordered_map>

#include "server/policy_proto.h"
#include "server/scene_proto.h"
#include "solver/generate/generator.h"
#include "solver/instancing/signature.h"

namespace leaflux {
namespace {

constexpr std::size_t kMembersShown = 8;

std::string ResolutionText(const FunctionResolution& resolution) {
    if (resolution.kind == PhaseKind::kConstant) return "constant";
    return std::string(PhaseKindName(resolution.kind)) + " " +
           std::to_string(DirectionSet::OfLevel(resolution.level).Size()) + " directions";
}

void PrintPolicy(const InstancingPolicy& policy, std::ostream& out) {
    out << "policy " << policy.species << " (content hash " << PolicyContentHash(policy)
        << ")\n  instance types:";
    for (const NodeType type : policy.instanceTypes) out << ' ' << NodeTypeName(type);
    out << "\n  signature:" << (policy.byType ? " type" : "");
    if (policy.leafCount.Used()) out << " leaf_count(" << policy.leafCount.Count() << " bins)";
    if (policy.age.Used()) out << " age(" << policy.age.Count() << " bins)";
    if (policy.inclination.Used()) out << " inclination(" << policy.inclination.Count() << " bins)";
    for (const AttributeBins& attribute : policy.attributes) {
        out << ' ' << attribute.name << '(' << attribute.bins.Count() << " bins)";
    }
    for (const FixedFunction& cap : policy.fixed) {
        out << "\n  fixed: " << NodeTypeName(cap.type) << " above " << cap.leafCountAbove
            << " leaves";
    }
    out << "\n  phase: " << ResolutionText(policy.phase)
        << "; transmittance: " << ResolutionText(policy.transmittance) << "\n";
}

Scene SceneOf(const PolicyCheckCommand& command, std::ostream& out) {
    if (!command.scene.empty()) {
        out << "scene " << command.scene << "\n";
        return LoadSceneFile(command.scene);
    }
    Scene scene;
    scene.bands = {{"PAR"}};
    scene.optics = {{"leaf", {{0.1, 0.1, 0.05, 0.05}}}, {"stem", {{0.3, 0.3, 0.0, 0.0}}}};
    TreeParameters tree;
    tree.leafCount = command.leaves;
    tree.seed = command.seed;
    AddTree(scene, tree, {0, 0, 0});
    scene.Validate();
    out << "scene: a generated tree of " << command.leaves << " leaves, seed " << command.seed
        << "\n";
    return scene;
}

// A median of leaf counts is a whole number or a half: "1000000", "12.5", never "1e+06".
std::string MedianText(double median) {
    const auto whole = static_cast<std::int64_t>(median);
    return std::to_string(whole) + (median > static_cast<double>(whole) ? ".5" : "");
}

}  // namespace

CLI::App* AddPolicyCommand(CLI::App& app, PolicyCheckCommand& command) {
    CLI::App* policyApp = app.add_subcommand("policy", "Instantiation policies");
    policyApp->require_subcommand(1);
    CLI::App* check = policyApp->add_subcommand(
        "check",
        "Validate a policy and print the groups it makes of a scene's structures: signature, "
        "members, leaf counts and the representative each group's original is computed from");
    check->add_option("--policy", command.policy, "Policy file (leaflux.v1.InstancingPolicy)")
        ->required()
        ->check(CLI::ExistingFile);
    check->add_option("--scene", command.scene, "Scene file (default: a generated tree)")
        ->check(CLI::ExistingFile);
    check->add_option("--leaves", command.leaves, "Leaves of the generated tree")
        ->check(CLI::Range(1, 10'000'000));
    check->add_option("--seed", command.seed, "Seed of the generated tree");
    check->add_flag("--all-members", command.allMembers,
                    "Every member's id (default: the first " + std::to_string(kMembersShown) + ")");
    return check;
}

int RunPolicyCheck(const PolicyCheckCommand& command, std::ostream& out) {
    const InstancingPolicy policy = LoadPolicyFile(command.policy);
    PrintPolicy(policy, out);
    const Scene scene = SceneOf(command, out);
    const auto start = std::chrono::steady_clock::now();
    const SceneSignatures signatures = ComputeSignatures(scene, policy);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::size_t unbinned = 0;
    for (const StructureSignature& s : signatures.structures) unbinned += s.signature.empty();
    out << signatures.structures.size() << " instantiable structures, " << signatures.groups.size()
        << " groups, " << unbinned << " in no bin (" << std::fixed << std::setprecision(3)
        << seconds << std::defaultfloat << " s)\n";
    std::unordered_map<NodeId, const Node*> nodes;
    for (const Node& node : scene.nodes) nodes.emplace(node.id, &node);
    for (const SignatureGroup& group : signatures.groups) {
        std::int64_t least = signatures.Find(group.members.front())->leafCount, most = least;
        for (const NodeId id : group.members) {
            least = std::min(least, signatures.Find(id)->leafCount);
            most = std::max(most, signatures.Find(id)->leafCount);
        }
        out << group.signature << "\n  "
            << "members " << group.members.size() << ", leaves " << least << " / "
            << MedianText(group.medianLeafCount) << " / " << most
            << " (min / median / max), representative "
            << scene.NodeName(*nodes.at(group.representative)) << " ("
            << signatures.Find(group.representative)->leafCount << " leaves)\n  ids:";
        const std::size_t shown = command.allMembers
                                      ? group.members.size()
                                      : std::min(group.members.size(), kMembersShown);
        for (std::size_t i = 0; i < shown; ++i) out << ' ' << group.members[i];
        if (shown < group.members.size()) out << " … (" << group.members.size() - shown << " more)";
        out << "\n";
    }
    for (const StructureSignature& s : signatures.structures) {
        if (s.signature.empty()) out << "in no bin: node " << s.id << " " << s.unbinned << "\n";
    }
    return 0;
}

}  // namespace leaflux
