// The originals a scene's instances share (Soler 2003 §5, "Instantiation Database"): one
// per signature group of the policy, taken from the phase-function database, or computed
// from the group's representative structure on a miss and stored there, so that a later
// cycle, another session of the species or a restarted process reuses it.
#pragma once

#include <map>
#include <memory>
#include <set>
#include <string>

#include "solver/instancing/compute_original.h"
#include "solver/instancing/phase_db.h"
#include "solver/instancing/phase_key.h"
#include "solver/instancing/signature.h"

namespace leaflux {

// A content hash of what the functions' light depends on in the scene: its bands' names
// and every optics' id and values.
std::string OpticsContentHash(const Scene& scene);

// The settings the policy sets (kinds and levels of f and τ) over `accuracy`'s others.
OriginalSettings SettingsOf(const InstancingPolicy& policy, OriginalSettings accuracy);

// The key of a group's original.
PhaseKey KeyOf(const std::string& species, const InstancingPolicy& policy,
               const std::string& signature, const Scene& scene, const OriginalSettings& settings);

struct SceneOriginals {
    std::map<std::string, std::shared_ptr<const Original>> bySignature;
    int computed = 0;  // missing from the database (or a bad row), computed now
    int reused = 0;    // from memory or the file, or computed meanwhile by another caller
    double computeSeconds = 0.0;  // spent computing the missing ones
    // Spent finding the others: reading them from the file, or awaiting another caller's
    // computation of them.
    double reuseSeconds = 0.0;
};

// `needed`: the signatures whose originals are asked (empty: every group's).
SceneOriginals OriginalsOf(const Scene& scene, const SceneSignatures& signatures,
                           const InstancingPolicy& policy, const OriginalSettings& accuracy,
                           PhaseDatabase& database, const std::set<std::string>& needed = {});

}  // namespace leaflux
