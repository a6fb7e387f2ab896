// The light a solver computed: the one output format every solver fills, so that any two
// can be compared on the same scene (DESIGN §3).
#pragma once

#include <chrono>
#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <string>
#include <vector>

#include "solver/scene/geometry.h"

namespace leaflux {

// The light on one receiver in one band.
struct BandLight {
    double irradianceUpperWm2 = 0.0;  // mean over the receiver, arriving on the upper side
    double irradianceLowerWm2 = 0.0;
    double absorbedW = 0.0;
    // ∫ L(ω) dω and ∫ L(ω) ω dω over the whole sphere (W/m²): the light vector is their
    // ratio (DESIGN §2); kept apart so that structures can aggregate them.
    double radianceIntegral = 0.0;
    glm::dvec3 radianceMoment{0.0};

    // Towards where the light comes from: |v| = 1 for one beam, 0 for isotropic light.
    glm::dvec3 LightVector() const {
        return radianceIntegral > 0.0 ? radianceMoment / radianceIntegral : glm::dvec3(0.0);
    }
};

// The standard errors of BandLight's irradiances and absorbed power: Monte Carlo's. The
// deterministic solvers give none and hold none (Solution::error): kept in BandLight, they
// took 24 of its 80 bytes on every receiver, 12 MB on a plantation.
struct BandError {
    double upperWm2 = 0.0;
    double lowerWm2 = 0.0;
    double absorbedW = 0.0;
};

// Where the light of one band went, in W: incident = absorbed + escaped for a converged,
// energy-conserving solution.
struct EnergyBalance {
    double incidentW = 0.0;  // from the sources onto any surface (first arrival)
    double absorbedW = 0.0;  // by every surface
    double escapedW = 0.0;   // leaving the scene after at least one scattering
    double stderrW = -1.0;   // standard error of incident − absorbed − escaped

    double RelativeResidual() const {
        return incidentW > 0.0 ? (incidentW - absorbedW - escapedW) / incidentW : 0.0;
    }
};

struct SolveStats {
    double wallSeconds = 0.0;
    double cpuSeconds = 0.0;
    std::int64_t peakRssBytes = 0;
    // Where leaflux solve measured them (0: not measured): the process's resident size once
    // its scene was loaded, and its peak from then on, while solving; the second less the
    // first is the solver's working memory. peakRssBytes is the process's, loading included.
    std::int64_t loadedRssBytes = 0, solvingPeakRssBytes = 0;
    std::int64_t rays = 0;
    int threads = 0;
    // Deterministic solvers: the hierarchy and the iteration.
    std::int64_t links = 0;
    std::int64_t elements = 0;
    int refinementDepth = 0;  // deepest level of the hierarchy that links reach
    int iterations = 0;
    int extrapolations = 0;       // jumps that accelerated the iteration
    std::int64_t warmOrgans = 0;  // organs whose iteration started from a warm start
    double residual = 0.0;        // relative change of the radiosity still to come
};

// Wall and CPU time and peak memory of a solve, from its start to Stamp.
class ResourceClock {
  public:
    ResourceClock();
    void Stamp(SolveStats& stats) const;

  private:
    double wallStart_, cpuStart_;
};

// Wall time in laps: each Lap, the seconds since the last (or since made).
class Stopwatch {
  public:
    double Lap() {
        const auto now = std::chrono::steady_clock::now();
        const double seconds = std::chrono::duration<double>(now - last_).count();
        last_ = now;
        return seconds;
    }

  private:
    std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// HRC's links of one kind against rays from their receivers (HrcOptions::auditLinks): the
// power the links hand on with the solution's radiosity, all bands together, and what
// cosine-distributed rays from every leaf patch side find — the radiosity of the side of
// the point each ray hits, on the patch's area — where a link of that kind covers the
// point hit: a Monte Carlo estimate of the same exchanges, with its standard error. Two
// more rows, of no link, hold what the rays find where no link covers the point or two do:
// nothing, when the links partition the exchanges as they must.
struct LinkAudit {
    std::string kind;
    std::int64_t links = 0;
    double handedW = 0.0, foundW = 0.0, foundStderrW = 0.0;
};

// The same quantities for a botanical structure (branch, plant, …): the organs below it,
// area-weighted for irradiances, summed for absorbed power and radiance integrals.
struct StructureLight {
    NodeId node = 0;
    std::string name;
    NodeType type = NodeType::kOther;
    int organCount = 0;
    double areaM2 = 0.0;
    std::vector<BandLight> bands;
    std::vector<BandError> errors;  // per band; empty when the solver gives none
};

// Per receiver and band, in one block: table[receiver][band]. A vector a receiver cost 40
// bytes more each, 10 MB on a plantation.
template <class Cell>
class ReceiverTable {
  public:
    template <class Item>
    class Rows {  // iterates receivers, each a span of its bands
      public:
        Rows(Item* at, std::size_t bands) : at_(at), bands_(bands) {}
        std::span<Item> operator*() const { return {at_, bands_}; }
        Rows& operator++() {
            at_ += bands_;
            return *this;
        }
        bool operator==(const Rows& other) const { return at_ == other.at_; }

      private:
        Item* at_;
        std::size_t bands_;
    };

    ReceiverTable() = default;
    ReceiverTable(std::size_t receivers, std::size_t bands) { assign(receivers, bands); }
    // Every receiver's every band a default cell (unlit light, no error).
    void assign(std::size_t receivers, std::size_t bands) {
        receivers_ = receivers;
        bands_ = bands;
        cells_.assign(receivers * bands, Cell{});
    }

    std::size_t size() const { return receivers_; }  // receivers
    bool empty() const { return receivers_ == 0; }
    std::size_t Bands() const { return bands_; }
    std::span<Cell> operator[](std::size_t r) { return {cells_.data() + r * bands_, bands_}; }
    std::span<const Cell> operator[](std::size_t r) const {
        return {cells_.data() + r * bands_, bands_};
    }
    std::span<const Cell> front() const { return (*this)[0]; }
    Rows<Cell> begin() { return {cells_.data(), bands_}; }
    Rows<Cell> end() { return {cells_.data() + cells_.size(), bands_}; }
    Rows<const Cell> begin() const { return {cells_.data(), bands_}; }
    Rows<const Cell> end() const { return {cells_.data() + cells_.size(), bands_}; }

  private:
    std::size_t receivers_ = 0, bands_ = 0;
    std::vector<Cell> cells_;
};

using LightTable = ReceiverTable<BandLight>;
using ErrorTable = ReceiverTable<BandError>;

struct Solution {
    LightTable light;
    ErrorTable error;  // the light's standard errors: Monte Carlo's; empty for the others
    // Structures solved as a whole, their leaves not one by one (the instanced solver
    // stopped opening there: InstancedOptions::maxDepth, openUntil): the light of each as
    // one, its irradiances NaN (not solved); their organs are `unsolved` (1 by receiver)
    // and left out of the organ results. Both empty for the other solvers.
    std::vector<StructureLight> wholeStructures;
    std::vector<std::uint8_t> unsolved;
    // Organs whose light a structure solved whole handed down (InstancedOptions::pushDown):
    // approximate (push_down.h); 1 by receiver, empty when there are none.
    std::vector<std::uint8_t> pushedDown;
    std::vector<EnergyBalance> balance;  // [band]
    SolveStats stats;
    std::vector<LinkAudit> linkAudit;  // HRC with auditLinks only

    // Receiver r's standard errors by band, or none.
    std::span<const BandError> ErrorOf(std::size_t r) const {
        return error.empty() ? std::span<const BandError>{} : error[r];
    }
    // Receiver r's standard errors in band b: zero where the solver gives none.
    BandError ErrorAt(std::size_t r, std::size_t b) const {
        return error.empty() ? BandError{} : error[r][b];
    }
};

// Aggregates for every node that has organs below it (itself included), from the solved
// organs and the structures solved whole; a structure holding one of those has NaN
// irradiances (not solved), its absorbed power and light vector summed as the others.
std::vector<StructureLight> AggregateStructures(const Scene& scene, const FlatScene& flat,
                                                const Solution& solution);

}  // namespace leaflux
