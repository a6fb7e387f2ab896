// The daemon's instanced sessions (SOLVER_KIND_INSTANCED): the light of each cycle is that
// of the instanced solver on the scene the cycles made, and the phase functions live in the
// daemon's database, shared by its sessions and kept across restarts; a database that
// cannot be opened leaves the daemon serving from memory.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <thread>

#include "server/daemon.h"
#include "server/policy_proto.h"
#include "server/scene_proto.h"
#include "solver/generate/generator.h"
#include "solver/instancing/instanced.h"
#include "solver/util/error.h"
#include "tests/scene_builders.h"

namespace leaflux {
namespace {

constexpr const char* kSpecies = "test-tree";

// Small trees in a row (three of 40 leaves by default) under a sun and a sky, two bands.
Scene Trees(int trees = 3, int leaves = 40) {
    Scene scene;
    scene.bands = {{"PAR"}, {"NIR"}};
    scene.optics = {{"leaf", {{0.08, 0.06, 0.05, 0.05}, {0.45, 0.4, 0.45, 0.45}}},
                    {"stem", {{0.1, 0.1, 0.0, 0.0}, {0.3, 0.3, 0.0, 0.0}}}};
    TreeParameters tree;
    tree.leafCount = leaves;
    NodeId next = 1;
    for (int t = 0; t < trees; ++t) {
        tree.seed = 1 + t;
        next = AddTree(scene, tree, {1.0 * t, 0.2 * t, 0.0}, next);
    }
    Sun sun = testing::SunAt(55.0, 140.0, 500.0);
    sun.normalIrradianceWm2 = {500.0, 450.0};
    scene.sources.suns.push_back(sun);
    Sky sky;
    sky.horizontalIrradianceWm2 = {90.0, 70.0};
    sky.discretization = SkyDiscretization::kTurtle46;
    scene.sources.skies.push_back(sky);
    scene.Validate();
    return scene;
}

// The scene as the wire has it, every organ's mesh inline (a delta's nodes then need no
// mesh library).
v1::Scene InlineProto(const Scene& scene) {
    v1::Scene message = ToProto(scene);
    for (v1::Node& node : *message.mutable_nodes()) {
        if (!node.has_organ() || !node.organ().has_mesh_ref()) continue;
        const auto mesh = message.meshes().find(node.organ().mesh_ref());
        EXPECT_NE(mesh, message.meshes().end());
        *node.mutable_organ()->mutable_mesh() = mesh->second;
    }
    message.clear_meshes();
    return message;
}

// Instanced settings: the default policy, phase functions of 34 directions.
v1::SolverSettings Instanced() {
    v1::SolverSettings settings;
    settings.set_solver(v1::SOLVER_KIND_INSTANCED);
    settings.set_epsilon(1e-3);
    v1::FunctionResolution* phase = settings.mutable_instanced()->mutable_phase();
    phase->set_kind(v1::FUNCTION_KIND_MONO);
    phase->set_level(2);
    return settings;
}

v1::Reply Call(Daemon& daemon, v1::Request request) {
    request.set_version(v1::PROTOCOL_VERSION_CURRENT);
    return daemon.Handle(request);
}

std::string Open(Daemon& daemon, const v1::Scene& scene,
                 const v1::SolverSettings& settings = Instanced()) {
    v1::Request request;
    v1::OpenSession* open = request.mutable_open_session();
    *open->mutable_scene() = scene;
    *open->mutable_settings() = settings;
    open->set_species(kSpecies);
    const v1::Reply reply = Call(daemon, request);
    EXPECT_TRUE(reply.has_opened()) << reply.DebugString();
    return reply.opened().session();
}

v1::CycleResult RunCycle(Daemon& daemon, const std::string& session, std::int64_t number,
                         const v1::TopologyDelta& delta = {}) {
    v1::Request request;
    v1::Cycle* cycle = request.mutable_cycle();
    cycle->set_session(session);
    cycle->set_number(number);
    *cycle->mutable_delta() = delta;
    cycle->mutable_outputs()->set_leaves(true);
    const v1::Reply reply = Call(daemon, request);
    EXPECT_TRUE(reply.has_cycle()) << reply.error().DebugString();
    return reply.cycle();
}

// The instanced solver on `scene` as `leaflux solve --solver instanced` runs it, with the
// session's settings, on `database`: organ light by node. A function is kept by its
// signature, computed from the structure that first had it: the same scene gets the same
// light from the same database.
// The options a session of Instanced() solves with.
InstancedOptions AloneOptions() {
    InstancedOptions options;
    options.hrc.epsilon = 1e-3;
    return options;
}

std::map<std::uint64_t, BandLight> SolvedAlone(const v1::Scene& message, PhaseDatabase& database,
                                               const InstancedOptions& options = AloneOptions()) {
    const Scene scene = FromProto(message, "", {});
    const PreparedScene prepared(scene);
    InstancingPolicy policy = DefaultPolicy();
    policy.species = kSpecies;
    policy.phase = {PhaseKind::kMonoDirectional, 2};
    const InstancedSolution solved =
        SolveInstanced(scene, prepared.Flat(), &prepared.Rays(), policy, database, options);
    std::map<std::uint64_t, BandLight> light;
    for (std::size_t r = 0; r < prepared.Flat().receivers.size(); ++r)
        light[prepared.Flat().receivers[r].node] = solved.solution.light[r][0];
    return light;
}

void ExpectSameLight(const v1::CycleResult& got, const std::map<std::uint64_t, BandLight>& want,
                     int cycle) {
    ASSERT_EQ(static_cast<std::size_t>(got.organs_size()), want.size()) << "cycle " << cycle;
    for (const v1::OrganLight& organ : got.organs()) {
        const BandLight& w = want.at(organ.node());
        const v1::BandLight& g = organ.bands(0);
        EXPECT_NEAR(g.irradiance_upper_wm2(), w.irradianceUpperWm2,
                    1e-9 * (1.0 + w.irradianceUpperWm2))
            << "cycle " << cycle << ", organ " << organ.node();
        EXPECT_NEAR(g.irradiance_lower_wm2(), w.irradianceLowerWm2,
                    1e-9 * (1.0 + w.irradianceLowerWm2))
            << "cycle " << cycle << ", organ " << organ.node();
    }
}

// The ids of `root` and everything below it in `scene`.
std::vector<std::uint64_t> Subtree(const v1::Scene& scene, std::uint64_t root) {
    std::vector<std::uint64_t> ids = {root};
    for (std::size_t i = 0; i < ids.size(); ++i) {
        for (const v1::Node& n : scene.nodes())
            if (n.parent() == ids[i]) ids.push_back(n.id());
    }
    return ids;
}

TEST(DaemonInstanced, CyclesOfAddsRemovalsAndUpdatesGetTheLightOfASolveOfTheirScene) {
    Daemon daemon;
    const Scene four = Trees(4);
    v1::Scene all = InlineProto(four);
    // The session opens on the first three trees; the fourth comes in a cycle.
    std::vector<std::uint64_t> roots;
    for (const Node& n : four.nodes)
        if (n.parent == kNoParent) roots.push_back(n.id);
    ASSERT_EQ(roots.size(), 4u);
    const std::uint64_t lastRoot = roots[3];
    const std::vector<std::uint64_t> lastTree = Subtree(all, lastRoot);
    v1::Scene mirror = all;
    v1::TopologyDelta addFourth;
    mirror.clear_nodes();
    for (const v1::Node& n : all.nodes()) {
        const bool inLast = std::find(lastTree.begin(), lastTree.end(), n.id()) != lastTree.end();
        *(inLast ? addFourth.add_added() : mirror.add_nodes()) = n;
    }
    const std::string session = Open(daemon, mirror);

    // Each cycle against a solve of the scene it made, on the daemon's database.
    const auto check = [&](std::int64_t number, const v1::TopologyDelta& delta) {
        const v1::CycleResult result = RunCycle(daemon, session, number, delta);
        ExpectSameLight(result, SolvedAlone(mirror, daemon.PhaseFunctions()), number);
        return result;
    };
    // 1: the scene as opened.
    check(1, {});
    // 2: the fourth tree added.
    for (const v1::Node& n : addFourth.added()) *mirror.add_nodes() = n;
    const v1::CycleResult second = check(2, addFourth);
    // 3: the second tree removed.
    v1::TopologyDelta removal;
    removal.add_removed(roots[1]);
    const std::vector<std::uint64_t> gone = Subtree(mirror, roots[1]);
    v1::Scene kept = mirror;
    kept.clear_nodes();
    for (const v1::Node& n : mirror.nodes())
        if (std::find(gone.begin(), gone.end(), n.id()) == gone.end()) *kept.add_nodes() = n;
    mirror = kept;
    check(3, removal);
    // 4: a leaf of the first tree raised by 5 cm.
    v1::TopologyDelta update;
    for (v1::Node& n : *mirror.mutable_nodes()) {
        if (!n.has_organ() || n.type() != v1::NODE_TYPE_LEAF) continue;
        v1::Mesh* mesh = n.mutable_organ()->mutable_mesh();
        for (int i = 2; i < mesh->positions_size(); i += 3)
            mesh->set_positions(i, mesh->positions(i) + 0.05);
        *update.add_updated() = n;
        break;
    }
    const v1::CycleResult fourthCycle = check(4, update);
    // Functions come from the database: the trees' structures, met in cycle 1, are reused.
    EXPECT_GT(second.statistics().phase_functions_reused(), 0);
    EXPECT_EQ(fourthCycle.statistics().phase_db_health(), "");
}

// The largest difference between the first band's light on a cycle's organs' lower sides
// and `light`'s.
double LargestLowerDifference(const v1::CycleResult& result,
                              const std::map<std::uint64_t, BandLight>& light) {
    double largest = 0.0;
    for (const v1::OrganLight& organ : result.organs()) {
        largest = std::max(largest, std::abs(organ.bands(0).irradiance_lower_wm2() -
                                             light.at(organ.node()).irradianceLowerWm2));
    }
    return largest;
}

// `per_bin`: an opened instance takes the light that arrived on it per direction bin, as
// `leaflux solve --per-bin` does; not what the default's held level gives.
TEST(DaemonInstanced, APerBinSessionGetsTheLightOfAPerBinSolve) {
    Daemon daemon;
    const v1::Scene scene = InlineProto(Trees());
    v1::SolverSettings settings = Instanced();
    settings.mutable_instanced()->set_per_bin(true);
    const v1::CycleResult result = RunCycle(daemon, Open(daemon, scene, settings), 1);
    InstancedOptions perBin = AloneOptions();
    perBin.holdOutside = false;
    ExpectSameLight(result, SolvedAlone(scene, daemon.PhaseFunctions(), perBin), 1);
    const auto held = SolvedAlone(scene, daemon.PhaseFunctions());
    EXPECT_GT(LargestLowerDifference(result, held), 1e-3);  // the field changed the solve
}

// `merge_triangles`: the session's plants solved each as one problem with the axes they
// hold, as `leaflux solve --merge-triangles` solves them.
TEST(DaemonInstanced, AMergingSessionGetsTheLightOfAMergedSolve) {
    Daemon daemon;
    const v1::Scene scene = InlineProto(Trees(2, 150));  // axes of more than 10 leaves
    v1::SolverSettings settings = Instanced();
    settings.mutable_instanced()->set_merge_triangles(1 << 20);
    const v1::CycleResult result = RunCycle(daemon, Open(daemon, scene, settings), 1);
    InstancedOptions merged = AloneOptions();
    merged.mergeTriangles = 1 << 20;
    ExpectSameLight(result, SolvedAlone(scene, daemon.PhaseFunctions(), merged), 1);
    const auto opened = SolvedAlone(scene, daemon.PhaseFunctions());
    EXPECT_GT(LargestLowerDifference(result, opened), 1e-3);  // the field changed the solve
}

// `push_down` with `output_level`: every organ of the plants solved whole is in the reply,
// with the light `leaflux solve --output-level plant --push-down` hands down to it.
TEST(DaemonInstanced, APushDownSessionGetsTheLightHandedDownToEveryOrgan) {
    Daemon daemon;
    const v1::Scene scene = InlineProto(Trees());
    v1::SolverSettings settings = Instanced();
    settings.mutable_instanced()->set_output_level(v1::NODE_TYPE_PLANT);
    settings.mutable_instanced()->set_push_down(true);
    const v1::CycleResult result = RunCycle(daemon, Open(daemon, scene, settings), 1);
    InstancedOptions pushed = AloneOptions();
    pushed.outputLevel = NodeType::kPlant;
    pushed.pushDown = true;
    const auto want = SolvedAlone(scene, daemon.PhaseFunctions(), pushed);
    ExpectSameLight(result, want, 1);
    EXPECT_GT(result.organs_size(), 0);
}

std::filesystem::path TempFile(const std::string& name) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("leaflux-" + name + "-" + std::to_string(::getpid()) + ".db");
    for (const char* tail : {"", "-wal", "-shm"}) std::filesystem::remove(path.string() + tail);
    return path;
}

TEST(DaemonInstanced, ARestartedDaemonReusesEveryFunctionItStored) {
    const auto path = TempFile("restart");
    const v1::Scene scene = InlineProto(Trees());
    DaemonPhaseFunctions phase;
    phase.database.path = path.string();
    v1::CycleResult first, again;
    {
        Daemon daemon({}, phase);
        first = RunCycle(daemon, Open(daemon, scene), 1);
        EXPECT_GT(first.statistics().phase_functions_computed(), 0);
        daemon.PhaseFunctions().Flush();
    }
    {
        Daemon daemon({}, phase);
        again = RunCycle(daemon, Open(daemon, scene), 1);
    }
    EXPECT_EQ(again.statistics().phase_functions_computed(), 0);
    EXPECT_EQ(again.statistics().phase_functions_reused(),
              first.statistics().phase_functions_computed() +
                  first.statistics().phase_functions_reused());
    EXPECT_EQ(again.statistics().phase_compute_seconds(), 0.0);
    ASSERT_EQ(again.organs_size(), first.organs_size());
    for (int i = 0; i < first.organs_size(); ++i) {
        EXPECT_EQ(again.organs(i).bands(0).irradiance_upper_wm2(),
                  first.organs(i).bands(0).irradiance_upper_wm2());
    }
    std::filesystem::remove(path);
}

TEST(DaemonInstanced, TwoSessionsMissingTheSameSignaturesComputeThemOnce) {
    const v1::Scene scene = InlineProto(Trees());
    Daemon alone;
    const int signatures =
        RunCycle(alone, Open(alone, scene), 1).statistics().phase_functions_computed();
    ASSERT_GT(signatures, 0);
    Daemon daemon;
    const std::string a = Open(daemon, scene), b = Open(daemon, scene);
    v1::CycleResult ra, rb;
    std::thread other([&] { rb = RunCycle(daemon, b, 1); });
    ra = RunCycle(daemon, a, 1);
    other.join();
    EXPECT_EQ(
        ra.statistics().phase_functions_computed() + rb.statistics().phase_functions_computed(),
        signatures);
    // Each session got every function, the one computing it or the other awaiting it.
    for (const v1::CycleResult* r : {&ra, &rb}) {
        EXPECT_EQ(
            r->statistics().phase_functions_computed() + r->statistics().phase_functions_reused(),
            signatures);
    }
}

TEST(DaemonInstanced, ADatabaseThatCannotBeOpenedIsReportedAndTheDaemonServesOn) {
    const auto path = TempFile("corrupt");
    const std::string garbage(5000, 'x');
    std::ofstream(path, std::ios::binary) << garbage;
    DaemonPhaseFunctions phase;
    phase.database.path = path.string();
    Daemon daemon({}, phase);
    v1::Request status;
    status.mutable_status();
    const v1::Reply reply = Call(daemon, status);
    EXPECT_FALSE(reply.status().phase_db().persistent());
    EXPECT_NE(reply.status().phase_db().health().find(path.string()), std::string::npos)
        << reply.status().phase_db().health();
    const v1::CycleResult cycle = RunCycle(daemon, Open(daemon, InlineProto(Trees())), 1);
    EXPECT_GT(cycle.organs_size(), 0);
    EXPECT_GT(cycle.statistics().phase_functions_computed(), 0);
    EXPECT_NE(cycle.statistics().phase_db_health(), "");
    daemon.PhaseFunctions().Flush();
    std::ifstream in(path, std::ios::binary);
    const std::string after((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(after, garbage) << "a file the daemon did not create is never written";
    std::filesystem::remove(path);
}

TEST(DaemonInstanced, BadInstancedSettingsAreRefusedNamingTheField) {
    Daemon daemon;
    const v1::Scene scene = InlineProto(Trees(1));
    const auto refused = [&](v1::SolverSettings settings, const std::string& field) {
        v1::Request request;
        *request.mutable_open_session()->mutable_scene() = scene;
        *request.mutable_open_session()->mutable_settings() = settings;
        const v1::Reply reply = Call(daemon, request);
        ASSERT_TRUE(reply.has_error()) << field;
        EXPECT_EQ(reply.error().field(), field) << reply.error().message();
        // Described once: a policy's own error, rethrown under the settings, does not carry
        // its first description ("invalid_argument phase: …") inside the second.
        const std::string& message = reply.error().message();
        const std::string said = message.substr(message.find(": ") + 2);
        for (const ErrorCode code : {ErrorCode::kInvalidArgument, ErrorCode::kNotFound,
                                     ErrorCode::kUnsupported, ErrorCode::kParse}) {
            EXPECT_NE(said.rfind(ErrorCodeName(code), 0), 0u) << message;
        }
    };
    v1::SolverSettings unknown = Instanced();
    unknown.mutable_instanced()->set_policy_name("poplar");
    refused(unknown, "settings.instanced.policy_name");
    v1::SolverSettings path = Instanced();
    path.mutable_instanced()->set_policy_name("../etc/passwd");
    refused(path, "settings.instanced.policy_name");
    v1::SolverSettings bi = Instanced();
    bi.mutable_instanced()->mutable_transmittance()->set_kind(v1::FUNCTION_KIND_BI);
    bi.mutable_instanced()->mutable_transmittance()->set_level(2);
    refused(bi, "settings.instanced.transmittance.kind");
    v1::SolverSettings both = Instanced();
    both.mutable_instanced()->set_max_depth(1);
    both.mutable_instanced()->set_output_level(v1::NODE_TYPE_AXIS);
    refused(both, "settings.instanced.output_level");
    v1::SolverSettings pushDown = Instanced();
    pushDown.mutable_instanced()->set_push_down(true);  // nothing solved whole to hand down
    refused(pushDown, "settings.instanced.push_down");
    v1::SolverSettings merge = Instanced();
    merge.mutable_instanced()->set_merge_triangles(-1);
    refused(merge, "settings.instanced.merge_triangles");
    merge.mutable_instanced()->set_merge_triangles(4096);
    merge.mutable_instanced()->set_output_level(v1::NODE_TYPE_AXIS);
    refused(merge, "settings.instanced.merge_triangles");
    v1::SolverSettings inlinePolicy = Instanced();
    inlinePolicy.mutable_instanced()->mutable_inline_policy()->set_species("x");
    refused(inlinePolicy, "settings.instanced.inline_policy.phase");
    v1::SolverSettings hrc;
    hrc.set_solver(v1::SOLVER_KIND_HRC);
    hrc.mutable_instanced()->set_max_depth(1);
    refused(hrc, "settings.instanced");
}

}  // namespace
}  // namespace leaflux
