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
    // Adds `organs` organs of area a and light `light` (area means, summed powers) to s.
    const auto add = [&](StructureLight& s, int organs, double a,
                         std::span<const BandLight> light) {
        if (s.bands.empty()) {
            s.bands.assign(bands, BandLight{});
            for (BandLight& b : s.bands)
                b.stderrUpperWm2 = b.stderrLowerWm2 = b.stderrAbsorbedW = 0.0;
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
            const bool hasError = leaf.stderrUpperWm2 >= 0.0;
            sum.stderrUpperWm2 =
                hasError ? sum.stderrUpperWm2 + std::pow(a * leaf.stderrUpperWm2, 2) : -1.0;
            sum.stderrLowerWm2 =
                hasError ? sum.stderrLowerWm2 + std::pow(a * leaf.stderrLowerWm2, 2) : -1.0;
            sum.stderrAbsorbedW =
                hasError ? sum.stderrAbsorbedW + std::pow(leaf.stderrAbsorbedW, 2) : -1.0;
        }
    };
    for (std::size_t r = 0; r < flat.receivers.size(); ++r) {
        const Receiver& receiver = flat.receivers[r];
        if (receiver.kind != ReceiverKind::kOrgan) continue;
        if (!solution.unsolved.empty() && solution.unsolved[r]) continue;
        for (NodeId at = receiver.node; at != kNoParent; at = byId.at(at)->parent)
            add(sums[at], 1, receiver.areaM2, solution.light[r]);
    }
    // Those solved whole, into themselves and the structures above them.
    for (const StructureLight& whole : solution.wholeStructures) {
        for (NodeId at = whole.node; at != kNoParent; at = byId.at(at)->parent)
            add(sums[at], whole.organCount, whole.areaM2, whole.bands);
    }
    std::vector<StructureLight> result;
    for (const Node& node : scene.nodes) {
        auto it = sums.find(node.id);
        if (it == sums.end()) continue;
        StructureLight s = std::move(it->second);
        s.node = node.id;
        s.name = scene.NodeName(node);
        s.type = node.type;
        for (BandLight& b : s.bands) {
            b.irradianceUpperWm2 /= s.areaM2;
            b.irradianceLowerWm2 /= s.areaM2;
            b.radianceIntegral /= s.areaM2;
            b.radianceMoment /= s.areaM2;
            if (b.stderrUpperWm2 >= 0.0) {
                b.stderrUpperWm2 = std::sqrt(b.stderrUpperWm2) / s.areaM2;
                b.stderrLowerWm2 = std::sqrt(b.stderrLowerWm2) / s.areaM2;
                b.stderrAbsorbedW = std::sqrt(b.stderrAbsorbedW);
            }
        }
        result.push_back(std::move(s));
    }
    return result;
}

}  // namespace leaflux
