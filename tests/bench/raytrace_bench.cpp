// Rays per second of the ray engine on a generated 10⁵-leaf tree, occlusion and closest
// hit, on every core (TBB), for two kinds of rays: from random points of the tree's
// bounding box in random directions (the usual throughput figure), and from random points
// on random triangles, each ignoring the triangle it leaves (the rays the solvers shoot:
// they start in the foliage and cross more of it).
// Run: build/release/tests/leaflux_bench_raytrace [--benchmark_out=raytrace.csv
//      --benchmark_out_format=csv]
#include <benchmark/benchmark.h>
#include <tbb/parallel_for.h>

#include "solver/generate/generator.h"
#include "solver/solve.h"
#include "solver/util/sampling.h"

namespace leaflux {
namespace {

const PreparedScene& Tree() {
    static const Scene scene = [] {
        Scene s;
        s.bands = {{"PAR"}};
        s.optics = {{"leaf", {{0.1, 0.1, 0.05, 0.05}}}, {"stem", {{0.1, 0.1, 0, 0}}}};
        TreeParameters tree;
        tree.leafCount = 100000;
        AddTree(s, tree, {0, 0, 0});
        s.Validate();
        return s;
    }();
    static const PreparedScene prepared(scene);
    return prepared;
}

template <bool kOcclusion, bool kFromSurfaces>
void Rays(benchmark::State& state) {
    const PreparedScene& tree = Tree();
    const FlatScene& flat = tree.Flat();
    constexpr int kBatch = 1 << 20;
    std::int64_t hits = 0, total = 0, batch = 0;
    for (auto _ : state) {
        std::atomic<std::int64_t> hitCount{0};
        tbb::parallel_for(
            tbb::blocked_range<int>(0, kBatch, 4096), [&](const tbb::blocked_range<int>& range) {
                SetFlushToZero();
                Random random(StreamSeed(7, batch, range.begin()));
                std::int64_t local = 0;
                for (int i = range.begin(); i < range.end(); ++i) {
                    RayStart start;
                    if constexpr (kFromSurfaces) {
                        const auto t =
                            random.Below(static_cast<std::uint32_t>(flat.triangles.size()));
                        const Triangle& tri = flat.triangles[t];
                        const glm::dvec3 w = UniformTriangle(random.Uniform(), random.Uniform());
                        start = {w.x * tri.a + w.y * tri.b + w.z * tri.c, t};
                    } else {
                        const glm::dvec3 u(random.Uniform(), random.Uniform(), random.Uniform());
                        start = {flat.boundsMin + u * (flat.boundsMax - flat.boundsMin)};
                    }
                    const glm::dvec3 d = UniformSphere(random.Uniform(), random.Uniform());
                    if constexpr (kOcclusion) {
                        local += tree.Rays().Occluded(start, d);
                    } else {
                        local += tree.Rays().Trace(start, d).fate == RayFate::kHit;
                    }
                }
                hitCount += local;
            });
        hits += hitCount;
        total += kBatch;
        ++batch;
    }
    state.counters["rays_per_s"] =
        benchmark::Counter(static_cast<double>(total), benchmark::Counter::kIsRate);
    state.counters["hit_fraction"] = static_cast<double>(hits) / total;
    state.counters["triangles"] = static_cast<double>(flat.triangles.size());
}

BENCHMARK(Rays<true, false>)
    ->Name("occlusion_from_bounds")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
BENCHMARK(Rays<false, false>)
    ->Name("closest_hit_from_bounds")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
BENCHMARK(Rays<true, true>)
    ->Name("occlusion_from_surfaces")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);
BENCHMARK(Rays<false, true>)
    ->Name("closest_hit_from_surfaces")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

}  // namespace
}  // namespace leaflux

BENCHMARK_MAIN();
