#include "solver/radiosity/closed_exchange.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>

#include "solver/util/box.h"
#include "solver/util/check.h"

namespace leaflux {
namespace {

// Points of a box spread evenly through it: the centres of a 4 × 4 × 4 grid of its cells;
// a receiver's in HeldAroundLinks, the centres of a 4 × 4 grid over it.
constexpr int kCells = 4;
// The least transmittance a held instance's light is taken to have passed on its way out of
// its box, and the deepest optical depth it is taken to have crossed there (a factor 20).
constexpr double kLeastTransmittance = 0.05, kDeepest = 3.0;

// The share of the line x + t ω, t ≥ 0, of the box [lo, hi] (instance frame) over its whole
// chord; 0 when the line misses it.
double ChordShare(const glm::dvec3& x, const glm::dvec3& omega, const glm::dvec3& lo,
                  const glm::dvec3& hi) {
    const BoxSpan span = LineThroughBox(x, omega, lo, hi);
    if (!span.Meets() || span.exit <= 0.0) return 0.0;
    return (span.exit - std::max(span.enter, 0.0)) / (span.exit - span.enter);
}

}  // namespace

Emitters EmittersAlong(const ClosedNode& sender, const glm::dvec3& x, const glm::dvec3& along,
                       double from, double to, double volume, double share) {
    const double length = to - from;
    if (!(length > 0.0)) return {};
    if (!sender.organArea) return {length / volume, from + share * length};
    // The line walked cell by cell (Amanatides & Woo 1987), each piece taken whole: at most
    // one piece per cell plane crossed.
    constexpr int kSide = AreaGrid::kCells;
    struct Piece {
        double from, to, integral;
    };
    std::array<Piece, 3 * kSide + 1> pieces;
    std::size_t count = 0;
    const glm::dvec3 cell = (sender.boxMax - sender.boxMin) / static_cast<double>(kSide);
    const glm::dvec3 start = x + from * along;
    glm::ivec3 at, step;
    glm::dvec3 next, delta;
    for (int a = 0; a < 3; ++a) {
        at[a] = std::clamp(static_cast<int>(std::floor((start[a] - sender.boxMin[a]) / cell[a])), 0,
                           kSide - 1);
        step[a] = along[a] > 0.0 ? 1 : -1;
        if (along[a] == 0.0) {
            next[a] = delta[a] = std::numeric_limits<double>::infinity();
            continue;
        }
        const double plane = sender.boxMin[a] + (at[a] + (along[a] > 0.0 ? 1 : 0)) * cell[a];
        next[a] = (plane - x[a]) / along[a];
        delta[a] = cell[a] / std::abs(along[a]);
    }
    const double perCell = static_cast<double>(AreaGrid::kCount) / volume;
    Emitters e;
    for (double t = from; t < to && count < pieces.size();) {
        const int a = next.x <= next.y ? (next.x <= next.z ? 0 : 2) : (next.y <= next.z ? 1 : 2);
        const double exit = std::min(next[a], to);
        if (exit > t) {
            const int c = AreaGrid::Index(at.x, at.y, at.z);
            const double piece =
                static_cast<double>(sender.organArea->share[c]) * perCell * (exit - t);
            pieces[count++] = {t, exit, piece};
            e.integral += piece;
        }
        t = exit;
        at[a] += step[a];
        if (at[a] < 0 || at[a] >= kSide) break;
        next[a] += delta[a];
    }
    // Where the share of the integral is reached, within its piece's even density.
    double before = 0.0;
    const double target = share * e.integral;
    for (std::size_t k = 0; k < count; ++k) {
        const Piece& piece = pieces[k];
        e.distance = piece.to;
        if (piece.integral > 0.0 && before + piece.integral >= target) {
            e.distance = piece.from + (target - before) / piece.integral * (piece.to - piece.from);
            break;
        }
        before += piece.integral;
    }
    return e;
}

bool BoundsOverlap(const HrcNode& a, const HrcNode& b) {
    return glm::length(b.centroid - a.centroid) < a.radius + b.radius;
}

bool OverlappingClosed(const Hierarchy& hierarchy, std::uint32_t r, std::uint32_t s) {
    return hierarchy[r].closed >= 0 && hierarchy[s].closed >= 0 &&
           BoundsOverlap(hierarchy[r], hierarchy[s]);
}

std::vector<NodeLink> OverlappingClosedLinks(const NodeModel& model, std::uint32_t r,
                                             std::uint32_t s, double visibility) {
    const Hierarchy& hierarchy = model.Nodes();
    const ClosedNode& receiver = hierarchy.Closed()[hierarchy[r].closed];
    const ClosedNode& sender = hierarchy.Closed()[hierarchy[s].closed];
    const DirectionSet& directions = model.Directions();
    const glm::dmat4 receiverFromSender =
        glm::inverse(receiver.sceneFromInstance) * sender.sceneFromInstance;
    const glm::dmat3 receiverFromScene = glm::inverse(glm::dmat3(receiver.sceneFromInstance));
    std::vector<glm::dvec3> points;  // the sender's, in the receiver's frame
    const glm::dvec3 cell = (sender.boxMax - sender.boxMin) / static_cast<double>(kCells);
    for (int i = 0; i < kCells; ++i) {
        for (int j = 0; j < kCells; ++j) {
            for (int k = 0; k < kCells; ++k) {
                const glm::dvec3 p = sender.boxMin + cell * glm::dvec3(i + 0.5, j + 0.5, k + 0.5);
                points.emplace_back(receiverFromSender * glm::dvec4(p, 1.0));
            }
        }
    }
    std::vector<NodeLink> links;
    for (int d = 0; d < directions.Size(); ++d) {
        const glm::dvec3& omega = directions.Direction(d);  // the way the light goes
        const double facing = model.ProjectedArea(r, -omega);
        if (facing <= 0.0) continue;
        const glm::dvec3 along = glm::normalize(receiverFromScene * omega);
        const double tau = std::clamp(receiver.contents->Transmittance(along), 0.0, 1.0);
        double stopped = 0.0;
        for (const glm::dvec3& x : points) {
            const double share = ChordShare(x, along, receiver.boxMin, receiver.boxMax);
            if (share > 0.0) stopped += 1.0 - std::pow(tau, share);
        }
        stopped /= static_cast<double>(points.size());
        if (stopped <= 0.0) continue;
        NodeLink link;
        link.sender = s;
        link.ownRays = true;  // its visibility is the pair's, valued once
        link.toSender = glm::vec3(-omega);
        link.transfer[0] =
            static_cast<float>(visibility * directions.HatIntegralSr(d) * stopped / facing);
        link.receiverBins = Locate(directions, -omega);
        link.senderBins.index = {static_cast<std::uint16_t>(d), static_cast<std::uint16_t>(d),
                                 static_cast<std::uint16_t>(d)};
        link.senderBins.weight = {static_cast<std::uint16_t>(BinWeights::kUnit), 0};
        link.reach = -1.0f;  // neither end can be split: it stands whatever it carries
        link.geometricError = 1.0f;
        links.push_back(link);
    }
    return links;
}

std::vector<double> HeldDepths(const ClosedNode& node, const DirectionSet& directions) {
    std::vector<double> depths(directions.Size());
    for (int d = 0; d < directions.Size(); ++d) {
        const glm::dvec3& omega = directions.Direction(d);
        depths[d] = -std::log(std::clamp(node.contents->Transmittance(node.ToInstance(omega)),
                                         kLeastTransmittance, 1.0)) *
                    node.BoxProjectedArea(omega);
    }
    return depths;
}

std::vector<NodeLink> HeldAroundLinks(
    const NodeModel& model, std::uint32_t r, std::uint32_t s,
    const std::function<double(const Hierarchy::Point&, const glm::dvec3&, double)>& passed,
    std::int64_t& rays) {
    const Hierarchy& hierarchy = model.Nodes();
    const ClosedNode& sender = hierarchy.Closed()[hierarchy[s].closed];
    const DirectionSet& directions = model.Directions();
    const glm::dmat4 instanceFromScene = glm::inverse(sender.sceneFromInstance);
    const glm::dmat3 linear(instanceFromScene);
    const glm::dvec3 size = sender.boxMax - sender.boxMin;
    const double volume =
        size.x * size.y * size.z / std::abs(glm::determinant(linear));  // the scene's m³
    if (!(volume > 0.0)) return {};
    // r's points, spread over its area (in the sender's frame).
    std::vector<Hierarchy::Point> at;
    std::vector<glm::dvec3> points;
    for (int i = 0; i < kCells; ++i) {
        for (int j = 0; j < kCells; ++j) {
            at.push_back(hierarchy.Sample(r, (i + 0.5) / kCells, (j + 0.5) / kCells));
            points.emplace_back(instanceFromScene * glm::dvec4(at.back().position, 1.0));
        }
    }
    // The light arriving inside the box is not yet dimmed by the organs it has still to pass
    // on its way out, which I(ω) holds: per unit of ∫ e dℓ between the point and where the
    // light leaves the box, the box's mean optical depth along ω.
    const std::vector<double>& depths = sender.heldDepth;
    LEAFLUX_CHECK(depths.size() == static_cast<std::size_t>(directions.Size()));
    std::vector<NodeLink> links;
    for (int d = 0; d < directions.Size(); ++d) {
        const glm::dvec3& omega = directions.Direction(d);  // the way the light goes
        const glm::dvec3 back = linear * -omega;            // towards where it comes from
        // The mean over r's points, by their area facing the light, of ∫ e dℓ (1/m²) as far
        // as seen from each.
        double behind = 0.0;
        const double depth = depths[d];
        // A point of each row of r's grid, in a column that turns with the bin: each bin
        // sees r's whole extent, and the bins together every point.
        double weights = 0.0;
        for (int row = 0; row < kCells; ++row) {
            const int column = (row + d) % kCells;
            const std::size_t i = row * kCells + column;
            // Each point by its area facing the light, as a link's rays are (Between).
            const double weight = model.ReceivingWeight(at[i].triangle, at[i].normal, -omega);
            weights += weight;
            if (weight <= 0.0) continue;
            const BoxSpan span = LineThroughBox(points[i], back, sender.boxMin, sender.boxMax);
            if (!span.Meets() || span.exit <= 0.0) continue;
            const double from = std::max(span.enter, 0.0);
            // Seen as far as a point of the emitters behind, a share (column + ½) / kCells
            // of them nearer: the organs between stop the light of the nearer ones less
            // than that of the farther, and a ray to where they are centred took the
            // farther ones' share for all of them.
            const Emitters behindPoint = EmittersAlong(sender, points[i], back, from, span.exit,
                                                       volume, (column + 0.5) / kCells);
            if (behindPoint.integral <= 0.0) continue;
            const double ahead =
                span.enter < 0.0
                    ? EmittersAlong(sender, points[i], back, span.enter, 0.0, volume).integral
                    : 0.0;
            ++rays;
            behind += weight * behindPoint.integral * std::exp(std::min(depth * ahead, kDeepest)) *
                      passed(at[i], -omega, behindPoint.distance);
        }
        if (behind <= 0.0) continue;
        behind /= weights;
        NodeLink link;
        link.sender = s;
        link.ownRays = true;  // its rays traced here
        link.toSender = glm::vec3(-omega);
        link.transfer[0] = static_cast<float>(directions.HatIntegralSr(d) * behind);
        link.receiverBins = Locate(directions, -omega);
        link.senderBins.index = {static_cast<std::uint16_t>(d), static_cast<std::uint16_t>(d),
                                 static_cast<std::uint16_t>(d)};
        link.senderBins.weight = {static_cast<std::uint16_t>(BinWeights::kUnit), 0};
        link.reach = -1.0f;  // it stands whatever it carries
        link.geometricError = 1.0f;
        links.push_back(link);
    }
    return links;
}

}  // namespace leaflux
