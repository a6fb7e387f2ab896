// Directional functions of a plant structure in its own frame (Soler 2003 §4.2): values at
// the directions of a tetrahedral set (DirectionSet: 4, 10, 34, 130, 514 directions),
// interpolated linearly on the face that holds a direction.
//
// Every function is stored in the structure's frame (z along its main axis, DESIGN §2), so
// one function serves every instance whatever its orientation: a caller turns its world
// directions into that frame (instanceFromWorld) before looking a value up. Values are
// floats: a 514² phase function of two bands is 2.1 MB as floats, twice that as doubles, and
// its own accuracy is a few percent (the paper's §4.2.2 table).
#pragma once

#include <glm/glm.hpp>
#include <span>
#include <string>
#include <vector>

#include "solver/util/directions.h"

namespace leaflux {

// A function on the sphere with `channels` values per direction (a band each, say).
// Invariant: values_.size() == Directions().Size() * channels_.
class SphereFunction {
  public:
    SphereFunction() = default;
    SphereFunction(int level, int channels);  // every value zero
    // From stored values; throws std::invalid_argument when their count does not fit.
    static SphereFunction FromValues(int level, int channels, std::vector<float> values);

    int Level() const { return level_; }
    int Channels() const { return channels_; }
    const DirectionSet& Directions() const { return DirectionSet::OfLevel(level_); }
    bool Empty() const { return values_.empty(); }

    float& At(int direction, int channel) { return values_[direction * channels_ + channel]; }
    float At(int direction, int channel) const { return values_[direction * channels_ + channel]; }
    // Linear on the face holding `direction` (any length > 0).
    double Value(const glm::dvec3& direction, int channel) const;
    // ∫ over the sphere of the interpolated function (sr × its unit).
    double Integral(int channel) const;
    std::span<const float> Values() const { return values_; }

  private:
    int level_ = 0;
    int channels_ = 0;
    std::vector<float> values_;
};

// How finely a phase function follows the directions (Soler 2003 §4.2.1).
enum class PhaseKind : int {
    kConstant = 0,         // one value per band: scattered evenly, whatever the light's direction
    kMonoDirectional = 1,  // per incoming direction, scattered evenly in every direction
    kBiDirectional = 2,    // per incoming and outgoing direction
};
const char* PhaseKindName(PhaseKind kind);  // "constant", "mono", "bi"

// f(ωi, ωo) per band: the intensity (W/sr) leaving the structure towards ωo per unit
// irradiance (W/m², normal to the beam) arriving from ωi (the direction towards the
// source), both unit vectors of the structure's frame. It holds the area the structure
// intercepts from ωi and every scattering inside it; light that crosses without meeting a
// leaf is the transmittance's, not f's. Its integral over ωo is the power (W) the
// structure scatters per unit irradiance from ωi.
//
// Layout (Values()): constant [band]; mono-directional [i][band]; bi-directional
// [i][o][band], i and o directions of Directions().
class PhaseFunction {
  public:
    PhaseFunction() = default;
    // Every value zero.
    PhaseFunction(PhaseKind kind, int level, int bands);
    // From stored values; throws std::invalid_argument when their count does not fit.
    static PhaseFunction FromValues(PhaseKind kind, int level, int bands,
                                    std::vector<float> values);

    PhaseKind Kind() const { return kind_; }
    int Level() const { return level_; }  // of the directions; 0 for a constant function
    int Bands() const { return bands_; }
    const DirectionSet& Directions() const { return DirectionSet::OfLevel(level_); }
    bool Empty() const { return values_.empty(); }
    std::span<const float> Values() const { return values_; }
    std::span<float> MutableValues() { return values_; }
    std::size_t Bytes() const { return values_.size() * sizeof(float); }

    double Value(int band, const glm::dvec3& towardSource, const glm::dvec3& outgoing) const;
    // Value for every pair, each direction located once: table[o * towardSources.size() + i]
    // = Value(band, towardSources[i], outgoing[o]).
    void Table(int band, std::span<const glm::dvec3> towardSources,
               std::span<const glm::dvec3> outgoing, double* table) const;
    // ∫ f(ωi, ωo) dωo (W per W/m²) from unit ωi.
    double ScatteredPower(int band, const glm::dvec3& towardSource) const;

    // The coarser kinds from this one (Soler 2003 §4.2.1: "easily obtained from the phase
    // function itself"): mono-directional keeps each incoming direction's scattered power,
    // spread evenly over 4π; constant keeps its mean over the incoming directions.
    PhaseFunction Reduced(PhaseKind kind) const;

  private:
    double V(std::size_t index) const { return static_cast<double>(values_[index]); }

    PhaseKind kind_ = PhaseKind::kConstant;
    int level_ = 0;
    int bands_ = 0;
    std::vector<float> values_;
};

}  // namespace leaflux
