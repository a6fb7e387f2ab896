// A plant structure alone, in its own frame (Soler 2003 §4.2.3: "we stimulate the
// geometry ... inside the geometry"): the organs of one scene node's subtree, placed by
// their frames below that node, with the scene's bands and optics and nothing else — no
// environment, no sources, no other plant. Its directional functions are computed on it.
//
// Frames: the structure's frame is its root node's local frame (z along the main axis,
// DESIGN §2), so that one original serves every instance whatever its placement;
// worldFromInstance is the root's worldFromLocal. The flat scene stores positions relative
// to its own origin (FlatScene), which is `Origin()` in the structure's frame.
//
// Invariant: the box holds every triangle, padded so that no side is flat (a single flat
// leaf has a box light can cross edge-on) and no triangle touches a side.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <string>

#include "solver/raytrace/raytrace.h"
#include "solver/scene/scene.h"

namespace leaflux {

class StructureAlone {
  public:
    // The subtree under scene node `root` of a validated scene; throws InputError
    // (kNotFound) naming `root` when it is no node, (kDegenerate) when no organ lies under it.
    StructureAlone(const Scene& scene, NodeId root);
    StructureAlone(const StructureAlone&) = delete;
    StructureAlone& operator=(const StructureAlone&) = delete;

    const Scene& Alone() const { return alone_; }
    const FlatScene& Flat() const { return flat_; }
    const RayScene& Rays() const { return *rays_; }
    const std::string& Name() const { return name_; }
    std::int64_t LeafCount() const { return leafCount_; }
    double LeafAreaM2() const { return leafAreaM2_; }

    // The box, in the flat scene's frame and in the structure's.
    glm::dvec3 BoxMin() const { return boxMin_; }
    glm::dvec3 BoxMax() const { return boxMax_; }
    glm::dvec3 Origin() const { return flat_.origin; }

    // The box's area seen along unit `direction` (m²): its cross-section for a beam.
    double ProjectedArea(const glm::dvec3& direction) const;
    // A point where a ray along unit `direction` enters the box, uniform over the box's
    // projection for u in [0, 1)³ (flat scene frame).
    glm::dvec3 Entry(const glm::dvec3& direction, double u1, double u2, double u3) const;

  private:
    Scene alone_;
    FlatScene flat_;
    std::unique_ptr<RayScene> rays_;
    std::string name_;
    std::int64_t leafCount_ = 0;
    double leafAreaM2_ = 0.0;
    glm::dvec3 boxMin_{0.0}, boxMax_{0.0};
};

}  // namespace leaflux
