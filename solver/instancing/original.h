// An original (Soler 2003 §3.2, §4): what every instance of one signature shares — the
// structure's directional transmittance and phase function in its own frame, its box
// there, and where they came from. An instance adds only its transform.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <string>

#include "solver/instancing/directional.h"
#include "solver/radiosity/closed_node.h"

namespace leaflux {

// How an original's functions were computed, for the database and its users.
struct OriginalProvenance {
    std::string representative;  // the structure they came from: "plant 3 / axis 17"
    std::int64_t leafCount = 0;  // organs that carry light in it
    double leafAreaM2 = 0.0;     // one side
    std::string method;          // "mc" or "hr"
    double accuracy = 0.0;       // photons per beam (mc) or ε (hr)
    double computeSeconds = 0.0;
    // The standard error of τ and of f's scattered power, as fractions of their mean.
    double transmittanceRelativeError = 0.0;
    double phaseRelativeError = 0.0;
};

struct Original {
    glm::dvec3 boxMin{0.0}, boxMax{0.0};  // the structure's bounds in its frame (m)
    SphereFunction transmittance;         // τ(ω), one channel
    PhaseFunction phase;
    // The power the structure absorbs (W) per unit irradiance (W/m², normal to the beam)
    // arriving from ω, per band: what a structure solved whole absorbs (instanced.h).
    // Empty in an original of format 1.
    SphereFunction absorption;
    OriginalProvenance provenance;
};

// What a member of a signature group with organ area `areaM2` scales its group's original
// by: its area over the representative's.
inline double MemberScale(const Original& original, double areaM2) {
    return original.provenance.leafAreaM2 > 0.0 ? areaM2 / original.provenance.leafAreaM2 : 1.0;
}

// An original as the radiosity engine's closed nodes see it (closed_node.h). A member of a
// signature group takes its group's original with its phase function scaled by its organ
// area over the representative's (`phaseScale`), for a structure intercepts and scatters in
// proportion to its area (MemberScale).
class OriginalContents : public ClosedContents {
  public:
    explicit OriginalContents(std::shared_ptr<const Original> original, double phaseScale = 1.0)
        : original_(std::move(original)), scale_(phaseScale) {}
    double Transmittance(const glm::dvec3& omega) const override {
        return original_->transmittance.Value(omega, 0);
    }
    double Phase(int band, const glm::dvec3& towardSource,
                 const glm::dvec3& outgoing) const override {
        return scale_ * original_->phase.Value(band, towardSource, outgoing);
    }
    void PhaseTable(int band, std::span<const glm::dvec3> towardSources,
                    std::span<const glm::dvec3> outgoing, double* table) const override {
        original_->phase.Table(band, towardSources, outgoing, table);
        for (std::size_t i = 0; i < towardSources.size() * outgoing.size(); ++i) table[i] *= scale_;
    }
    const Original& Of() const { return *original_; }

  private:
    std::shared_ptr<const Original> original_;
    double scale_;
};

}  // namespace leaflux
