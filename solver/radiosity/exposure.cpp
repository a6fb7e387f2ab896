#include "solver/radiosity/exposure.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

#include "solver/util/sampling.h"

namespace leaflux {

Exposure::Exposure(const NodeModel& model, const RayScene& scene, int raysPerDirection,
                   const std::vector<std::uint8_t>* needed)
    : model_(&model), bins_(model.BinCount()) {
    const Hierarchy& hierarchy = model.Nodes();
    if (raysPerDirection <= 0) return;
    const std::size_t size = hierarchy.Size();
    nodes_ = size;
    share_.assign(size * bins_, 1.0f);
    std::vector<std::uint32_t> clusters;
    for (std::uint32_t n = 0; n < size; ++n) {
        // A cluster held from outside a local problem receives nothing to hand down.
        if (!hierarchy[n].patch && !model.Planar(n) && !model.Held(n) &&
            (needed == nullptr || (*needed)[n]))
            clusters.push_back(n);
    }
    const DirectionSet& directions = model.Directions();
    const DirectionSet& coarse =
        DirectionSet::OfLevel(std::min(1, DirectionSet::LevelWithCount(bins_)));
    std::vector<DirectionSet::Interpolation> toCoarse;
    for (int d = 0; d < bins_; ++d) toCoarse.push_back(coarse.Locate(directions.Direction(d)));
    std::atomic<std::int64_t> traced{0};
    const int half = (raysPerDirection + 1) / 2;
    tbb::parallel_for(std::size_t{0}, clusters.size(), [&](std::size_t i) {
        SetFlushToZero();
        const std::uint32_t n = clusters[i];
        const HrcNode& C = hierarchy[n];
        const RayScene::Group group{hierarchy.Ranks(), C.first, C.first + C.count};
        std::vector<double> open(C.children.size() * bins_, 1.0);
        std::vector<double> coarseOpen(coarse.Size(), 1.0);
        std::int64_t local = 0;
        for (std::size_t j = 0; j < C.children.size(); ++j) {
            const std::uint32_t c = C.children[j];
            for (int d = 0; d < coarse.Size(); ++d) {
                const glm::dvec3& omega = coarse.Direction(d);
                Random random(StreamSeed(0xE7905, c, d));
                double seen = 0.0, total = 0.0;
                int passed = 0, blocked = 0, cast = 0;
                for (int ray = 0; ray < raysPerDirection; ++ray) {
                    // The even strata first, then the odd: where the first half all agree,
                    // the child is taken as wholly open (or shut) that way.
                    const int k = ray < half ? 2 * ray : 2 * (ray - half) + 1;
                    if (ray == half && (passed == 0) != (blocked == 0)) break;
                    const Hierarchy::Point p = hierarchy.Sample(
                        c, (k + random.Uniform()) / raysPerDirection, random.Uniform());
                    ++cast;
                    const double weight = model.ReceivingWeight(p.triangle, p.normal, omega);
                    if (weight <= 0.0) continue;
                    total += weight;
                    if (!scene.OccludedByGroup({p.position, p.triangle}, omega, 2.0 * C.radius,
                                               group)) {
                        seen += weight;
                        ++passed;
                    } else {
                        ++blocked;
                    }
                }
                coarseOpen[d] = total > 0.0 ? seen / total : 1.0;
                local += cast;
            }
            for (int d = 0; d < bins_; ++d) {
                const DirectionSet::Interpolation& w = toCoarse[d];
                double value = 0.0;
                for (int k = 0; k < 3; ++k) value += w.weight[k] * coarseOpen[w.vertex[k]];
                open[j * bins_ + d] = value;
            }
        }
        for (int d = 0; d < bins_; ++d) {
            double facing = 0.0, lit = 0.0;
            for (std::size_t j = 0; j < C.children.size(); ++j) {
                const HrcNode& c = hierarchy[C.children[j]];
                const double area = c.patch ? c.areaM2 * model.BinCosine(c, d).second
                                            : model.ProjectedBin(C.children[j], d);
                facing += area;
                lit += area * open[j * bins_ + d];
            }
            if (lit <= 0.0) continue;
            for (std::size_t j = 0; j < C.children.size(); ++j) {
                share_[static_cast<std::size_t>(C.children[j]) * bins_ + d] =
                    static_cast<float>(open[j * bins_ + d] * facing / lit);
            }
        }
        traced += local;
    });
    traced_ = traced;
}

std::vector<std::uint8_t> ExposedClusters(const NodeModel& model,
                                          const std::vector<std::uint32_t>& preOrder,
                                          const Links& links, const Gathered& gathered,
                                          double scattered,
                                          const std::function<double(std::uint32_t)>& threshold) {
    const Hierarchy& hierarchy = model.Nodes();
    std::vector<std::uint8_t> needed(hierarchy.Size(), 0);
    const int bins = model.BinCount(), channels = model.ChannelSet().Count();
    // Down the hierarchy, the bins handed down so far (the path's clusters').
    struct Above {
        std::uint32_t node;
        std::vector<double> bins;
    };
    std::vector<Above> path;
    for (std::uint32_t n : preOrder) {
        const HrcNode& node = hierarchy[n];
        while (!path.empty() && path.back().node != node.parent) path.pop_back();
        if (node.patch || model.Planar(n)) continue;
        std::vector<double> sum =
            path.empty() ? std::vector<double>(bins * channels, 0.0) : path.back().bins;
        if (!links.node[n].empty()) {
            const double* in = gathered.bins[model.Slot(n)];
            for (int i = 0; i < bins * channels; ++i) sum[i] += in[i];
        }
        double power = 0.0;
        for (int d = 0; d < bins; ++d)
            power += model.ChannelSet().Measure(&sum[d * channels]) * model.ProjectedBin(n, d);
        needed[n] = scattered * power > threshold(n);
        path.push_back({n, std::move(sum)});
    }
    return needed;
}

}  // namespace leaflux
