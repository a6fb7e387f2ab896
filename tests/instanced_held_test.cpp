// What an opened instance holds from around it and lights its leaves with: the ground, the
// room's walls and lamps, and the crowns grown into it, against the flattened scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "server/policy_proto.h"
#include "solver/instancing/instanced.h"
#include "solver/solve.h"
#include "tests/instanced_scenes.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {

using testing::Copies, testing::Hrc, testing::Plants, testing::PlantsInstanced;

// The mean light on the leaves' upper and lower sides, per band.
std::array<std::vector<double>, 2> MeanSidesWm2(const FlatScene& flat, const Solution& solution) {
    std::array<std::vector<double>, 2> mean;
    mean.fill(std::vector<double>(solution.balance.size(), 0.0));
    double area = 0.0;
    for (std::size_t r = 0; r < flat.receivers.size(); ++r) {
        if (flat.receivers[r].kind != ReceiverKind::kOrgan) continue;
        area += flat.receivers[r].areaM2;
        for (std::size_t b = 0; b < solution.balance.size(); ++b) {
            const BandLight& light = solution.light[r][b];
            mean[0][b] += flat.receivers[r].areaM2 * light.irradianceUpperWm2;
            mean[1][b] += flat.receivers[r].areaM2 * light.irradianceLowerWm2;
        }
    }
    for (auto& side : mean) {
        for (double& m : side) m /= area;
    }
    return mean;
}

// The scene instantiated by `policy` (its plants) and flattened (HRC), both at `epsilon`:
// the leaves' mean light on each side, per band, within `bound` of the flattened scene's
// (a fraction per side and band; an empty side is not checked).
void ExpectSidesNearFlattened(const Scene& scene, double epsilon,
                              const std::array<std::vector<double>, 2>& bound,
                              const InstancingPolicy& policy = Plants()) {
    const PreparedScene prepared(scene);
    const Solution hrc = Hrc(prepared, epsilon);
    PhaseDatabase database({});
    InstancedOptions options;
    options.hrc.epsilon = epsilon;
    const InstancedSolution instanced =
        SolveInstanced(scene, prepared.Flat(), &prepared.Rays(), policy, database, options);
    ASSERT_GE(instanced.stats.depths.size(), 2u);
    const auto flat = MeanSidesWm2(prepared.Flat(), hrc);
    const auto opened = MeanSidesWm2(prepared.Flat(), instanced.solution);
    for (int side : {0, 1}) {
        for (std::size_t b = 0; b < bound[side].size(); ++b) {
            std::printf("band %zu: %s sides %.3f W/m2 instanced, %.3f flattened (%+.2f %%)\n", b,
                        side == 0 ? "upper" : "lower", opened[side][b], flat[side][b],
                        100.0 * (opened[side][b] / flat[side][b] - 1.0));
            EXPECT_NEAR(opened[side][b], flat[side][b], bound[side][b] * flat[side][b]);
        }
    }
}

void ExpectLowerSidesNearFlattened(const Scene& scene, const std::vector<double>& bound) {
    ExpectSidesNearFlattened(scene, 1e-5, {std::vector<double>{}, bound});
}

// A tree over a bright ground, which its crown shades: what the ground sends its leaves'
// lower sides is what the ground under them sends, in its shadow, not what the crown's
// centre sees of it, and an opened instance holds the ground to take it so. The ground's
// light held per bin over the instance gave the lower sides 7.6 % (PAR) and 6.8 % (NIR)
// more than the flattened scene's HRC, at ε = 1e-4 as at 1e-5; held as a sender, −2.3 %
// and −2.3 % at 1e-5 (the test prints them; −7.3 % and −6.8 % at 1e-4, where the held
// ground's links are coarser than HRC's, which is within 0.9 % at 1e-4). Bound: 3 %.
TEST(Instanced, AShadedGroundLightsTheLowerSidesFromUnderThem) {
    Scene scene = Copies(1, 300);
    scene.optics.push_back({"ground", {{0.6, 0.6, 0.0, 0.0}, {0.6, 0.6, 0.0, 0.0}}});
    scene.environment.push_back({"ground", testing::Rectangle(6, 6, 0), "ground"});
    scene.Validate();
    ExpectLowerSidesNearFlattened(scene, {0.03, 0.03});
}

// Eight small plants in a greenhouse at night, in two rows: white walls and floor round
// them, a lamp bar above each row, nothing from the sky; plants and axes instances (the
// default policy). An opened instance holds the room's surfaces as the levels round it
// solved them, each surface one sender (Emitter::triangleExitanceWm2) that its hierarchy
// clusters as they did, and a lamp bar's pieces as a lamp, which splits the clusters of
// organs it lights rather than itself (NodeModel::Lamp). `black`: nothing scatters, and
// what the leaves get is the lamps' light through the pieces held.
Scene Greenhouse(bool black) {
    Scene scene;
    scene.bands = {{"PAR"}, {"NIR"}};
    const auto optics = [&](const char* id, double par, double nir) {
        const double rho = black ? 0.0 : 1.0;
        scene.optics.push_back(
            {id, {{rho * par, rho * par, 0.0, 0.0}, {rho * nir, rho * nir, 0.0, 0.0}}});
    };
    optics("leaf", 0.1, 0.45);
    optics("stem", 0.1, 0.3);
    optics("floor", 0.6, 0.7);
    optics("wall", 0.8, 0.85);
    GreenhouseParameters room;
    room.plantation.rows = 2;
    room.plantation.columns = 4;
    room.plantation.columnSpacingM = 0.8;
    room.plantation.rowSpacingM = 1.4;
    room.plantation.tree.leafCount = 200;
    room.plantation.tree.leafLengthM = 0.06;
    room.lampExitanceWm2 = {1500.0, 150.0};
    AddGreenhouse(scene, room);
    scene.Validate();
    return scene;
}

// Black, at ε = 1e-4: the upper sides measured +0.3 % off the flattened scene's (the lower
// sides get next to nothing); with each patch the levels solved a sender of its own, held
// in clusters mixing pieces of the lamps, walls and floor, −3.2 %. Bound: 2 %.
TEST(Instanced, AHeldLampLightsTheLeavesAsTheLampItself) {
    ExpectSidesNearFlattened(Greenhouse(true), 1e-4, {{{0.02, 0.02}, {}}}, DefaultPolicy());
}

// White, at ε = 1e-4 against the flattened scene at 1e-4: measured upper sides +0.5 / +0.7 %
// (PAR / NIR), lower +0.3 / +1.0 %; each patch its own sender, the walls' light reached the
// upper sides through clusters of pieces of every wall, the floor and the lamps: −3.7 /
// −3.2 % (in the 24-plant greenhouse of docs/results.md, −12 %). Bound: 2 %.
TEST(Instanced, ARoomsWallsLightTheLeavesAsInTheFlattenedScene) {
    ExpectSidesNearFlattened(Greenhouse(false), 1e-4, {{{0.02, 0.02}, {0.02, 0.02}}},
                             DefaultPolicy());
}

// What the lamps send onto the plants closed at the top is incident light: no level under
// it counts it (an opened plant counts the suns' and sky's alone). Measured on the
// eight-plant greenhouse: within 0.1 % of the flattened scene's incident power; uncounted,
// the 24-plant greenhouse's was 9.4 % short. Bound: 1 %.
TEST(Instanced, TheLampsLightOnTheClosedPlantsIsIncident) {
    const Scene scene = Greenhouse(false);
    const PreparedScene prepared(scene);
    const Solution hrc = Hrc(prepared, 1e-4);
    PhaseDatabase database({});
    InstancedOptions options;
    const InstancedSolution instanced = SolveInstanced(scene, prepared.Flat(), &prepared.Rays(),
                                                       DefaultPolicy(), database, options);
    for (std::size_t b = 0; b < hrc.balance.size(); ++b) {
        const double incident = hrc.balance[b].incidentW;
        std::printf("band %zu: incident %.2f W instanced, %.2f W flattened\n", b,
                    instanced.solution.balance[b].incidentW, incident);
        EXPECT_NEAR(instanced.solution.balance[b].incidentW, incident, 0.01 * incident);
    }
}

// Two copies whose crowns grow into one another: each copy's leaves take the other's light
// from all round them and from inside their own box. Linked as clusters, from the other's
// centre, their lower sides got 9.3 % (PAR) and 22.5 % (NIR) less than the flattened
// scene's HRC gives them; taken per direction bin over the opened copy with the share of
// the sender's rays the receiver's box stops (closed_exchange.h), 6.0 and 13.6 % less;
// the other copy held and linked into the opened one's leaves from all round them
// (HeldAroundLinks), its light leaving evenly from its box, 3.5 and 7.1 % less; leaving
// from where its organs lie (AreaGrid), 0.8 % less and as much; each group's points
// weighted by their area facing the light, seen as far as points spread over the organs
// behind them, and the light not dimmed by the organs ahead of them, 0.4 % less and 1.3 %
// more (the test prints them). The bounds, 2 and 3 %, hold what was gained.
TEST(Instanced, OverlappingCrownsExchangeTheirScatteredLight) {
    ExpectLowerSidesNearFlattened(Copies(2, 300, 0.3), {0.02, 0.03});
}

// A tree whose branches are instances: each opened branch takes the light of the others,
// whose boxes wrap its leaves, from all around them (HeldAroundLinks). Each group of leaves
// took the mean of its points' light, its lower sides' NIR 3.24 % short of the flattened
// scene's (ε = 1e-4, the ten 1,000-leaf branches of a 10,000-leaf tree): points on leaves
// seen edge-on from where the light comes, shaded by the leaves beside them, counted as
// much as those facing it. Weighted by their area facing the light, as a link's rays are,
// 1.24 % short; with the light not yet dimmed by the held branch's organs ahead of the
// point, which its intensity holds, 0.46 %; seen as far as points spread over the organs
// behind, not their centre, 0.34 % (upper sides 0.61 % short before, 0.20 % now; the test
// prints them). Bounds: 1 % (upper), 1.5 % (lower).
TEST(Instanced, BranchesHeldAroundOneAnotherLightTheLeavesTheyWrap) {
    InstancingPolicy branches = Plants();
    branches.instanceTypes = {NodeType::kAxis};
    branches.leafCount.edges = {724, 1001};  // the ten branches of 1,000 leaves
    branches.phase = {PhaseKind::kBiDirectional, 3};
    ExpectSidesNearFlattened(Copies(1, 10000), 1e-4,
                             {std::vector<double>{0.01, 0.01}, std::vector<double>{0.015, 0.015}},
                             branches);
}

// Organs among a held instance's leaves take its light in groups, each the mean over its
// points (HeldAroundLinks). That light changes from organ to organ with the depth of the
// held instance's organs behind each, so groups are split while it is more than a link may
// carry (Refiner::HeldAroundLight). Three copies whose crowns grow into one another, at
// ε = 1e-4: the leaves' sides are 1.26 % of the brightest off the flattened scene's NIR
// (RMS; HRC at 1e-5) so, 1.49 % in groups of half the held radius (the test prints it).
// Bound: 1.35 %.
TEST(Instanced, OrgansAmongAHeldCrownTakeItsLightSideBySide) {
    const Scene scene = Copies(3, 300, 0.3);
    const PreparedScene prepared(scene);
    const Solution hrc = Hrc(prepared, 1e-5);
    const InstancedSolution instanced = PlantsInstanced(scene, prepared, 1e-4);
    constexpr int kNir = 1;
    double squares = 0.0, brightest = 0.0;
    int sides = 0;
    for (std::size_t r = 0; r < prepared.Flat().receivers.size(); ++r) {
        if (prepared.Flat().receivers[r].kind != ReceiverKind::kOrgan) continue;
        const BandLight& flat = hrc.light[r][kNir];
        const BandLight& held = instanced.solution.light[r][kNir];
        for (const double off : {held.irradianceUpperWm2 - flat.irradianceUpperWm2,
                                 held.irradianceLowerWm2 - flat.irradianceLowerWm2})
            squares += off * off;
        brightest = std::max({brightest, flat.irradianceUpperWm2, flat.irradianceLowerWm2});
        sides += 2;
    }
    const double rms = 100.0 * std::sqrt(squares / sides) / brightest;
    std::printf("NIR per side: %.3f %% of the brightest off the flattened scene (RMS)\n", rms);
    EXPECT_LT(rms, 1.35);
}

}  // namespace
}  // namespace leaflux
