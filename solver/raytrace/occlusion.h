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
#include "solver/raytrace/sun_map.h"

namespace leaflux {

// A closed instance as rays see it. Frames: the instance's own, and the ray scene's (the
// flat scene's local frame).
struct ClosedProxy {
    glm::dmat4 sceneFromInstance{1.0};
    glm::dvec3 boxMin{0.0}, boxMax{0.0};  // in the instance's frame
    // τ(ω) ∈ [0, 1] of a unit direction ω in the instance's frame.
    std::function<double(const glm::dvec3&)> transmittance;
};

class Occlusion;

// What lies outside a local problem (an opened instance, Soler 2003 §3.4): the occlusion of
// the level it was opened in, its own proxy left out, so that rays from the opened contents
// still meet the rest of the scene — that level's triangles, its closed instances, and what
// lies outside it in turn. Each level keeps its own flat scene's origin (far-from-origin
// scenes keep their precision): a local point p is at p + offset in the outside's frame.
struct OutsideView {
    const Occlusion* occlusion = nullptr;
    std::vector<std::uint32_t> exclude;  // its proxies open around the local problem
    glm::dvec3 offset{0.0};              // a point of the local frame is at p + offset there
};

// The whole scene's triangles, which the rays of the suns and sky cones from a level's
// triangles meet instead of the levels' closed instances: exact shadows where the
// transmittance of a closed instance would give its mean (Soler 2003 §4.3). A level's
// triangle t is the whole scene's triangleOf[t]; a local point p is at p + offset there.
struct ShadowView {
    const RayScene* rays = nullptr;
    std::vector<std::uint32_t> triangleOf;
    glm::dvec3 offset{0.0};
    std::uint32_t organTriangles = 0;  // the whole scene's first triangles are its organs'
    const SunMaps* suns = nullptr;     // the suns' light on those organs, where drawn
};

class Occlusion {
  public:
    // `quality`: Embree's build quality of the boxes' hierarchy (the answer does not depend
    // on it).
    Occlusion(const RayScene& triangles, std::vector<ClosedProxy> proxies,
              RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH,
              std::shared_ptr<RayDevice> device = RayDevice::Shared());
    // A local problem's: its own triangles and closed instances, then what lies outside; and
    // the whole scene's triangles for direct light, when `shadows` has them.
    Occlusion(const RayScene& triangles, std::vector<ClosedProxy> proxies, OutsideView outside,
              ShadowView shadows = {});
    ~Occlusion();
    Occlusion(const Occlusion&) = delete;
    Occlusion& operator=(const Occlusion&) = delete;

    // The fraction of light passing from start along `direction` (unit) for maxDistance:
    // 0 behind a triangle, else the product of τ of the closed instances crossed, but those
    // listed in `exclude` (indices into the proxies: a link's own ends and the instances
    // open around them).
    // With an outside view, the light must pass the outside as well.
    double Transmittance(const RayStart& start, const glm::dvec3& direction,
                         double maxDistance = std::numeric_limits<double>::infinity(),
                         std::span<const std::uint32_t> exclude = {}) const {
        const double local = LocalTransmittance(start, direction, maxDistance, exclude);
        if (local <= 0.0 || outside_.occlusion == nullptr) return local;
        // Nothing of the local problem is in the outside's scene: no triangle to skip.
        const RayStart there{start.origin + outside_.offset};
        return local *
               outside_.occlusion->Transmittance(there, direction, maxDistance, outside_.exclude);
    }
    // The same through the local problem's own triangles and closed instances alone.
    double LocalTransmittance(const RayStart& start, const glm::dvec3& direction,
                              double maxDistance = std::numeric_limits<double>::infinity(),
                              std::span<const std::uint32_t> exclude = {}) const {
        if (triangles_.Occluded(start, direction, maxDistance)) return 0.0;
        return boxes_.empty() ? 1.0 : ThroughBoxes(start, direction, maxDistance, exclude);
    }

    // Where the line from `origin` along `direction` (unit) is inside closed instance c's
    // box: from enter to exit, distances along the direction (exit ≤ enter: it misses), and
    // the direction in the instance's frame (unit; zero when it misses).
    struct Chord {
        double enter, exit;
        glm::dvec3 direction;
    };
    Chord ChordOf(std::uint32_t c, const glm::dvec3& origin, const glm::dvec3& direction) const;
    // Point x of the scene in closed instance c's frame.
    glm::dvec3 InInstance(std::uint32_t c, const glm::dvec3& x) const {
        return glm::dvec3(boxes_[c].instanceFromScene * glm::dvec4(x, 1.0));
    }

    std::size_t ProxyCount() const { return proxies_.size(); }
    // A local problem's, with the level it was opened in around it.
    bool HasOutside() const { return outside_.occlusion != nullptr; }
    const ShadowView& Shadows() const { return shadows_; }
    // Triangles alone, nothing outside: a ray passes or not (traced in batches).
    bool TrianglesOnly() const { return proxies_.empty() && outside_.occlusion == nullptr; }
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
    OutsideView outside_;
    ShadowView shadows_;
    std::vector<Box> boxes_;
    std::shared_ptr<RayDevice> device_;
    RTCScene scene_ = nullptr;
};

}  // namespace leaflux
