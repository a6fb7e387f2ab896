#include "solver/radiosity/push_pull.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "solver/util/check.h"

namespace leaflux {
namespace {
constexpr double kPi = glm::pi<double>();
}  // namespace

void PushPull::PullUp(Field& field) const {
    // Children before parents: the subtrees in parallel (each a pre-order range of its
    // own), then the nodes above them.
    field.emitted.resize(hierarchy_.Size(), 0.0);
    const auto& preOrder = traversal_.PreOrder();
    const auto& subtrees = traversal_.Subtrees();
    tbb::parallel_for(std::size_t{0}, subtrees.size(), [&](std::size_t t) {
        for (std::size_t i = subtrees[t].second; i-- > subtrees[t].first;)
            PullNode(field, preOrder[i]);
    });
    const auto& above = traversal_.Above();
    for (auto it = above.rbegin(); it != above.rend(); ++it) PullNode(field, *it);
}

void PushPull::PullNode(Field& field, std::uint32_t n) const {
    const HrcNode& node = hierarchy_[n];
    const Channels& set = model_.ChannelSet();
    const int channels = set.Count();
    if (node.closed >= 0) return;  // its light is its phase function's (closed_scattering.h)
    double& emitted = field.emitted[n];
    emitted = 0.0;
    if (node.patch && node.children.empty()) {
        const double* upper = field.radiosity(n, kUpper);
        const double* lower = field.radiosity(n, kLower);
        if (set.measure == ChannelMeasure::kSum || set.beams == 1) {
            for (int c = 0; c < channels; ++c) emitted += node.areaM2 * (upper[c] + lower[c]);
        } else {
            thread_local std::vector<double> power;
            power.resize(channels);
            for (int c = 0; c < channels; ++c) power[c] = node.areaM2 * (upper[c] + lower[c]);
            emitted = set.Measure(power.data());
        }
        return;
    }
    // A cluster's children may be brightest under different beams: their sum bounds it.
    for (std::uint32_t child : node.children) emitted += field.emitted[child];
    if (model_.Planar(n)) {
        // A split patch or a flat cluster radiates the area mean of its parts; a flat
        // cluster's intensity, below, is for the clusters above it.
        for (int s : {kUpper, kLower}) {
            double* mean = field.radiosity(n, s);
            bool first = true;  // 0 + x is x: the first part is assigned
            for (std::uint32_t child : node.children) {
                const double share = hierarchy_[child].areaM2 / node.areaM2;
                const double* part = field.radiosity(child, s);
                for (int c = 0; c < channels; ++c)
                    mean[c] = first ? share * part[c] : mean[c] + share * part[c];
                first = false;
            }
        }
        if (node.patch) return;
    }
    const int bins = model_.BinCount();
    double* out = field.intensity[model_.Slot(n)];
    std::fill(out, out + bins * channels, 0.0);
    for (std::uint32_t child : node.children) {
        const HrcNode& c = hierarchy_[child];
        if (!c.patch) {
            const double* in = field.intensity[model_.Slot(child)];
            for (int i = 0; i < bins * channels; ++i) out[i] += in[i];
            continue;
        }
        // A patch faces each direction with one side: the other's lobe is 0 there.
        thread_local std::vector<double> lobes;
        lobes.resize(2 * static_cast<std::size_t>(bins));
        model_.BinLobes(c, lobes.data());
        const double* upper = field.radiosity(child, kUpper);
        const double* lower = field.radiosity(child, kLower);
        const double scale = c.areaM2 / kPi;
        for (int d = 0; d < bins; ++d) {
            const double u = scale * lobes[d], l = scale * lobes[bins + d];
            for (int k = 0; k < channels; ++k) out[d * channels + k] += u * upper[k] + l * lower[k];
        }
    }
}

template <class Holds, class Add, class Top>
void PushPull::DescendAll(std::size_t width, Holds holds, Add add, Top top,
                          const std::vector<double>& fixed) const {
    const auto& preOrder = traversal_.PreOrder();
    const auto& subtrees = traversal_.Subtrees();
    const std::uint32_t root = traversal_.Root();
    tbb::parallel_for(std::size_t{0}, subtrees.size(), [&](std::size_t t) {
        const std::uint32_t start = preOrder[subtrees[t].first];
        std::vector<double> above = fixed.empty() ? std::vector<double>(width, 0.0) : fixed;
        std::vector<std::uint32_t> chain;  // handed down from the root, as Descend does
        for (std::uint32_t m = start; m != root;) {
            m = hierarchy_[m].parent;
            if (holds(m)) chain.push_back(m);
        }
        for (auto m = chain.rbegin(); m != chain.rend(); ++m) add(*m, above);
        Scratch scratch;
        Descend(start, above, holds, add, top, scratch);
    });
}

template <class Holds, class Add, class Top>
void PushPull::Descend(std::uint32_t start, const std::vector<double>& above, Holds holds, Add add,
                       Top top, Scratch& scratch) const {
    // Depth-first; sums[k] is written only by a node of depth k that holds something, and
    // read by its descendants, so a sibling's subtree never overwrites a sum still in use.
    struct Entry {
        std::uint32_t node;
        int depth, sum;
    };
    std::vector<std::vector<double>> sums = {above};
    std::vector<Entry> stack = {{start, 1, 0}};
    while (!stack.empty()) {
        const Entry entry = stack.back();
        stack.pop_back();
        int sum = entry.sum;
        if (holds(entry.node)) {
            if (static_cast<int>(sums.size()) <= entry.depth) sums.resize(entry.depth + 1);
            sums[entry.depth] = sums[entry.sum];
            add(entry.node, sums[entry.depth]);
            sum = entry.depth;
        }
        const HrcNode& node = hierarchy_[entry.node];
        if (node.patch || node.closed >= 0) {
            top(entry.node, sums[sum], scratch);
            continue;
        }
        for (std::uint32_t child : node.children) stack.push_back({child, entry.depth + 1, sum});
    }
}

template <class Holds, class Add, class Leaf>
void PushPull::DescendPatches(std::uint32_t t, const std::vector<double>& value,
                              std::deque<std::vector<double>>& levels, std::size_t level,
                              Holds holds, Add add, Leaf leaf) const {
    const HrcNode& node = hierarchy_[t];
    if (node.children.empty()) return leaf(t, value);
    for (std::uint32_t child : node.children) {
        if (!holds(child)) {
            DescendPatches(child, value, levels, level, holds, add, leaf);
            continue;
        }
        if (levels.size() <= level) levels.resize(level + 1);
        std::vector<double>& below = levels[level];
        below = value;
        add(child, below);
        DescendPatches(child, below, levels, level + 1, holds, add, leaf);
    }
}

void PushPull::PushSources(const Links& links, const std::vector<DirectionalSource>& sources,
                           SourceLight& out, ClosedLight* closed) const {
    const std::size_t size = hierarchy_.Size();
    const int channels = model_.ChannelSet().Count();
    out.sides.Assign(size);
    out.incident.Assign(size);
    out.integral.Assign(size);
    out.moment.Assign(size);
    const auto holds = [&](std::uint32_t n) { return !links.source[n].empty(); };
    const auto add = [&](std::uint32_t n, std::vector<double>& visibility) {
        AddSources(n, links, visibility);
    };
    const auto leaf = [&](std::uint32_t n, const std::vector<double>& visibility) {
        const HrcNode& node = hierarchy_[n];
        for (std::size_t s = 0; s < sources.size(); ++s) {
            if (visibility[s] <= 0.0) continue;
            double share[2] = {sources[s].SideShare(node.normal),
                               sources[s].SideShare(-node.normal)};
            for (int side : {kUpper, kLower}) {
                if (model_.Inner(node.triangle, side)) share[side] = 0.0;
            }
            if (share[kUpper] + share[kLower] <= 0.0) continue;
            double* integral = out.integral[n];
            glm::dvec3* moment = out.moment[n];
            for (int k = 0; k < channels; ++k) {
                const double normal = sources[s].normalIrradiance[k] * visibility[s];
                for (int side : {kUpper, kLower}) {
                    out.sides(n, side)[k] += normal * share[side];
                    if (sources[s].incident) out.incident(n, side)[k] += normal * share[side];
                }
                // A cone of radius r brings L Ω (1 + cos r) / 2 onto a plane facing it, and
                // that times its axis is its ∫ L ω dω; its ∫ L dω is L Ω.
                integral[k] += normal * 2.0 / (1.0 + sources[s].cosRadius);
                moment[k] += normal * sources[s].Moment();
            }
        }
    };
    const auto top = [&](std::uint32_t t, const std::vector<double>& visibility, Scratch& scratch) {
        if (const std::int32_t c = hierarchy_[t].closed; c >= 0) {
            std::copy(visibility.begin(), visibility.end(), closed->sources[c]);
            return;
        }
        DescendPatches(t, visibility, scratch.levels, 0, holds, add, leaf);
    };
    DescendAll(sources.size(), holds, add, top, aboveSources_);
}

// An arrival on a patch, as PushDown hands it down: per channel, W/m² on the upper and
// the lower side, ∫ L dω, and ∫ L ω dω (three numbers).
namespace {
struct Arrival {
    double* data;
    int channels;
    double* Side(int side) const { return data + side * channels; }
    double* Integral() const { return data + 2 * channels; }
    double* Moment(int k) const { return data + 3 * channels + 3 * k; }
    static std::size_t Width(int channels) { return 6 * static_cast<std::size_t>(channels); }
};
struct ConstArrival {
    const double* data;
    int channels;
    const double* Side(int side) const { return data + side * channels; }
    const double* Integral() const { return data + 2 * channels; }
    glm::dvec3 Moment(int k) const {
        const double* m = data + 3 * channels + 3 * k;
        return {m[0], m[1], m[2]};
    }
};
}  // namespace

template <bool kDirections>
void PushPull::PushDown(const Links& links, const Gathered& gathered, const SourceLight& sources,
                        LeafLight& leafLight, ClosedLight* closed) const {
    const int bins = model_.BinCount();
    const int channels = model_.ChannelSet().Count();
    const DirectionSet& directions = model_.Directions();
    const auto holds = [&](std::uint32_t n) { return HoldsBins(n, links); };
    const auto add = [&](std::uint32_t n, std::vector<double>& sum) {
        AddBins(n, links, gathered, sum);
    };
    const auto patchHolds = [&](std::uint32_t n) { return !links.node[n].empty(); };
    const auto addGathered = [&](std::uint32_t n, std::vector<double>& value) {
        const Arrival in{value.data(), channels};
        const double* upper = gathered.sides(n, kUpper);
        const double* lower = gathered.sides(n, kLower);
        for (int k = 0; k < channels; ++k) {
            in.Side(kUpper)[k] += upper[k];
            in.Side(kLower)[k] += lower[k];
            if constexpr (kDirections) {
                in.Integral()[k] += gathered.integral[n][k];
                const glm::dvec3& m = gathered.moment[n][k];
                double* moment = in.Moment(k);
                moment[0] += m.x, moment[1] += m.y, moment[2] += m.z;
            }
        }
    };
    const auto leaf = [&](std::uint32_t n, const std::vector<double>& value) {
        const ConstArrival in{value.data(), channels};
        for (int side : {kUpper, kLower}) {
            double* irradiance = leafLight.irradiance(n, side);
            const double* source = sources.sides(n, side);
            for (int k = 0; k < channels; ++k) irradiance[k] = in.Side(side)[k] + source[k];
        }
        if constexpr (kDirections) {
            for (int k = 0; k < channels; ++k) {
                leafLight.integral[n][k] = in.Integral()[k] + sources.integral[n][k];
                leafLight.moment[n][k] = in.Moment(k) + sources.moment[n][k];
            }
        }
    };
    const auto top = [&](std::uint32_t t, const std::vector<double>& sum, Scratch& scratch) {
        const HrcNode& node = hierarchy_[t];
        if (node.closed >= 0) {
            std::copy(sum.begin(), sum.end(), closed->bins[node.closed]);
            return;
        }
        // The clusters' light on t's normal, once for the patches t was split into; none
        // from the directions an inner side faces.
        scratch.top.assign(Arrival::Width(channels), 0.0);
        scratch.lobes.resize(2 * static_cast<std::size_t>(bins));
        model_.BinLobes(node, scratch.lobes.data());
        const bool inner[2] = {model_.Inner(node.triangle, kUpper),
                               model_.Inner(node.triangle, kLower)};
        const double* upper = scratch.lobes.data();
        const double* lower = upper + bins;
        const Arrival in{scratch.top.data(), channels};
        for (int k = 0; k < channels; ++k) {
            double side[2] = {0.0, 0.0};
            for (int d = 0; d < bins; ++d) {
                side[kUpper] += sum[d * channels + k] * upper[d];
                side[kLower] += sum[d * channels + k] * lower[d];
            }
            for (int s : {kUpper, kLower}) in.Side(s)[k] += inner[s] ? 0.0 : side[s];
            if constexpr (kDirections) {
                glm::dvec3 moment(0.0);
                for (int d = 0; d < bins; ++d) {
                    // The side facing d: the upper lobe is positive exactly there (each
                    // side's lobe scale is positive, ScaleLobes).
                    if (inner[upper[d] > 0.0 ? kUpper : kLower]) continue;
                    const double normal = sum[d * channels + k];
                    in.Integral()[k] += normal;
                    moment += normal * directions.Direction(d);
                }
                double* out = in.Moment(k);
                out[0] += moment.x, out[1] += moment.y, out[2] += moment.z;
            }
        }
        // What t, the patches it was split from and the flat clusters above gathered.
        for (std::uint32_t m = t; m != kNoNode && model_.Planar(m); m = hierarchy_[m].parent)
            addGathered(m, scratch.top);
        DescendPatches(t, scratch.top, scratch.levels, 0, patchHolds, addGathered, leaf);
    };
    DescendAll(static_cast<std::size_t>(bins) * channels, holds, add, top, aboveBins_);
}

std::vector<double> PushPull::BinsAbove(std::uint32_t n, const Links& links,
                                        const Gathered& gathered) const {
    std::vector<std::uint32_t> chain;
    for (std::uint32_t m = hierarchy_[n].parent; m != kNoNode; m = hierarchy_[m].parent) {
        LEAFLUX_CHECK(!model_.Planar(m));  // a plane's parts share its light: no subtree there
        if (HoldsBins(m, links)) chain.push_back(m);
    }
    std::vector<double> sum(
        static_cast<std::size_t>(model_.BinCount()) * model_.ChannelSet().Count(), 0.0);
    for (auto m = chain.rbegin(); m != chain.rend(); ++m) AddBins(*m, links, gathered, sum);
    return sum;
}

std::vector<double> PushPull::SourcesAbove(std::uint32_t n, const Links& links,
                                           std::size_t sourceCount) const {
    std::vector<std::uint32_t> chain;  // added from the top down, as DescendAll adds them
    for (std::uint32_t m = hierarchy_[n].parent; m != kNoNode; m = hierarchy_[m].parent)
        chain.push_back(m);
    std::vector<double> visibility(sourceCount, 0.0);
    for (auto m = chain.rbegin(); m != chain.rend(); ++m) AddSources(*m, links, visibility);
    return visibility;
}

template void PushPull::PushDown<false>(const Links&, const Gathered&, const SourceLight&,
                                        LeafLight&, ClosedLight*) const;
template void PushPull::PushDown<true>(const Links&, const Gathered&, const SourceLight&,
                                       LeafLight&, ClosedLight*) const;

}  // namespace leaflux
