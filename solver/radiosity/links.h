// Links: the light one node (or a directional source) hands another, as the gathering
// sweeps read it, and the directional sources themselves. Compact, for a scene has millions
// of links and every sweep reads each (RenderPark's links: receiver, source, coefficient).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "solver/radiosity/channels.h"
#include "solver/radiosity/directional_source.h"
#include "solver/radiosity/light_state.h"
#include "solver/util/directions.h"

namespace leaflux {

// Where a direction falls among the direction set's bins: three bins and their weights,
// the first two in 65535ths and the third what they leave, so that the weights sum to 1
// exactly in ten bytes.
struct BinWeights {
    static constexpr double kUnit = 65535.0;
    std::array<std::uint16_t, 3> index{};
    std::array<std::uint16_t, 2> weight{};

    double Weight(int j) const {
        return j < 2 ? weight[j] / kUnit : 1.0 - (weight[0] + weight[1]) / kUnit;
    }
};

inline BinWeights Locate(const DirectionSet& set, const glm::dvec3& direction) {
    const auto located = set.Locate(direction);
    BinWeights bins;
    for (int j = 0; j < 3; ++j) bins.index[j] = static_cast<std::uint16_t>(located.vertex[j]);
    const auto first = static_cast<long>(std::lround(located.weight[0] * BinWeights::kUnit));
    const auto second = static_cast<long>(std::lround(located.weight[1] * BinWeights::kUnit));
    bins.weight[0] = static_cast<std::uint16_t>(std::clamp(first, 0L, 65535L));
    bins.weight[1] = static_cast<std::uint16_t>(std::clamp(second, 0L, 65535L - bins.weight[0]));
    return bins;
}

// Light from a node S to a node R, in single precision.
struct NodeLink {
    static constexpr double kUnit = 65535.0;
    std::uint32_t sender = 0;
    bool exact : 1 = false;  // patch ← patch by the analytic form factor
    // A plane (NodeModel::Planar) sends its radiosity, any other cluster its intensity.
    bool senderPlane : 1 = false;
    std::uint8_t senderSide : 1 = kUpper;  // a plane sender: its side facing R
    // The transfer's visibility comes from rays of its own, not from the rays that judged
    // the link (Refiner::Value).
    bool ownRays : 1 = false;
    // Plane ← plane, one of them a flat cluster (Estimator::PlanesForm): its transfer is an
    // exact link's, F per side of R, but it is judged as a link between clusters.
    bool sided : 1 = false;
    std::uint16_t spread = 0;  // visibility spread of the rays that judged it, in 65535ths
    // From R's centre towards S: unit for a link from a cluster; for exact and sided links
    // the mean of ω over S's solid angle (Estimator::Arrival), so that the light vector
    // takes ∫ L ω dω = L × transfer[2] × toSender.
    glm::vec3 toSender{0.0f};
    // Exact: v F on R's upper and lower sides and v Ω (the solid angle of S at R's centre).
    // Sided: as exact. Else transfer[0]: for a cluster sender v / d², times its intensity;
    // for a plane sender v Ω / π (PlaneSolidAngle), times its radiosity (bounded however
    // near).
    std::array<float, 3> transfer{};
    BinWeights receiverBins, senderBins;  // not exact: R's bin of the light, S's bin that sends it
    // For judging the link again with new light (Refiner::Rerefine) without its geometry:
    // the W it may carry per unit of its sender's light (the radiosity of S's side facing R,
    // or S's intensity towards R, Channels::Measure), or −1 when all S sends may reach R; W
    // per unit of difference between S's two sides' radiosity (R across S's plane); and the
    // geometric error, which with the visibility spread is the error per W carried.
    float reach = 0.0f, sideReach = 0.0f, geometricError = 0.0f;

    double Spread() const { return spread / kUnit; }
    // A link whose rays were all blocked carries nothing; it is kept to be judged again.
    bool Carries() const { return transfer != std::array<float, 3>{}; }
};

// What a link's sender sends towards its receiver, channel by channel: f(k, light) for
// each channel k, the radiosity of a plane's side or the intensity of a cluster
// interpolated between its bins (`slot`: the sender's, NodeModel::Slot).
template <class F>
inline void ForEachSent(const NodeLink& link, const Field& field, std::uint32_t slot, int channels,
                        F&& f) {
    if (link.senderPlane) {
        const double* radiosity = field.radiosity(link.sender, link.senderSide);
        for (int k = 0; k < channels; ++k) f(k, radiosity[k]);
        return;
    }
    const double* in = field.intensity[slot];
    const double* bins[3] = {in + link.senderBins.index[0] * channels,
                             in + link.senderBins.index[1] * channels,
                             in + link.senderBins.index[2] * channels};
    const double weights[3] = {link.senderBins.Weight(0), link.senderBins.Weight(1),
                               link.senderBins.Weight(2)};
    for (int k = 0; k < channels; ++k) {
        double sent = weights[0] * bins[0][k];
        sent += weights[1] * bins[1][k];
        sent += weights[2] * bins[2][k];
        f(k, sent);
    }
}

// Light of directional source `source` on a node: the lit fraction of its area.
struct SourceLink {
    std::uint32_t source;
    double visibility;
};

// The links of one hierarchy, by receiver node.
struct Links {
    std::vector<std::vector<NodeLink>> node;
    std::vector<std::vector<SourceLink>> source;

    void Resize(std::size_t nodes) {
        node.resize(nodes);
        source.resize(nodes);
    }
    std::size_t Count() const {
        std::size_t count = 0;
        for (const auto& l : node) count += l.size();
        for (const auto& l : source) count += l.size();
        return count;
    }
};

}  // namespace leaflux
