// The link audit (HrcOptions::auditLinks): what the links of each kind hand on, against what
// cosine-distributed rays from every leaf patch side find where a link of that kind covers
// the point hit — a Monte Carlo estimate of the same exchanges (LinkAudit). It shows which
// kind of link loses or makes light, where the energy balance shows only that some does.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "solver/radiosity/light_state.h"
#include "solver/radiosity/links.h"
#include "solver/radiosity/node_model.h"
#include "solver/raytrace/raytrace.h"
#include "solver/results/light.h"

namespace leaflux {

// `collect` gathers and pushes down the light of the links as they then are (without the
// light of the directional sources, which the audit takes off and puts back); the links,
// the source light and the leaf light are as they were when it returns.
std::vector<LinkAudit> AuditLinks(const NodeModel& model, const RayScene& rays,
                                  const std::vector<std::uint32_t>& leaves, const Field& field,
                                  Links& links, SourceLight& sources, LeafLight& leafLight,
                                  const std::function<void()>& collect);

}  // namespace leaflux
