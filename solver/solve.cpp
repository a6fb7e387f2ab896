#include "solver/solve.h"

#include <optional>

#include "solver/util/error.h"

namespace leaflux {

PreparedScene::PreparedScene(const Scene& scene) : PreparedScene(scene, Flatten(scene)) {}

PreparedScene::PreparedScene(const Scene& scene, FlatScene flat)
    : scene_(scene), flat_(std::move(flat)) {
    std::optional<PeriodicDomain> periodic;
    if (scene.periodic) {
        // The ray engine works in the flat scene's frame, centred on its bounds.
        periodic = *scene.periodic;
        periodic->xMin -= flat_.origin.x;
        periodic->xMax -= flat_.origin.x;
        periodic->yMin -= flat_.origin.y;
        periodic->yMax -= flat_.origin.y;
    }
    rays_ = std::make_unique<RayScene>(flat_, periodic);
}

Solution Solve(const PreparedScene& prepared, const SolverSettings& settings) {
    switch (settings.kind) {
        case SolverKind::kMonteCarlo:
            return SolveReference(prepared.Source(), prepared.Flat(), prepared.Rays(),
                                  settings.monteCarlo);
        case SolverKind::kHrc:
            // Links do not wrap around a periodic tile yet: say so rather than lose the light
            // that crosses its sides.
            if (prepared.Source().periodic) {
                throw InputError(ErrorCode::kUnsupported, "periodic",
                                 "the hrc solver does not handle periodic domains yet: use mc");
            }
            return SolveHrc(prepared.Source(), prepared.Flat(), prepared.Rays(), settings.hrc);
        case SolverKind::kInstanced: {
            const InstancedSettings& instanced = settings.instanced;
            std::optional<PhaseDatabase> own;
            PhaseDatabase* database = instanced.database;
            if (database == nullptr) database = &own.emplace(PhaseDatabaseOptions{});
            InstancedOptions options;
            options.hrc = settings.hrc;
            options.originals = instanced.originals;
            options.maxDepth = instanced.maxDepth;
            options.outputLevel = instanced.outputLevel;
            options.pushDown = instanced.pushDown;
            options.holdOutside = instanced.holdOutside;
            options.mergeTriangles = instanced.mergeTriangles;
            InstancedSolution solved =
                SolveInstanced(prepared.Source(), prepared.Flat(),
                               instanced.shadowsByGeometry ? &prepared.Rays() : nullptr,
                               instanced.policy, *database, options);
            if (instanced.stats != nullptr) *instanced.stats = std::move(solved.stats);
            return std::move(solved.solution);
        }
    }
    return {};
}

}  // namespace leaflux
