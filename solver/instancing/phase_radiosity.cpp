#include "solver/instancing/phase_radiosity.h"

#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <numbers>
#include <vector>

#include "solver/util/sampling.h"

namespace leaflux {

RadiosityPhase PhaseFromRadiosity(const StructureAlone& structure,
                                  const RadiosityPhaseOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const DirectionSet& set = DirectionSet::OfLevel(options.level);
    const int n = set.Size();
    std::vector<glm::dvec3> beams(n);
    for (int i = 0; i < n; ++i) beams[i] = set.Direction(i);
    const BeamSolution solution =
        SolveBeams(structure.Alone(), structure.Flat(), structure.Rays(), options.hrc, beams);
    const int bands = solution.channels.bands;
    const std::size_t patches = solution.patches.size();

    // What leaves each patch towards each outgoing direction per unit exitance of the side
    // facing it: A |cos θo| e(ωo) / π (m²/sr), and that side.
    std::vector<float> seen(patches * n);
    std::vector<std::uint8_t> sideOf(patches * n);
    std::atomic<std::int64_t> rays{0};
    tbb::parallel_for(std::size_t{0}, patches, [&](std::size_t p) {
        SetFlushToZero();
        const BeamPatch& patch = solution.patches[p];
        Random random(StreamSeed(options.seed, 0xe5c, p));
        for (int o = 0; o < n; ++o) {
            const glm::dvec3 d = set.Direction(o);
            const double cosine = glm::dot(patch.normal, d);
            int escaped = 0;
            for (int r = 0; r < options.escapeRays; ++r) {
                const glm::dvec3 w =
                    UniformTriangle((r + random.Uniform()) / options.escapeRays, random.Uniform());
                const RayStart from{w.x * patch.a + w.y * patch.b + w.z * patch.c, patch.triangle};
                escaped += !structure.Rays().Occluded(from, d);
            }
            seen[p * n + o] = static_cast<float>(patch.areaM2 * std::abs(cosine) * escaped /
                                                 options.escapeRays / std::numbers::pi);
            sideOf[p * n + o] = cosine > 0.0 ? kUpper : kLower;
        }
        rays += static_cast<std::int64_t>(n) * options.escapeRays;
    });

    PhaseFunction bi(PhaseKind::kBiDirectional, options.level, bands);
    float* values = bi.MutableValues().data();
    tbb::parallel_for(0, n, [&](int i) {
        for (int o = 0; o < n; ++o) {
            for (int b = 0; b < bands; ++b) {
                const int channel = i * bands + b;
                double intensity = 0.0;
                for (std::size_t p = 0; p < patches; ++p) {
                    intensity +=
                        double(seen[p * n + o]) * solution.Radiosity(p, sideOf[p * n + o])[channel];
                }
                values[(static_cast<std::size_t>(i) * n + o) * bands + b] =
                    static_cast<float>(intensity);
            }
        }
    });
    RadiosityPhase result;
    result.scatteredW.assign(static_cast<std::size_t>(n) * bands, 0.0);
    for (int i = 0; i < n; ++i)
        for (int b = 0; b < bands; ++b)
            result.scatteredW[i * bands + b] = bi.ScatteredPower(b, set.Direction(i));
    result.absorbedW = solution.absorbedW;
    result.phase = bi.Reduced(options.kind);
    result.stats = solution.stats;
    result.escapeRays = rays;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace leaflux
