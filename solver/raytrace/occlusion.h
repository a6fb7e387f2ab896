// Visibility through closed instances (Soler 2003 §4.3, last paragraph): a closed instance
// has no geometry loaded, only a bounding box and a directional transmittance τ(ω) in its
// own frame, so a ray through it is attenuated, not blocked. Occlusion answers what fraction
// of light passes along a segment: 0 when a triangle of the ray scene is in the way, else
// the product of τ over the closed instances it crosses, each counted once.
//
// Debian's Embree 3.13 is built with one instance level, which periodic scenes use, so the
// closed instances are Embree user geometries (oriented boxes), traced apart from the
// triangles; opened contents are reached by recursion, not by nested Embree instances. At a
// high build quality a primitive's callback may fire more than once along a ray: each
// instance is multiplied in once. A segment that starts or ends inside a box takes
// τ(ω)^(its length inside / the line's whole chord), so that a full crossing takes exactly
// τ(ω), the mean unoccluded fraction of parallel rays through the box.
//
// Committed once in its constructor and read-only afterwards: trace it from any thread.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "solver/raytrace/raytrace.h"

namespace leaflux {

// A closed instance as rays see it. Frames: the instance's own, and the ray scene's (the
// flat scene's local frame).
struct ClosedProxy {
    glm::dmat4 sceneFromInstance{1.0};
    glm::dvec3 boxMin{0.0}, boxMax{0.0};  // in the instance's frame
    // τ(ω) ∈ [0, 1] of a unit direction ω in the instance's frame.
    std::function<double(const glm::dvec3&)> transmittance;
};

class Occlusion {
  public:
    // `quality`: Embree's build quality of the boxes' hierarchy (the answer does not depend
    // on it).
    Occlusion(const RayScene& triangles, std::vector<ClosedProxy> proxies,
              RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH,
              std::shared_ptr<RayDevice> device = RayDevice::Shared());
    ~Occlusion();
    Occlusion(const Occlusion&) = delete;
    Occlusion& operator=(const Occlusion&) = delete;

    // The fraction of light passing from start along `direction` (unit) for maxDistance:
    // 0 behind a triangle, else the product of τ of the closed instances crossed, but those
    // listed in `exclude` (indices into the proxies: a link's own ends and the instances
    // open around them).
    double Transmittance(const RayStart& start, const glm::dvec3& direction,
                         double maxDistance = std::numeric_limits<double>::infinity(),
                         std::span<const std::uint32_t> exclude = {}) const {
        if (triangles_.Occluded(start, direction, maxDistance)) return 0.0;
        return boxes_.empty() ? 1.0 : ThroughBoxes(start, direction, maxDistance, exclude);
    }

    std::size_t ProxyCount() const { return proxies_.size(); }
    const RayScene& Triangles() const { return triangles_; }

  private:
    struct Box {
        glm::dmat4 instanceFromScene;
        glm::dvec3 boxMin, boxMax;
        glm::dvec3 lower, upper;  // bounds in the ray scene's frame
    };
    friend struct ProxyQuery;
    // The product of τ along a segment that no triangle blocks.
    double ThroughBoxes(const RayStart& start, const glm::dvec3& direction, double maxDistance,
                        std::span<const std::uint32_t> exclude) const;
    static void Bounds(const RTCBoundsFunctionArguments* args);
    static void Crossed(const RTCOccludedFunctionNArguments* args);
    static void CrossedIntersect(const RTCIntersectFunctionNArguments* args);

    const RayScene& triangles_;
    std::vector<ClosedProxy> proxies_;
    std::vector<Box> boxes_;
    std::shared_ptr<RayDevice> device_;
    RTCScene scene_ = nullptr;
};

}  // namespace leaflux
