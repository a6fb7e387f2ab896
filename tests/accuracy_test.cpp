// The accuracy figures of `leaflux bench error` (solver/results/accuracy.h): by hand on a small
// scene, and the reference floor against the spread of two Monte Carlo solutions.
#include "solver/results/accuracy.h"

#include <gtest/gtest.h>

#include <cmath>

#include "solver/generate/generator.h"
#include "solver/solve.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {

using testing::OneBandScene;
using testing::OrganNode;
using testing::Rectangle;

// Four leaves and a ground square; light set by hand, not solved.
struct HandMadeCase {
    Scene scene;
    FlatScene flat;

    HandMadeCase() {
        scene = OneBandScene({{"leaf", testing::Leaf(0.1, 0.1)}, {"ground", testing::Opaque(0.2)}});
        for (NodeId id = 1; id <= 4; ++id) {
            scene.nodes.push_back(OrganNode(id, "leaf" + std::to_string(id),
                                            Rectangle(0.1, 0.1, static_cast<double>(id)), "leaf"));
        }
        scene.environment.push_back({"ground", Rectangle(5, 5, 0), "ground"});
        scene.Validate();
        flat = Flatten(scene);
    }

    // Upper and lower irradiance of the four leaves (W/m²), the ground's set far off.
    Solution Light(std::vector<std::pair<double, double>> leaves, double stderrWm2 = -1.0) const {
        Solution solution;
        solution.balance.resize(1);
        solution.light.assign(flat.receivers.size(), 1);
        if (stderrWm2 >= 0.0) solution.error.assign(flat.receivers.size(), 1);
        for (std::size_t r = 0; r < flat.receivers.size(); ++r) {
            BandLight& light = solution.light[r][0];
            if (stderrWm2 >= 0.0) solution.error[r][0] = {stderrWm2, stderrWm2, 0.0};
            if (flat.receivers[r].kind != ReceiverKind::kOrgan) {
                light.irradianceUpperWm2 = 1e6;  // not a leaf: must not count
                continue;
            }
            const auto [upper, lower] = leaves.at(flat.receivers[r].node - 1);
            light.irradianceUpperWm2 = upper;
            light.irradianceLowerWm2 = lower;
        }
        return solution;
    }
};

TEST(LeafAccuracy, MatchesTheFiguresWorkedByHand) {
    const HandMadeCase c;
    // Both sides summed: reference 100, 50, 10, 2 W/m² (the last below 5 % of 100: unlit).
    const Solution reference = c.Light({{80, 20}, {50, 0}, {5, 5}, {1, 1}}, 3.0);
    const Solution value = c.Light({{90, 20}, {45, 0}, {5, 6}, {3, 1}});
    const std::vector<BandAccuracy> accuracy = CompareLeaves(c.scene, c.flat, reference, value);
    ASSERT_EQ(accuracy.size(), 1u);
    const BandAccuracy& a = accuracy[0];
    EXPECT_EQ(a.leaves, 4);
    EXPECT_EQ(a.litLeaves, 3);
    EXPECT_DOUBLE_EQ(a.referenceMaxWm2, 100.0);
    // Errors +10, −5, +1, +2: RMS √(130/4).
    EXPECT_NEAR(a.l2PctOfMax, 100.0 * std::sqrt(130.0 / 4.0) / 100.0, 1e-12);
    // Relative errors of the lit leaves: 10 %, 10 %, 10 %.
    EXPECT_NEAR(a.meanRelativePct, 10.0, 1e-12);
    EXPECT_NEAR(a.p95RelativePct, 10.0, 1e-12);
    // Standard error 3 W/m² a side: √(9 + 9) a leaf, in % of 100.
    EXPECT_NEAR(a.referenceFloorPct, std::sqrt(18.0), 1e-12);
}

TEST(LeafAccuracy, TheReferenceAgainstItselfIsExactAndADarkSceneGivesZeros) {
    const HandMadeCase c;
    const Solution reference = c.Light({{80, 20}, {50, 0}, {5, 5}, {1, 1}});
    const BandAccuracy same = CompareLeaves(c.scene, c.flat, reference, reference)[0];
    EXPECT_EQ(same.l2PctOfMax, 0.0);
    EXPECT_EQ(same.p95RelativePct, 0.0);
    EXPECT_EQ(same.referenceFloorPct, 0.0);  // no standard error given
    const Solution dark = c.Light({{0, 0}, {0, 0}, {0, 0}, {0, 0}});
    const BandAccuracy none = CompareLeaves(c.scene, c.flat, dark, reference)[0];
    EXPECT_EQ(none.litLeaves, 0);
    EXPECT_EQ(none.l2PctOfMax, 0.0);
}

// Two Monte Carlo solutions of other seeds differ by their own noise: the L2 difference
// is √2 times the floor each reports. Over 300 leaves (600 sides) the sum of squares is
// known to ≈ √(2/600) ≈ 6 %, its root to 3 %, and the 16-replicate standard errors add
// their own spread of ≈ 1/√(2·15·600): the ratio stays within 15 % (≈ 4σ) unless the
// floor is not a standard error.
TEST(LeafAccuracy, TheFloorIsTheSpreadOfTheMonteCarloNoise) {
    Scene scene;
    scene.bands = {{"PAR"}};
    scene.optics = {{"leaf", {testing::Leaf(0.3, 0.3)}}};
    CanopyParameters canopy;
    canopy.leaves = 300;
    AddRandomCanopy(scene, canopy);
    scene.sources.suns.push_back(testing::SunAt(50, 30, 500));
    scene.sources.skies.push_back({SkyModel::kUniform, {100}, SkyDiscretization::kTurtle46});
    scene.Validate();
    const PreparedScene prepared(scene);
    SolverSettings settings;
    settings.monteCarlo.samplesPerReceiver = 256;
    settings.monteCarlo.seed = 1;
    const Solution first = Solve(prepared, settings);
    settings.monteCarlo.seed = 2;
    const Solution second = Solve(prepared, settings);
    const BandAccuracy a = CompareLeaves(scene, prepared.Flat(), first, second)[0];
    const BandAccuracy b = CompareLeaves(scene, prepared.Flat(), second, first)[0];
    const double floors = std::hypot(a.referenceFloorPct,
                                     b.referenceFloorPct * b.referenceMaxWm2 / a.referenceMaxWm2);
    EXPECT_GT(a.referenceFloorPct, 0.0);
    EXPECT_NEAR(a.l2PctOfMax / floors, 1.0, 0.15)
        << "L2 " << a.l2PctOfMax << " %, floors " << a.referenceFloorPct << " and "
        << b.referenceFloorPct << " %";
}

}  // namespace
}  // namespace leaflux
