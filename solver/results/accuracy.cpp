#include "solver/results/accuracy.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "solver/util/check.h"

namespace leaflux {
namespace {

std::vector<std::size_t> LeafReceivers(const Scene& scene, const FlatScene& flat,
                                       const std::unordered_set<NodeId>* within) {
    std::unordered_set<NodeId> leaves;
    for (const Node& node : scene.nodes) {
        if (node.type() == NodeType::kLeaf && (within == nullptr || within->count(node.id)))
            leaves.insert(node.id);
    }
    std::vector<std::size_t> receivers;
    for (std::size_t r = 0; r < flat.receivers.size(); ++r) {
        const Receiver& receiver = flat.receivers[r];
        if (receiver.kind == ReceiverKind::kOrgan && leaves.count(receiver.node)) {
            receivers.push_back(r);
        }
    }
    return receivers;
}

double BothSides(const BandLight& light) {
    return light.irradianceUpperWm2 + light.irradianceLowerWm2;
}

// A value against the reference's, and the reference's standard error (negative: none).
struct Pair {
    double expected, value, standardError;
};

BandAccuracy Accuracy(const std::vector<Pair>& pairs) {
    BandAccuracy accuracy;
    accuracy.leaves = static_cast<int>(pairs.size());
    for (const Pair& p : pairs)
        accuracy.referenceMaxWm2 = std::max(accuracy.referenceMaxWm2, p.expected);
    if (accuracy.referenceMaxWm2 <= 0.0) return accuracy;
    double squaredError = 0.0, squaredStderr = 0.0;
    std::vector<double> relative;
    for (const Pair& p : pairs) {
        const double error = p.value - p.expected;
        squaredError += error * error;
        if (p.standardError >= 0.0) squaredStderr += p.standardError * p.standardError;
        if (p.expected >= BandAccuracy::kLitFraction * accuracy.referenceMaxWm2)
            relative.push_back(std::abs(error) / p.expected);
    }
    const double n = static_cast<double>(pairs.size());
    accuracy.l2PctOfMax = 100.0 * std::sqrt(squaredError / n) / accuracy.referenceMaxWm2;
    accuracy.referenceFloorPct = 100.0 * std::sqrt(squaredStderr / n) / accuracy.referenceMaxWm2;
    accuracy.litLeaves = static_cast<int>(relative.size());
    double sum = 0.0;
    for (double e : relative) sum += e;
    accuracy.meanRelativePct = 100.0 * sum / static_cast<double>(relative.size());
    // The 95th percentile: the value 95 % of the lit leaves stay at or below.
    const std::size_t rank =
        std::min(relative.size() - 1, static_cast<std::size_t>(0.95 * relative.size()));
    const auto p95 = relative.begin() + static_cast<std::ptrdiff_t>(rank);
    std::nth_element(relative.begin(), p95, relative.end());
    accuracy.p95RelativePct = 100.0 * *p95;
    return accuracy;
}

}  // namespace

std::vector<BandAccuracy> CompareLeaves(const Scene& scene, const FlatScene& flat,
                                        const Solution& reference, const Solution& value,
                                        const std::unordered_set<NodeId>* within) {
    LEAFLUX_CHECK_EQ(reference.light.size(), flat.receivers.size());
    LEAFLUX_CHECK_EQ(value.light.size(), flat.receivers.size());
    const std::vector<std::size_t> leaves = LeafReceivers(scene, flat, within);
    std::vector<BandAccuracy> bands;
    for (std::size_t b = 0; b < scene.bands.size(); ++b) {
        std::vector<Pair> pairs;
        for (std::size_t r : leaves) {
            const std::span<const BandError> error = reference.ErrorOf(r);
            pairs.push_back(
                {BothSides(reference.light[r][b]), BothSides(value.light[r][b]),
                 error.empty() ? -1.0 : std::hypot(error[b].upperWm2, error[b].lowerWm2)});
        }
        bands.push_back(Accuracy(pairs));
    }
    return bands;
}

std::vector<BandAccuracy> CompareWholeStructures(const Scene& scene, const FlatScene& flat,
                                                 const Solution& reference, const Solution& value,
                                                 const std::unordered_set<NodeId>* within) {
    std::unordered_map<NodeId, const StructureLight*> truth;
    const std::vector<StructureLight> structures = AggregateStructures(scene, flat, reference);
    for (const StructureLight& s : structures) truth.emplace(s.node, &s);
    std::vector<BandAccuracy> bands;
    for (std::size_t b = 0; b < scene.bands.size(); ++b) {
        std::vector<Pair> pairs;
        for (const StructureLight& whole : value.wholeStructures) {
            if (within != nullptr && !within->count(whole.node)) continue;
            const StructureLight& expected = *truth.at(whole.node);
            pairs.push_back(
                {expected.bands[b].absorbedW / expected.areaM2,
                 whole.bands[b].absorbedW / whole.areaM2,
                 expected.errors.empty() ? -1.0 : expected.errors[b].absorbedW / expected.areaM2});
        }
        bands.push_back(Accuracy(pairs));
    }
    return bands;
}

}  // namespace leaflux
