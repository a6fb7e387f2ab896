// Conversion from the policy file schema (leaflux.v1.InstancingPolicy, leaflux.proto) to the
// solver's InstancingPolicy (solver/instancing/policy.h).
//
// PolicyFromProto checks what only the schema can get wrong (an unspecified node type or
// function kind, a direction count no set has, a newer version) and then runs
// ValidatePolicy: a policy it returns is valid. Errors are InputError naming the field.
#pragma once

#include <string>

#include "leaflux.pb.h"
#include "solver/instancing/policy.h"

namespace leaflux {

InstancingPolicy PolicyFromProto(const v1::InstancingPolicy& message);

// A function's kind and direction set; errors name `field` (".kind", ".direction_count").
// Its level's range is ValidatePolicy's to check.
FunctionResolution ResolutionFromProto(const v1::FunctionResolution& in, const std::string& field);

// Reads a policy file in protobuf text format. An unreadable file is kIo naming the path;
// a parse error or an unknown field is kParse naming "path:line:column"; a policy that
// parses but is not usable is the InputError of PolicyFromProto, naming the field.
InstancingPolicy LoadPolicyFile(const std::string& path);

// proto/policies/default.txtpb, built in: for a species no policy has been fitted to.
InstancingPolicy DefaultPolicy();

}  // namespace leaflux
