// A closed instance (Soler 2003 §3.2, §4): a structure whose geometry is not loaded, known
// by what it does to light — its directional transmittance τ(ω) and its phase function
// f(ωi, ωo) — and where it is (a box in its own frame and sceneFromInstance). It sits in a
// hierarchy as a node without children: links reach it, its intensity is what its phase
// function makes of the light arriving on it, rays through it are attenuated by τ, and
// nothing is refined into it, nor does it link to itself (its phase function holds its
// inner scattering).
#pragma once

#include <glm/glm.hpp>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "solver/raytrace/occlusion.h"
#include "solver/scene/scene.h"
#include "solver/util/area_grid.h"

namespace leaflux {

class ClosedContents {
  public:
    virtual ~ClosedContents() = default;
    // τ(ω): the fraction of parallel light along unit ω (instance frame) that crosses the
    // box without meeting the structure.
    virtual double Transmittance(const glm::dvec3& omega) const = 0;
    // f(ωi, ωo) in band b: the intensity (W/sr) leaving towards unit ωo per unit irradiance
    // (W/m², normal to the beam) arriving from unit ωi (towards the source), both in the
    // instance frame. It holds the structure's area intercepting ωi and every scattering
    // inside it.
    virtual double Phase(int band, const glm::dvec3& towardSource,
                         const glm::dvec3& outgoing) const = 0;
    // f for every pair: table[o * towardSources.size() + i] = Phase(band, towardSources[i],
    // outgoing[o]).
    virtual void PhaseTable(int band, std::span<const glm::dvec3> towardSources,
                            std::span<const glm::dvec3> outgoing, double* table) const {
        for (std::size_t o = 0; o < outgoing.size(); ++o) {
            for (std::size_t i = 0; i < towardSources.size(); ++i)
                table[o * towardSources.size() + i] = Phase(band, towardSources[i], outgoing[o]);
        }
    }
};

struct ClosedNode {
    std::string name;
    glm::dmat4 sceneFromInstance{1.0};    // into the flat scene's local frame
    glm::dvec3 boxMin{0.0}, boxMax{0.0};  // in the instance frame
    double areaM2 = 0.0;                  // the structure's leaf area, one side
    NodeId parent = kNoParent;            // the scene node it hangs under, or the top of the scene
    std::shared_ptr<const ClosedContents> contents;
    // A closed instance of a level further out, held as it was solved there (an opened
    // instance's sibling, Soler 2003 §3.4's link copies): the intensity it sends per bin of
    // the cluster light's set and channel, [bin][channel] in W/sr. It sends that, receives
    // nothing, and is not in the rays' scene (its proxy is the level's that holds it).
    std::vector<double> held;
    // Held: per direction of the cluster light's set (the way the light goes), the box's mean
    // optical depth along it (HeldDepths), which every receiver of its light from all around
    // takes (HeldAroundLinks).
    std::vector<double> heldDepth;
    // Its organs' triangles in the whole scene's shadow engine (ShadowView), when it has
    // one: what its intensity already lost to them is not lost again (HeldAroundLinks).
    std::shared_ptr<const RayScene::TriangleRanges> shadowTriangles;
    // Where its organs lie in its box, when known; else its light leaves evenly from the box.
    std::shared_ptr<const AreaGrid> organArea;
    // Opened once its level is solved: what leaves the scene from it is counted from its
    // organs (the energy balance), not from what its phase function sends.
    bool opens = false;
    // Opened, or left closed by the view alone (InstancedOptions::inView): its organs take
    // the suns and sky again, and its links from them set only what it scatters here, judged
    // as any node's (refinement.cpp), where one solved whole takes as many rays as bring its
    // structure's light within ε. The view does not count, so that the light of the
    // instances opened does not depend on which others are.
    bool relit = false;

    bool Held() const { return !held.empty(); }

    // Its box as rays see it.
    ClosedProxy Proxy() const {
        return {sceneFromInstance, boxMin, boxMax, [contents = contents](const glm::dvec3& omega) {
                    return contents->Transmittance(omega);
                }};
    }
    // The box's area projected along unit ω in the scene's frame, both sides together
    // halved: Σ over its three axes of |ω · n_i| times the face's area.
    double BoxProjectedArea(const glm::dvec3& omega) const {
        const glm::dmat3 linear(sceneFromInstance);
        const glm::dvec3 size = boxMax - boxMin;
        const glm::dvec3 e[3] = {linear[0] * size.x, linear[1] * size.y, linear[2] * size.z};
        double area = 0.0;
        for (int i = 0; i < 3; ++i)
            area += std::abs(glm::dot(glm::cross(e[(i + 1) % 3], e[(i + 2) % 3]), omega));
        return area;
    }
    // A direction of the scene's frame in the instance's, unit.
    glm::dvec3 ToInstance(const glm::dvec3& omega) const {
        return glm::normalize(glm::inverse(glm::dmat3(sceneFromInstance)) * omega);
    }
};

}  // namespace leaflux
