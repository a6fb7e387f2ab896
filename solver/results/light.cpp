#include "solver/results/light.h"

#include <chrono>
#include <cmath>
#include <unordered_map>

#include "solver/util/memory.h"

namespace leaflux {

namespace {
double WallSeconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}
}  // namespace

ResourceClock::ResourceClock() : wallStart_(WallSeconds()), cpuStart_(CpuSeconds()) {}

void ResourceClock::Stamp(SolveStats& stats) const {
    stats.wallSeconds = WallSeconds() - wallStart_;
    stats.cpuSeconds = CpuSeconds() - cpuStart_;
    stats.peakRssBytes = PeakRssBytes();
}

std::vector<StructureLight> AggregateStructures(const Scene& scene, const FlatScene& flat,
                                                const Solution& solution) {
    const std::size_t bands = scene.bands.size();
    std::unordered_map<NodeId, const Node*> byId;
    for (const Node& node : scene.nodes) byId.emplace(node.id, &node);

    // Sums first: area-weighted irradiances and squared errors; normalised at the end.
    std::unordered_map<NodeId, StructureLight> sums;
    // Adds `organs` organs of area a and light `light` (area means, summed powers) to s,
    // with their standard errors `error` when the solver gave them (squared, summed).
    const bool errors = !solution.error.empty();
    const auto add = [&](StructureLight& s, int organs, double a, std::span<const BandLight> light,
                         std::span<const BandError> error) {
        if (s.bands.empty()) {
            s.bands.assign(bands, BandLight{});
            if (errors) s.errors.assign(bands, BandError{});
        }
        s.organCount += organs;
        s.areaM2 += a;
        for (std::size_t b = 0; b < bands; ++b) {
            const BandLight& leaf = light[b];
            BandLight& sum = s.bands[b];
            sum.irradianceUpperWm2 += a * leaf.irradianceUpperWm2;
            sum.irradianceLowerWm2 += a * leaf.irradianceLowerWm2;
            sum.absorbedW += leaf.absorbedW;
            sum.radianceIntegral += a * leaf.radianceIntegral;
            sum.radianceMoment += a * leaf.radianceMoment;
            if (!error.empty()) {
                BandError& e = s.errors[b];
                e.upperWm2 += std::pow(a * error[b].upperWm2, 2);
                e.lowerWm2 += std::pow(a * error[b].lowerWm2, 2);
                e.absorbedW += std::pow(error[b].absorbedW, 2);
            }
        }
    };
    for (std::size_t r = 0; r < flat.receivers.size(); ++r) {
        const Receiver& receiver = flat.receivers[r];
        if (receiver.kind != ReceiverKind::kOrgan) continue;
        if (!solution.unsolved.empty() && solution.unsolved[r]) continue;
        // Light handed down from a structure solved whole: that structure's already.
        if (!solution.pushedDown.empty() && solution.pushedDown[r]) continue;
        for (NodeId at = receiver.node; at != kNoParent; at = byId.at(at)->parent)
            add(sums[at], 1, receiver.areaM2, solution.light[r], solution.ErrorOf(r));
    }
    // Those solved whole, into themselves and the structures above them.
    for (const StructureLight& whole : solution.wholeStructures) {
        for (NodeId at = whole.node; at != kNoParent; at = byId.at(at)->parent)
            add(sums[at], whole.organCount, whole.areaM2, whole.bands, whole.errors);
    }
    std::vector<StructureLight> result;
    for (const Node& node : scene.nodes) {
        auto it = sums.find(node.id);
        if (it == sums.end()) continue;
        StructureLight s = std::move(it->second);
        s.node = node.id;
        s.name = scene.NodeName(node);
        s.type = node.type();
        for (BandLight& b : s.bands) {
            b.irradianceUpperWm2 /= s.areaM2;
            b.irradianceLowerWm2 /= s.areaM2;
            b.radianceIntegral /= s.areaM2;
            b.radianceMoment /= s.areaM2;
        }
        for (BandError& e : s.errors) {
            e.upperWm2 = std::sqrt(e.upperWm2) / s.areaM2;
            e.lowerWm2 = std::sqrt(e.lowerWm2) / s.areaM2;
            e.absorbedW = std::sqrt(e.absorbedW);
        }
        result.push_back(std::move(s));
    }
    return result;
}

}  // namespace leaflux
