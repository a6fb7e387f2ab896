// The warm start (HrcOptions::warmStart, SolverSettings.warm_start): a solve that starts
// from an earlier solve's light gets the light a cold start gets on the same scene — the
// answer depends on the scene alone — within a quarter of what ε itself costs (the cold
// answer against a ten times finer ε). Not to the last digit: the links are judged in the
// light the iteration has reached, and from a warm start some are chosen otherwise, each
// within ε (the iteration alone, from either start, ends within 0.001 % of each other).
// With HRC and with the instanced solver, from the same scene's light and from the
// plant's a growth cycle earlier; and a daemon session that asks for it gets the light of
// a cold solve of the scene its cycles made.
#include <gtest/gtest.h>

#include <memory>

#include "server/daemon.h"
#include "server/policy_proto.h"
#include "server/scene_proto.h"
#include "solver/generate/generator.h"
#include "solver/instancing/instanced.h"
#include "solver/results/accuracy.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {

// A generated tree under a sun and a 46-cone sky, two bands; its nodes parent first.
Scene Tree(int leaves) {
    Scene scene;
    scene.bands = {{"PAR"}, {"NIR"}};
    scene.optics = {{"leaf", {{0.1, 0.1, 0.05, 0.05}, {0.45, 0.45, 0.45, 0.45}}},
                    {"stem", {{0.1, 0.1, 0.0, 0.0}, {0.4, 0.4, 0.0, 0.0}}}};
    TreeParameters tree;
    tree.leafCount = leaves;
    AddTree(scene, tree, {0.0, 0.0, 0.0});
    Sun sun = testing::SunAt(55.0, 140.0, 400.0);
    sun.normalIrradianceWm2 = {400.0, 350.0};
    scene.sources.suns.push_back(sun);
    Sky sky;
    sky.horizontalIrradianceWm2 = {100.0, 60.0};
    sky.discretization = SkyDiscretization::kTurtle46;
    scene.sources.skies.push_back(sky);
    scene.Validate();
    return scene;
}

// The plant a growth cycle earlier: its first nodes, without the last tenth.
Scene Earlier(const Scene& scene) {
    Scene earlier = scene;
    earlier.nodes.resize(scene.nodes.size() * 9 / 10);
    earlier.Validate();
    return earlier;
}

std::size_t Organs(const FlatScene& flat) {
    std::size_t organs = 0;
    for (const Receiver& r : flat.receivers) organs += r.kind == ReceiverKind::kOrgan;
    return organs;
}

// How far `warm` is from `cold` (L2, % of the largest irradiance), band by band, against
// what ε costs: `cold` against `fine`, the same solve at a ten times finer ε. A warm start
// that stopped early would keep light from the earlier scene: the 400-leaf tree's organs
// in the last cycle's light are 1.9 % (L2, both bands) off their light in the grown tree.
void ExpectWithinTheCostOfEpsilon(const Scene& scene, const FlatScene& flat, const Solution& cold,
                                  const Solution& fine, const Solution& warm) {
    const auto epsilonCost = CompareLeaves(scene, flat, fine, cold);
    const auto start = CompareLeaves(scene, flat, cold, warm);
    for (std::size_t b = 0; b < scene.bands.size(); ++b) {
        std::printf("%s: warm against cold %.4f %% L2, cold against a finer epsilon %.3f %%\n",
                    scene.bands[b].name.c_str(), start[b].l2PctOfMax, epsilonCost[b].l2PctOfMax);
        EXPECT_GT(epsilonCost[b].l2PctOfMax, 0.0) << scene.bands[b].name;
        EXPECT_LT(start[b].l2PctOfMax, 0.25 * epsilonCost[b].l2PctOfMax) << scene.bands[b].name;
    }
}

TEST(WarmStart, HrcFromItsOwnLightOrTheLastCyclesReachesTheLightOfAColdStart) {
    const Scene scene = Tree(400);
    const PreparedScene prepared(scene);
    const FlatScene& flat = prepared.Flat();
    HrcOptions options;
    options.epsilon = 1e-3;
    const Solution cold = SolveHrc(scene, flat, prepared.Rays(), options);
    HrcOptions finer = options;
    finer.epsilon = 1e-4;
    const Solution fine = SolveHrc(scene, flat, prepared.Rays(), finer);
    EXPECT_EQ(cold.stats.warmOrgans, 0);

    options.warmStart = std::make_shared<const WarmStart>(flat.receivers, cold);
    const Solution again = SolveHrc(scene, flat, prepared.Rays(), options);
    EXPECT_EQ(again.stats.warmOrgans, static_cast<std::int64_t>(Organs(flat)));
    EXPECT_LE(again.stats.iterations, cold.stats.iterations);
    ExpectWithinTheCostOfEpsilon(scene, flat, cold, fine, again);

    // The plant a cycle earlier: its organs start warm, the new tenth from the direct light.
    const Scene earlier = Earlier(scene);
    const PreparedScene before(earlier);
    HrcOptions plain = options;
    plain.warmStart = nullptr;
    options.warmStart = std::make_shared<const WarmStart>(
        before.Flat().receivers, SolveHrc(earlier, before.Flat(), before.Rays(), plain));
    const Solution grown = SolveHrc(scene, flat, prepared.Rays(), options);
    EXPECT_EQ(grown.stats.warmOrgans, static_cast<std::int64_t>(Organs(before.Flat())));
    EXPECT_LT(grown.stats.warmOrgans, again.stats.warmOrgans);
    ExpectWithinTheCostOfEpsilon(scene, flat, cold, fine, grown);
}

TEST(WarmStart, TheInstancedSolverFromTheLastCyclesLightReachesTheLightOfAColdStart) {
    const Scene scene = Tree(300);
    const PreparedScene prepared(scene);
    const FlatScene& flat = prepared.Flat();
    PhaseDatabase database({});
    InstancedOptions options;
    options.hrc.epsilon = 1e-3;
    const auto solve = [&](const Scene& s, const PreparedScene& p, const InstancedOptions& o) {
        return SolveInstanced(s, p.Flat(), &p.Rays(), DefaultPolicy(), database, o).solution;
    };
    const Solution cold = solve(scene, prepared, options);
    InstancedOptions finer = options;
    finer.hrc.epsilon = 1e-4;
    const Solution fine = solve(scene, prepared, finer);

    const Scene earlier = Earlier(scene);
    const PreparedScene before(earlier);
    options.hrc.warmStart =
        std::make_shared<const WarmStart>(before.Flat().receivers, solve(earlier, before, options));
    const Solution grown = solve(scene, prepared, options);
    EXPECT_EQ(grown.stats.warmOrgans, static_cast<std::int64_t>(Organs(before.Flat())));
    ExpectWithinTheCostOfEpsilon(scene, flat, cold, fine, grown);
}

// A session growing a tree with SolverSettings.warm_start: each cycle reports the organs
// that started from the last cycle's light, and the last cycle's light is a cold solve's.
TEST(WarmStart, ADaemonSessionThatAsksForItGetsTheLightOfAColdSolveOfItsScene) {
    const Scene scene = Tree(300);
    v1::Scene message = ToProto(scene);
    const std::vector<v1::Node> nodes(message.nodes().begin(), message.nodes().end());
    message.clear_nodes();
    v1::Request open;
    open.set_version(v1::PROTOCOL_VERSION_CURRENT);
    *open.mutable_open_session()->mutable_scene() = message;
    open.mutable_open_session()->mutable_settings()->set_epsilon(1e-3);
    open.mutable_open_session()->mutable_settings()->set_warm_start(true);
    Daemon daemon;
    const v1::Reply opened = daemon.Handle(open);
    ASSERT_TRUE(opened.has_opened()) << opened.DebugString();
    constexpr int kCycles = 4;
    std::size_t next = 0;
    std::int64_t organsBefore = 0;
    v1::CycleResult last;
    for (int c = 1; c <= kCycles; ++c) {
        v1::Request request;
        request.set_version(v1::PROTOCOL_VERSION_CURRENT);
        v1::Cycle* cycle = request.mutable_cycle();
        cycle->set_session(opened.opened().session());
        cycle->set_number(c);
        cycle->mutable_outputs()->set_leaves(true);
        for (; next < nodes.size() * c / kCycles; ++next)
            *cycle->mutable_delta()->add_added() = nodes[next];
        const v1::Reply reply = daemon.Handle(request);
        ASSERT_TRUE(reply.has_cycle()) << reply.DebugString();
        EXPECT_EQ(reply.cycle().statistics().warm_organs(), organsBefore) << "cycle " << c;
        organsBefore = reply.cycle().organs_size();
        last = reply.cycle();
    }
    const PreparedScene prepared(scene);
    const FlatScene& flat = prepared.Flat();
    HrcOptions options;
    options.epsilon = 1e-3;
    const Solution cold = SolveHrc(scene, flat, prepared.Rays(), options);
    options.epsilon = 1e-4;
    const Solution fine = SolveHrc(scene, flat, prepared.Rays(), options);
    Solution session = cold;  // the session's light, by the flat scene's receivers
    std::map<std::uint64_t, std::size_t> receiverOf;
    for (std::size_t r = 0; r < flat.receivers.size(); ++r) receiverOf[flat.receivers[r].node] = r;
    ASSERT_EQ(static_cast<std::size_t>(last.organs_size()), Organs(flat));
    for (const v1::OrganLight& organ : last.organs()) {
        for (std::size_t b = 0; b < scene.bands.size(); ++b) {
            BandLight& light = session.light[receiverOf.at(organ.node())][b];
            light.irradianceUpperWm2 = organ.bands(b).irradiance_upper_wm2();
            light.irradianceLowerWm2 = organ.bands(b).irradiance_lower_wm2();
        }
    }
    ExpectWithinTheCostOfEpsilon(scene, flat, cold, fine, session);
}

}  // namespace
}  // namespace leaflux
