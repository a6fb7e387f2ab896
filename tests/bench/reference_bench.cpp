// Monte Carlo reference cost: a generated 10,000-leaf tree under sun + CIE overcast sky
// with NIR-like leaves (ρ = τ = 0.45): the paths per leaf, and the time, that reach a
// median relative standard error of 1 % over lit leaves. Prints a table and writes CSV.
// Run: build/release/tests/leaflux_bench_reference [out.csv, default out/bench/reference_bench.csv]
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "solver/generate/generator.h"
#include "solver/solve.h"

namespace leaflux {
namespace {

struct Run {
    int samples;
    double seconds, cpuSeconds, medianRelativeError;
    std::size_t litLeaves;
    std::int64_t rays, peakRss;
};

// Lit: a leaf receiving at least 5 % of the sun's normal irradiance on its two sides.
Run Measure(const PreparedScene& prepared, int samples, double sunIrradiance) {
    SolverSettings settings;
    settings.monteCarlo.samplesPerReceiver = samples;
    const Solution solution = Solve(prepared, settings);
    std::vector<double> relative;
    for (std::size_t r = 0; r < prepared.Flat().receivers.size(); ++r) {
        if (prepared.Flat().receivers[r].kind != ReceiverKind::kOrgan) continue;
        if (ReceiverName(prepared.Source(), prepared.Flat().receivers[r]).rfind("leaf", 0) != 0)
            continue;
        const BandLight& nir = solution.light[r][0];
        const double e = nir.irradianceUpperWm2 + nir.irradianceLowerWm2;
        if (e < 0.05 * sunIrradiance) continue;
        const BandError& error = solution.error[r][0];
        relative.push_back(std::hypot(error.upperWm2, error.lowerWm2) / e);
    }
    std::nth_element(relative.begin(), relative.begin() + relative.size() / 2, relative.end());
    return {samples,
            solution.stats.wallSeconds,
            solution.stats.cpuSeconds,
            relative.empty() ? 0.0 : relative[relative.size() / 2],
            relative.size(),
            solution.stats.rays,
            solution.stats.peakRssBytes};
}

}  // namespace
}  // namespace leaflux

int main(int argc, char** argv) {
    using namespace leaflux;
    const double sun = 500.0;
    Scene scene;
    scene.bands = {{"NIR", 700, 2500}};
    scene.optics = {{"leaf", {{0.45, 0.45, 0.45, 0.45}}},
                    {"stem", {{0.4, 0.4, 0, 0}}},
                    {"ground", {{0.3, 0.3, 0, 0}}}};
    PlantationParameters plantation;
    plantation.tree.leafCount = 10000;
    plantation.tree.seed = 3;
    plantation.jitterM = 0.0;
    AddPlantation(scene, plantation, "ground");
    const double h = glm::radians(55.0);
    scene.sources.suns.push_back({{0.0, -std::cos(h), std::sin(h)}, {sun}, 0.0});
    scene.sources.skies.push_back({SkyModel::kCieOvercast, {120.0}});
    scene.Validate();
    const PreparedScene prepared(scene);

    std::vector<Run> runs;
    runs.push_back(Measure(prepared, 256, sun));
    // The error falls as 1/sqrt(paths): aim at 1 % from the first run, then check.
    const double ratio = runs[0].medianRelativeError / 0.01;
    const int target = std::max(256, static_cast<int>(std::ceil(256 * ratio * ratio / 16.0)) * 16);
    runs.push_back(Measure(prepared, target, sun));

    const char* path = argc > 1 ? argv[1] : "out/bench/reference_bench.csv";
    if (const auto folder = std::filesystem::path(path).parent_path(); !folder.empty())
        std::filesystem::create_directories(folder);  // out/ from the checkout root
    std::ofstream csv(path);
    csv << "scene,leaves,samples_per_leaf,wall_s,cpu_s,median_rel_stderr,lit_leaves,rays,peak_rss_"
           "mib\n";
    std::printf("%-28s %8s %9s %8s %8s %10s %6s %12s %9s\n", "scene", "leaves", "samples", "wall_s",
                "cpu_s", "median_err", "lit", "rays", "peak_MiB");
    for (const Run& r : runs) {
        csv << "tree_10k_nir_sun_sky,10000," << r.samples << ',' << r.seconds << ',' << r.cpuSeconds
            << ',' << r.medianRelativeError << ',' << r.litLeaves << ',' << r.rays << ','
            << r.peakRss / (1 << 20) << '\n';
        std::printf("%-28s %8d %9d %8.2f %8.2f %9.3f%% %6zu %12lld %9lld\n", "tree_10k_nir_sun_sky",
                    10000, r.samples, r.seconds, r.cpuSeconds, 100 * r.medianRelativeError,
                    r.litLeaves, static_cast<long long>(r.rays),
                    static_cast<long long>(r.peakRss / (1 << 20)));
    }
    std::printf("wrote %s\n", path);
    return 0;
}
