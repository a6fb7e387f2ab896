#include "solver/instancing/scene_originals.h"

#include <chrono>

#include "solver/instancing/structure.h"
#include "solver/util/content_hash.h"

namespace leaflux {

std::string OpticsContentHash(const Scene& scene) {
    ContentHash hash;
    hash.Add(static_cast<std::uint64_t>(scene.bands.size()));
    for (const Band& band : scene.bands) hash.Add(band.name);
    hash.Add(static_cast<std::uint64_t>(scene.optics.size()));
    for (const Optics& optics : scene.optics) {
        hash.Add(optics.id);
        for (const BandOptics& b : optics.bands)
            hash.Add(b.rhoUpper).Add(b.rhoLower).Add(b.tauUpperToLower).Add(b.tauLowerToUpper);
    }
    return hash.Hex();
}

OriginalSettings SettingsOf(const InstancingPolicy& policy, OriginalSettings accuracy) {
    accuracy.kind = policy.phase.kind;
    accuracy.phaseLevel = policy.phase.level;
    accuracy.transmittanceKind = policy.transmittance.kind;
    accuracy.transmittanceLevel =
        policy.transmittance.kind == PhaseKind::kConstant ? 2 : policy.transmittance.level;
    return accuracy;
}

PhaseKey KeyOf(const std::string& species, const InstancingPolicy& policy,
               const std::string& signature, const Scene& scene, const OriginalSettings& settings) {
    PhaseKey key;
    key.species = species;
    key.policyHash = PolicyContentHash(policy);
    key.signature = signature;
    key.opticsHash = OpticsContentHash(scene);
    for (const Band& band : scene.bands) key.bands.push_back(band.name);
    key.kind = settings.kind;
    key.directionLevel = settings.kind == PhaseKind::kConstant ? 0 : settings.phaseLevel;
    key.settings = settings.Describe();
    return key;
}

SceneOriginals OriginalsOf(const Scene& scene, const SceneSignatures& signatures,
                           const InstancingPolicy& policy, const OriginalSettings& accuracy,
                           PhaseDatabase& database, const std::set<std::string>& needed) {
    const OriginalSettings settings = SettingsOf(policy, accuracy);
    SceneOriginals originals;
    for (const SignatureGroup& group : signatures.groups) {
        if (!needed.empty() && !needed.contains(group.signature)) continue;
        OriginalSettings own = settings;
        if (own.method == PhaseMethod::kRadiosity &&
            signatures.Find(group.representative)->leafCount > own.radiosityLeavesAtMost)
            own.method = PhaseMethod::kPhotons;
        const PhaseKey key = KeyOf(policy.species, policy, group.signature, scene, own);
        double seconds = 0.0;
        const auto asked = std::chrono::steady_clock::now();
        const PhaseLookup lookup = database.GetOrCompute(key, [&] {
            const auto start = std::chrono::steady_clock::now();
            Original original = ComputeOriginal(StructureAlone(scene, group.representative), own);
            seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            return original;
        });
        const bool computed =
            lookup.source == PhaseSource::kComputed || lookup.source == PhaseSource::kRecomputed;
        originals.computed += computed;
        originals.reused += !computed;
        originals.computeSeconds += seconds;
        if (!computed) {
            originals.reuseSeconds +=
                std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
        }
        originals.bySignature[group.signature] = lookup.original;
    }
    return originals;
}

}  // namespace leaflux
