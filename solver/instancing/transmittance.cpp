#include "solver/instancing/transmittance.h"

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <vector>

#include "solver/util/check.h"
#include "solver/util/sampling.h"

namespace leaflux {

TransmittanceEstimate ComputeTransmittance(const StructureAlone& structure,
                                           const TransmittanceOptions& options) {
    LEAFLUX_CHECK(options.raysPerDirection > 0);
    const auto start = std::chrono::steady_clock::now();
    TransmittanceEstimate estimate;
    estimate.tau = SphereFunction(options.level, 1);
    estimate.standardError = SphereFunction(options.level, 1);
    const DirectionSet& set = estimate.tau.Directions();
    const int n = options.raysPerDirection;
    tbb::parallel_for(0, set.Size(), [&](int i) {
        SetFlushToZero();
        const glm::dvec3 d = set.Direction(i);
        Random random(StreamSeed(options.seed, 0x7a75, static_cast<std::uint64_t>(i)));
        std::vector<RayStart> starts(n);
        // Stratified over the projection's face choice and the face: one stratum per ray
        // along the first coordinate.
        for (int r = 0; r < n; ++r) {
            starts[r].origin =
                structure.Entry(d, (r + random.Uniform()) / n, random.Uniform(), random.Uniform());
        }
        std::vector<std::uint8_t> occluded;
        structure.Rays().Occluded(starts, d, occluded);
        int passed = 0;
        for (std::uint8_t o : occluded) passed += o == 0;
        const double tau = static_cast<double>(passed) / n;
        estimate.tau.At(i, 0) = static_cast<float>(tau);
        estimate.standardError.At(i, 0) = static_cast<float>(std::sqrt(tau * (1.0 - tau) / n));
    });
    estimate.rays = static_cast<std::int64_t>(set.Size()) * n;
    estimate.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return estimate;
}

}  // namespace leaflux
