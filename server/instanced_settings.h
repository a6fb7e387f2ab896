// A daemon session's instanced solver (leaflux.v1.InstancedSettings): its policy, found by
// name or species in the daemon's policy folder or sent inline, with the session's function
// kinds and resolutions over the policy's, and where opening stops. Checked whole when the
// session opens: a session never holds settings its solves would refuse.
#pragma once

#include <string>

#include "leaflux.pb.h"
#include "solver/instancing/instanced.h"
#include "solver/instancing/policy.h"

namespace leaflux {

struct InstancedRun {
    // Its species the session's (OpenSession.species), else the policy's own: the
    // database keeps the functions of a species apart from the others'.
    InstancingPolicy policy;
    // All but `hrc`, which the session's solver settings give at each solve.
    InstancedOptions options;
    bool singleValue = false;       // HrcOptions::directionalInstances off
    bool shadowsByGeometry = true;  // INSTANCED_SHADOWS_GEOMETRY
    std::string policySource;       // "inline", "default", or the file read: for the log
};

// Throws InputError naming the field under "settings.instanced" (or the policy file's
// line): an unknown policy name is kNotFound; a name that is not a plain file name (a
// path, "..") kInvalidArgument. `policyDir`: where policies are found by name
// (DIR/<name>.txtpb) and by species; "" none, and then only the built-in general policy
// and inline ones are known.
InstancedRun InstancedRunFromProto(const v1::InstancedSettings& in, const std::string& species,
                                   const std::string& policyDir);

}  // namespace leaflux
