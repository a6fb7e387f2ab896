// A scene's originals through the phase-function database (Soler 2003 §5): computed once
// per signature from its representative, reused on the next cycle, by a restarted
// process, and recomputed when what they depend on changes.
#include "solver/instancing/scene_originals.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "solver/generate/generator.h"

namespace leaflux {
namespace {
namespace fs = std::filesystem;

Scene Tree(int leaves, double nirReflectance = 0.45) {
    Scene scene;
    scene.bands = {{"PAR"}, {"NIR"}};
    scene.optics = {{"leaf", {{0.08, 0.06, 0.05, 0.05}, {nirReflectance, 0.4, 0.45, 0.45}}},
                    {"stem", {{0.1, 0.1, 0.0, 0.0}, {0.3, 0.3, 0.0, 0.0}}}};
    TreeParameters tree;
    tree.leafCount = leaves;
    AddTree(scene, tree, {0, 0, 0});
    return scene;
}

InstancingPolicy Shoots() {
    InstancingPolicy policy;
    policy.species = "generated";
    policy.instanceTypes = {NodeType::kAxis};
    policy.leafCount.edges = {1, 11, 101, 1001};
    policy.phase = {PhaseKind::kMonoDirectional, 2};
    policy.transmittance = {PhaseKind::kMonoDirectional, 2};
    return policy;
}

OriginalSettings Quick() {
    OriginalSettings settings;
    settings.raysPerDirection = 1024;
    return settings;
}

TEST(SceneOriginals, ComputedOncePerSignatureThenReusedAcrossCyclesAndRestarts) {
    const fs::path file =
        fs::temp_directory_path() / ("leaflux_originals_" + std::to_string(getpid()) + ".db");
    fs::remove(file);
    const Scene scene = Tree(150);
    const InstancingPolicy policy = Shoots();
    const SceneSignatures signatures = ComputeSignatures(scene, policy);
    ASSERT_GE(signatures.groups.size(), 2u);
    std::map<std::string, std::vector<float>> first;
    {
        PhaseDatabase database({file.string()});
        const SceneOriginals cycle1 = OriginalsOf(scene, signatures, policy, Quick(), database);
        EXPECT_EQ(cycle1.computed, static_cast<int>(signatures.groups.size()));
        EXPECT_EQ(cycle1.reused, 0);
        EXPECT_GT(cycle1.computeSeconds, 0.0);
        for (const auto& [signature, original] : cycle1.bySignature) {
            ASSERT_TRUE(original);
            EXPECT_EQ(original->phase.Kind(), PhaseKind::kMonoDirectional);
            EXPECT_EQ(original->provenance.method, "hr");
            first[signature].assign(original->phase.Values().begin(),
                                    original->phase.Values().end());
        }
        // The next cycle of the same plants.
        const SceneOriginals cycle2 = OriginalsOf(scene, signatures, policy, Quick(), database);
        EXPECT_EQ(cycle2.computed, 0);
        EXPECT_EQ(cycle2.reused, static_cast<int>(signatures.groups.size()));
        EXPECT_EQ(cycle2.computeSeconds, 0.0);
    }
    {
        // A restarted process: every function from the file, as it was.
        PhaseDatabase database({file.string()});
        const SceneOriginals again = OriginalsOf(scene, signatures, policy, Quick(), database);
        EXPECT_EQ(again.computed, 0);
        EXPECT_EQ(database.Stats().diskHits, static_cast<std::int64_t>(signatures.groups.size()));
        for (const auto& [signature, original] : again.bySignature) {
            const std::vector<float> values(original->phase.Values().begin(),
                                            original->phase.Values().end());
            EXPECT_EQ(values, first[signature]) << signature;
        }
        // Other optics, other functions: every one computed again.
        const Scene paler = Tree(150, 0.5);
        const SceneOriginals other =
            OriginalsOf(paler, ComputeSignatures(paler, policy), policy, Quick(), database);
        EXPECT_EQ(other.computed, static_cast<int>(signatures.groups.size()));
        // A finer function is another key too.
        InstancingPolicy finer = policy;
        finer.phase.level = 3;
        EXPECT_EQ(OriginalsOf(scene, signatures, finer, Quick(), database).computed,
                  static_cast<int>(signatures.groups.size()));
    }
    fs::remove(file);
    fs::remove(file.string() + "-wal");
    fs::remove(file.string() + "-shm");
}

TEST(SceneOriginals, ARepresentativesFunctionsAreItsOwnStructuresFunctions) {
    // The stored original is the representative's, in its own frame: computing that
    // structure alone again gives the same values.
    const Scene scene = Tree(120);
    const InstancingPolicy policy = Shoots();
    const SceneSignatures signatures = ComputeSignatures(scene, policy);
    PhaseDatabase database({});
    const SceneOriginals originals = OriginalsOf(scene, signatures, policy, Quick(), database);
    for (const SignatureGroup& group : signatures.groups) {
        const Original direct = ComputeOriginal(StructureAlone(scene, group.representative),
                                                SettingsOf(policy, Quick()));
        const Original& stored = *originals.bySignature.at(group.signature);
        ASSERT_EQ(stored.phase.Values().size(), direct.phase.Values().size());
        for (std::size_t k = 0; k < direct.phase.Values().size(); ++k)
            EXPECT_EQ(stored.phase.Values()[k], direct.phase.Values()[k]) << group.signature;
        EXPECT_EQ(stored.provenance.leafCount, direct.provenance.leafCount);
    }
}

}  // namespace
}  // namespace leaflux
