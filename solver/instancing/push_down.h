// The light of a structure solved whole handed down to its organs (InstancedOptions::
// pushDown): the "leaf results pushed down from the structure's solution", an
// approximation, for when opening stops at a depth or a structure type and the leaves'
// light is still wanted for little more time.
//
// A structure solved whole knows the light that arrived on its box, by direction, and what
// it absorbed of it (its original's absorption, InstancedSolve::SolveWhole). Each organ's
// triangles get from each arrival the irradiance on the side facing it, |n · ω| e, times
// what the structure lets through from the box's side the light enters by to the triangle:
// τ(ω) to the power of the share of the line through the box it crosses before it, as
// through a uniform medium whose whole chord passes τ. That is the light straight from the
// box's sides (the neighbours' scattered light among it). What the structure absorbs
// beyond what that light makes its organs absorb, the light they scatter onto one another,
// is handed to both sides of every organ alike. The organs absorb, together, at least what
// the structure does: more where the straight light already makes them absorb more (the
// structure's absorption, from its representative's phase-function computation, is not
// forced onto them). Their light vectors are the structure's.
//
// What it does not know: where the neighbours' shadows fall on the box (the light on it is
// taken as even over it), which organs shade which beyond the mean τ, and where the
// scattered light goes. The results' `output=axis pushed-down` rows measure it against the
// Monte Carlo reference (docs/solvers.md).
#pragma once

#include <functional>
#include <span>
#include <vector>

#include "solver/radiosity/closed_node.h"
#include "solver/results/light.h"
#include "solver/scene/geometry.h"
#include "solver/scene/scene.h"

namespace leaflux {

// Light arriving on a structure's box from one direction.
struct Arrival {
    glm::dvec3 toward{0.0};          // the structure's frame, unit: where the light comes from
    std::vector<double> irradiance;  // W/m² normal to it, by band
};

// Per receiver of `organs` (the structure's organs flattened in its own frame: its triangles
// plus FlatScene::origin are in the frame of `closed`'s box), its light by band. `tau`: the
// structure's transmittance towards a direction of its frame; `structure`: its light solved
// whole, by band (absorbed power, light vector); `optics`: the scene's.
std::vector<std::vector<BandLight>> PushDown(const FlatScene& organs, const ClosedNode& closed,
                                             const std::function<double(const glm::dvec3&)>& tau,
                                             std::span<const Arrival> arrivals,
                                             std::span<const BandLight> structure,
                                             const std::vector<Optics>& optics);

}  // namespace leaflux
