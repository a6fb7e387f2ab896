#include "solver/scene/copies.h"

#include <algorithm>
#include <cstring>
#include <unordered_map>

#include "solver/scene/topology.h"
#include "solver/scene/world_frames.h"

namespace leaflux {
namespace {

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

// An organ of a plant: its node's index, its mesh, and its frame in the plant root's.
struct PlantOrgan {
    std::uint32_t node = 0;
    const Mesh* mesh = nullptr;
    glm::dmat4 frame{1.0};

    bool operator==(const PlantOrgan& o) const { return mesh == o.mesh && frame == o.frame; }
};

std::uint64_t Mix(std::uint64_t hash, std::uint64_t value) {
    // FNV-1a's prime on 64-bit words, with a rotation so that equal words do not cancel.
    hash ^= value + 0x9E3779B97F4A7C15ull + (hash << 6) + (hash >> 2);
    return hash * 0x100000001B3ull;
}

class Plants {
  public:
    Plants(const Scene& scene, const FlatScene& flat) : scene_(scene), topology_(scene) {
        receiverOf_.assign(scene.nodes.size(), kNone);
        for (std::uint32_t r = 0; r < flat.receivers.size(); ++r) {
            if (flat.receivers[r].kind == ReceiverKind::kOrgan)
                receiverOf_[flat.receivers[r].declared] = r;
        }
    }
    const std::vector<std::uint32_t>& Roots() const { return topology_.Roots(); }

    // The organs under `root` in the nodes' order (that of their receivers); false when
    // their receivers are not consecutive.
    bool Organs(std::uint32_t root, std::vector<PlantOrgan>& organs) const {
        organs.clear();
        ForEachFrameUnder(scene_, topology_, root, glm::dmat4(1.0),
                          [&](const Node& node, const glm::dmat4& frame) {
                              if (!node.organ()) return;
                              const auto n =
                                  static_cast<std::uint32_t>(&node - scene_.nodes.data());
                              organs.push_back({n, node.organ()->mesh.get(), frame});
                          });
        std::sort(organs.begin(), organs.end(),
                  [](const PlantOrgan& a, const PlantOrgan& b) { return a.node < b.node; });
        for (std::size_t k = 0; k < organs.size(); ++k) {
            if (receiverOf_[organs[k].node] != receiverOf_[organs[0].node] + k) return false;
        }
        return !organs.empty();
    }
    std::uint32_t FirstReceiver(const std::vector<PlantOrgan>& organs) const {
        return receiverOf_[organs.front().node];
    }
    glm::dmat4 RootFrame(std::uint32_t root) const {
        return glm::dmat4(scene_.nodes[root].parentFromLocal());
    }

  private:
    const Scene& scene_;
    Topology topology_;
    std::vector<std::uint32_t> receiverOf_;
};

std::uint64_t HashOf(const std::vector<PlantOrgan>& organs) {
    std::uint64_t hash = 0xCBF29CE484222325ull;
    for (const PlantOrgan& organ : organs) {
        hash = Mix(hash, reinterpret_cast<std::uintptr_t>(organ.mesh));
        for (int c = 0; c < 4; ++c) {
            for (int r = 0; r < 3; ++r) {
                std::uint64_t bits;
                std::memcpy(&bits, &organ.frame[c][r], sizeof bits);
                hash = Mix(hash, bits);
            }
        }
    }
    return Mix(hash, organs.size());
}

}  // namespace

std::vector<PlantCopy> FindCopies(const Scene& scene, const FlatScene& flat) {
    const Plants plants(scene, flat);
    if (plants.Roots().size() < 2) return {};
    // Each plant's organs' hash, in the order of their receivers: the first plant of each
    // kind is its original, which the engine holds before its copies, and the others may
    // copy it; their organs are compared whole before a plant is taken as a copy.
    struct Plant {
        std::uint32_t firstReceiver, root;
        std::uint64_t hash;
    };
    std::vector<Plant> kinds;
    std::vector<PlantOrgan> organs, original;
    for (const std::uint32_t root : plants.Roots()) {
        if (plants.Organs(root, organs))
            kinds.push_back({plants.FirstReceiver(organs), root, HashOf(organs)});
    }
    std::sort(kinds.begin(), kinds.end(),
              [](const Plant& a, const Plant& b) { return a.firstReceiver < b.firstReceiver; });
    std::unordered_map<std::uint64_t, std::uint32_t> originalOf;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> candidates;  // (plant, original)
    for (const Plant& plant : kinds) {
        const auto [at, added] = originalOf.emplace(plant.hash, plant.root);
        if (!added) candidates.emplace_back(plant.root, at->second);
    }
    // By original, so that each original's organs are gathered once.
    std::sort(candidates.begin(), candidates.end(),
              [](const auto& a, const auto& b) { return a.second < b.second; });
    std::vector<PlantCopy> copies;
    std::uint32_t held = kNone;  // the original whose organs `original` holds
    for (const auto& [root, by] : candidates) {
        if (held != by) {
            plants.Organs(by, original);
            held = by;
        }
        plants.Organs(root, organs);
        if (organs != original) continue;
        PlantCopy copy;
        copy.firstReceiver = plants.FirstReceiver(organs);
        copy.receivers = static_cast<std::uint32_t>(organs.size());
        copy.original = plants.FirstReceiver(original);
        copy.moved = plants.RootFrame(root) * glm::inverse(plants.RootFrame(by));
        copies.push_back(copy);
    }
    std::sort(copies.begin(), copies.end(), [](const PlantCopy& a, const PlantCopy& b) {
        return a.firstReceiver < b.firstReceiver;
    });
    return copies;
}

}  // namespace leaflux
