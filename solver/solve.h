// The small solver API the server and the command line call: one scene in, light out.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "solver/instancing/instanced.h"
#include "solver/radiosity/hrc.h"
#include "solver/raytrace/raytrace.h"
#include "solver/reference/reference.h"
#include "solver/results/light.h"

namespace leaflux {

enum class SolverKind { kMonteCarlo, kHrc, kInstanced };

// The instanced solver's: its policy, the database its originals come from and go to,
// and what direct light meets (instanced.h). Its radiosity settings are `hrc`'s.
struct InstancedSettings {
    InstancingPolicy policy;            // required: a policy with an instance type
    PhaseDatabase* database = nullptr;  // null: one in memory for this solve
    OriginalSettings originals;
    bool shadowsByGeometry = true;
    int maxDepth = 0;                     // InstancedOptions::maxDepth
    std::optional<NodeType> outputLevel;  // InstancedOptions::outputLevel
    bool pushDown = false;                // InstancedOptions::pushDown
    bool holdOutside = true;              // InstancedOptions::holdOutside
    std::int64_t mergeTriangles = 0;      // InstancedOptions::mergeTriangles
    // Filled by the solve when not null: its instances, local problems and originals.
    InstancedStats* stats = nullptr;
};

struct SolverSettings {
    SolverKind kind = SolverKind::kMonteCarlo;
    ReferenceOptions monteCarlo;
    HrcOptions hrc;
    InstancedSettings instanced;
};

// A scene prepared for solving: flattened and committed to the ray engine. Build it once
// and solve it as often as needed (other seeds, other settings).
class PreparedScene {
  public:
    explicit PreparedScene(const Scene& scene);  // scene must be valid and outlive this
    // With the scene already flattened (SceneStore::Flat).
    PreparedScene(const Scene& scene, FlatScene flat);

    const Scene& Source() const { return scene_; }
    const FlatScene& Flat() const { return flat_; }
    const RayScene& Rays() const { return *rays_; }

  private:
    const Scene& scene_;
    FlatScene flat_;
    std::unique_ptr<RayScene> rays_;
};

Solution Solve(const PreparedScene& prepared, const SolverSettings& settings);

}  // namespace leaflux
