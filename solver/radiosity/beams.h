// The light sources of the radiosity engine as cones of light (DirectionalSource): a
// scene's suns and sky cones, or unit beams (the phase functions'), and the maps of the
// suns over a scene's triangles (SunMap).
#pragma once

#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "solver/radiosity/channels.h"
#include "solver/radiosity/directional_source.h"
#include "solver/raytrace/sun_map.h"
#include "solver/scene/scene.h"

namespace leaflux {

// The suns and sky cones of a scene as cones of light, one channel per band; those that
// bring nothing are left out. A continuous sky is taken as `skyCones`.
std::vector<DirectionalSource> BeamsOf(const Scene& scene, SkyDiscretization skyCones);

// Unit parallel beams, one per direction: channels bands × beams, beam k lighting only its
// own channels, each judged as a scene of its own (kWorstBeam).
std::vector<DirectionalSource> UnitBeams(const Channels& channels,
                                         std::span<const glm::dvec3> towardSource);

// The maps of a whole scene's suns (those of `sources` whose links reach each organ), over
// the triangles of `rays`, numbered as `flat`'s; `wanted`: the organ triangles whose light
// is asked (SunMap), or empty for all.
SunMaps DrawSuns(const FlatScene& flat, const RayScene& rays,
                 std::span<const DirectionalSource> sources,
                 std::span<const std::uint8_t> wanted = {});

}  // namespace leaflux
