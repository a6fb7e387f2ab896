// `leaflux policy check`: the groups a policy makes of a scene's structures (Soler 2003
// §4.1), so a user fitting a policy to a species can see which structures would share an
// original, how many there are, and which one each original is computed from.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <iosfwd>
#include <string>

namespace leaflux {

struct PolicyCheckCommand {
    std::string policy;  // policy file (leaflux.v1.InstancingPolicy, text format)
    std::string scene;   // scene file; empty: a generated tree of `leaves` leaves
    int leaves = 1000;
    std::uint64_t seed = 1;
    bool allMembers = false;  // every member's id, not the first few
};

// Registers `policy check` under `app`; returns the `check` subcommand.
CLI::App* AddPolicyCommand(CLI::App& app, PolicyCheckCommand& command);

// Prints the policy, then each group: signature, member count and ids, leaf counts
// (min / median / max), representative; then the structures no bin holds, and why.
// Throws InputError for a bad policy or scene; returns the process exit code.
int RunPolicyCheck(const PolicyCheckCommand& command, std::ostream& out);

}  // namespace leaflux
