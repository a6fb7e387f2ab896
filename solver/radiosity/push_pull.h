// Push/pull (Hanrahan 1991; Soler 2003 §3.1): light gathered anywhere in a hierarchy is
// handed down to its leaf patches, and what the leaf patches send is pulled up so that
// every node sends what its patches send. A cluster's intensity is kept per direction of
// the set (§4.2.2); a plane's radiosity is its parts' mean. Reads the hierarchy, the node
// model, the traversal and exposure; writes only the light tables it is handed.
#pragma once

#include <cstdint>
#include <deque>
#include <vector>

#include "solver/radiosity/exposure.h"
#include "solver/radiosity/light_state.h"
#include "solver/radiosity/links.h"
#include "solver/radiosity/node_model.h"
#include "solver/radiosity/traversal.h"

namespace leaflux {

class PushPull {
  public:
    PushPull(const NodeModel& model, const Traversal& traversal, const Exposure& exposure)
        : hierarchy_(model.Nodes()), model_(model), traversal_(traversal), exposure_(exposure) {}

    // A local problem (a subtree solved alone): the light its ancestors hand down to its
    // root, held fixed — per bin and channel, and the visibility of each source (BinsAbove,
    // SourcesAbove of the problem it came from). Empty: none.
    void HoldAbove(std::vector<double> bins, std::vector<double> sources) {
        aboveBins_ = std::move(bins);
        aboveSources_ = std::move(sources);
    }
    // What node n's ancestors hand down to it.
    std::vector<double> BinsAbove(std::uint32_t n, const Links& links,
                                  const Gathered& gathered) const;
    std::vector<double> SourcesAbove(std::uint32_t n, const Links& links,
                                     std::size_t sourceCount) const;

    // Children before parents: every node's emitted power, every plane's mean radiosity and
    // every cluster's intensity per direction from the leaf patches' radiosity.
    void PullUp(Field& field) const;
    // Per leaf patch, the light of the directional sources through their links; patches
    // split later take their parent's (the driver's split hook).
    // A closed instance takes the visibility of each source (`closed`, when the hierarchy
    // has closed instances).
    void PushSources(const Links& links, const std::vector<DirectionalSource>& sources,
                     SourceLight& out, ClosedLight* closed = nullptr) const;
    // Per leaf patch, the source light plus what the clusters and patches above gathered;
    // the radiance integral and moment (the light vector) only with kDirections.
    // A closed instance takes the light per bin that arrived on it and above it.
    template <bool kDirections>
    void PushDown(const Links& links, const Gathered& gathered, const SourceLight& sources,
                  LeafLight& leaf, ClosedLight* closed = nullptr) const;

  private:
    // Per task: buffers reused from patch to patch, so that handing light down allocates
    // nothing per node (a deque, whose elements stay where they are as it grows).
    struct Scratch {
        std::vector<double> top, lobes;
        std::deque<std::vector<double>> levels;
    };
    void PullNode(Field& field, std::uint32_t n) const;
    // Whether node n holds cluster light to hand down, and adding it to a sum of bins (its
    // share by exposure of what came from above, and what it gathered): inline, for every
    // sweep hands every node's light down through them.
    bool HoldsBins(std::uint32_t n, const Links& links) const {
        return (!model_.Planar(n) && !links.node[n].empty()) || exposure_.Exposed(n);
    }
    void AddBins(std::uint32_t n, const Links& links, const Gathered& gathered,
                 std::vector<double>& sum) const {
        const int bins = model_.BinCount(), channels = model_.ChannelSet().Count();
        if (exposure_.Exposed(n)) {
            const float* share = exposure_.Share(n);
            for (int d = 0; d < bins; ++d) {
                for (int k = 0; k < channels; ++k)
                    sum[d * channels + k] *= static_cast<double>(share[d]);
            }
        }
        if (model_.Planar(n) || links.node[n].empty()) return;
        const double* in = gathered.bins[model_.Slot(n)];
        for (int i = 0; i < bins * channels; ++i) sum[i] += in[i];
    }
    void AddSources(std::uint32_t n, const Links& links, std::vector<double>& visibility) const {
        for (const SourceLink& link : links.source[n]) visibility[link.source] += link.visibility;
    }
    // Handing light down to the leaf patches. Descend visits the top patches under `start`
    // (the first patch on each way down, or `start` itself) and the closed instances with
    // the sum of what their
    // ancestors hold: `above` plus, for every node n on the way with holds(n) (the top
    // patch included), what add(n, sum) adds; sums are copied only at such nodes.
    // top(t, sum, scratch) then hands the sum down t's own quadtree, whose patches share a
    // normal.
    template <class Holds, class Add, class Top>
    void Descend(std::uint32_t start, const std::vector<double>& above, Holds holds, Add add,
                 Top top, Scratch& scratch) const;
    // Descend over every subtree of the traversal in parallel, each from the sum of what
    // the nodes above it up to the traversal's root hold (sums of `width` numbers), on top
    // of `fixed` (what is held above the root) when it is not empty.
    template <class Holds, class Add, class Top>
    void DescendAll(std::size_t width, Holds holds, Add add, Top top,
                    const std::vector<double>& fixed) const;
    // Visits the leaf patches under patch t with `value` plus, for every patch m strictly
    // below t on the way with holds(m), what add(m, value) adds; levels[level] and deeper
    // are free for the sums.
    template <class Holds, class Add, class Leaf>
    void DescendPatches(std::uint32_t t, const std::vector<double>& value,
                        std::deque<std::vector<double>>& levels, std::size_t level, Holds holds,
                        Add add, Leaf leaf) const;

    const Hierarchy& hierarchy_;
    const NodeModel& model_;
    const Traversal& traversal_;
    const Exposure& exposure_;
    std::vector<double> aboveBins_, aboveSources_;
};

}  // namespace leaflux
