// leafluxd on loopback: a session over several cycles, and bad requests that each get a
// typed error while the daemon stays up and the session stays as it was.
#include "server/daemon.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <thread>
#include <tuple>

#include "tests/daemon_fixture.h"

namespace leaflux {
namespace {

v1::Node Leaf(std::uint64_t id, std::uint64_t parent, double x, double z = 1.0) {
    v1::Node node;
    node.set_id(id);
    node.set_parent(parent);
    node.set_type(v1::NODE_TYPE_LEAF);
    node.set_name("leaf" + std::to_string(id));
    v1::Organ* organ = node.mutable_organ();
    organ->set_optics("leaf");
    for (double v : {x, 0.0, z, x + 0.1, 0.0, z, x + 0.1, 0.1, z, x, 0.1, z})
        organ->mutable_mesh()->add_positions(v);
    for (unsigned i : {0u, 1u, 2u, 0u, 2u, 3u}) organ->mutable_mesh()->add_triangles(i);
    return node;
}

v1::Request OpenRequest() {
    v1::Request request;
    request.set_version(v1::PROTOCOL_VERSION_CURRENT);
    v1::OpenSession* open = request.mutable_open_session();
    v1::Scene* scene = open->mutable_scene();
    scene->add_bands()->set_name("PAR");
    v1::Optics* optics = scene->add_optics();
    optics->set_id("leaf");
    v1::BandOptics& par = (*optics->mutable_bands())["PAR"];
    par.set_rho_upper(0.1), par.set_rho_lower(0.1), par.set_tau_upper(0.05),
        par.set_tau_lower(0.05);
    v1::Node* plant = scene->add_nodes();
    plant->set_id(1);
    plant->set_type(v1::NODE_TYPE_PLANT);
    *scene->add_nodes() = Leaf(2, 1, 0.0);
    v1::Sun* sun = scene->add_suns();
    sun->mutable_direction()->set_z(1.0);
    (*sun->mutable_normal_irradiance())["PAR"] = 1000.0;
    open->mutable_settings()->set_solver(v1::SOLVER_KIND_HRC);
    return request;
}

v1::Request CycleRequest(const std::string& session, std::int64_t number) {
    v1::Request request;
    request.set_version(v1::PROTOCOL_VERSION_CURRENT);
    request.set_request_id(static_cast<std::uint64_t>(number) + 100);
    v1::Cycle* cycle = request.mutable_cycle();
    cycle->set_session(session);
    cycle->set_number(number);
    cycle->mutable_outputs()->set_leaves(true);
    cycle->mutable_outputs()->set_structures(true);
    return request;
}

TEST_F(DaemonOnLoopback, SessionLivesOverCyclesOfAddsUpdatesAndRemovals) {
    const v1::Reply opened = Call(OpenRequest());
    ASSERT_TRUE(opened.has_opened()) << opened.DebugString();
    const std::string session = opened.opened().session();

    v1::Reply first = Call(CycleRequest(session, 1));
    ASSERT_TRUE(first.has_cycle()) << first.DebugString();
    EXPECT_EQ(first.request_id(), 101u);
    ASSERT_EQ(first.cycle().organs_size(), 1);
    // One leaf in the open under a vertical sun: 1000 W/m² on top.
    EXPECT_NEAR(first.cycle().organs(0).bands(0).irradiance_upper_wm2(), 1000.0, 1e-9);

    v1::Request grow = CycleRequest(session, 2);
    *grow.mutable_cycle()->mutable_delta()->add_added() = Leaf(3, 1, 0.02, 0.9);  // under leaf 2
    const v1::Reply second = Call(grow);
    ASSERT_TRUE(second.has_cycle()) << second.DebugString();
    ASSERT_EQ(second.cycle().organs_size(), 2);
    EXPECT_LT(second.cycle().organs(1).bands(0).irradiance_upper_wm2(), 500.0);  // mostly shaded
    EXPECT_GE(second.cycle().structures_size(), 1);

    v1::Request move = CycleRequest(session, 3);
    *move.mutable_cycle()->mutable_delta()->add_updated() =
        Leaf(3, 1, 1.0, 0.9);  // out of the shade
    const v1::Reply third = Call(move);
    ASSERT_TRUE(third.has_cycle()) << third.DebugString();
    // The sun's 1000 W/m², and a few mW/m² from the other leaf's underside a metre away.
    EXPECT_NEAR(third.cycle().organs(1).bands(0).irradiance_upper_wm2(), 1000.0, 0.01);

    v1::Request prune = CycleRequest(session, 4);
    prune.mutable_cycle()->mutable_delta()->add_removed(3);
    const v1::Reply fourth = Call(prune);
    ASSERT_TRUE(fourth.has_cycle()) << fourth.DebugString();
    EXPECT_EQ(fourth.cycle().organs_size(), 1);
    v1::Request status;
    status.mutable_status()->set_session(session);
    const v1::Reply state = Call(status);
    ASSERT_EQ(state.status().sessions_size(), 1);
    EXPECT_EQ(state.status().sessions(0).nodes(), 2);
    EXPECT_EQ(state.status().sessions(0).cycles(), 4);
}

struct BadRequest {
    const char* what;
    std::function<v1::Request(const std::string& session)> make;
    v1::ErrorCode code;
    std::string field;
    std::uint64_t node;
};

TEST_F(DaemonOnLoopback, AnswersEveryBadRequestWithATypedErrorAndChangesNothing) {
    const std::string session = Call(OpenRequest()).opened().session();
    ASSERT_FALSE(session.empty());
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const std::vector<BadRequest> cases = {
        {"unknown session", [](const std::string&) { return CycleRequest("nope", 1); },
         v1::ERROR_CODE_UNKNOWN_SESSION, "session", 0},
        {"duplicate id",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             *r.mutable_cycle()->mutable_delta()->add_added() = Leaf(2, 1, 3.0);
             return r;
         },
         v1::ERROR_CODE_ALREADY_EXISTS, "delta.added", 2},
        {"removal of what does not exist",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             r.mutable_cycle()->mutable_delta()->add_removed(77);
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "delta.removed", 77},
        {"update of what does not exist",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             *r.mutable_cycle()->mutable_delta()->add_updated() = Leaf(78, 1, 0.0);
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "delta.updated", 78},
        {"unknown parent",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             *r.mutable_cycle()->mutable_delta()->add_added() = Leaf(5, 99, 0.0);
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "parent", 5},
        {"a cycle of parents",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node plant;
             plant.set_id(1);
             plant.set_parent(2);
             *r.mutable_cycle()->mutable_delta()->add_updated() = plant;
             return r;
         },
         v1::ERROR_CODE_CYCLE, "parent", 0},
        {"NaN vertex",
         [nan](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(6, 1, 0.0);
             leaf.mutable_organ()->mutable_mesh()->set_positions(4, nan);
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "organ.mesh.positions", 6},
        {"degenerate leaf",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(7, 1, 0.0);
             for (int i = 0; i < 12; ++i)
                 leaf.mutable_organ()->mutable_mesh()->set_positions(i, 0.5);
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_DEGENERATE, "organ.mesh.triangles", 7},
        {"unknown band in outputs",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             r.mutable_cycle()->mutable_outputs()->add_bands("UV");
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "outputs.bands[UV]", 0},
        {"rho + tau > 1 at opening",
         [](const std::string&) {
             auto r = OpenRequest();
             (*r.mutable_open_session()->mutable_scene()->mutable_optics(0)->mutable_bands())["PAR"]
                 .set_tau_upper(0.95);
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "optics[leaf].bands[PAR]", 0},
        {"frame of five numbers",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(8, 1, 0.0);
             for (int k = 0; k < 5; ++k) leaf.mutable_frame()->add_m(1.0);
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "frame", 8},
        {"singular frame",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(8, 1, 0.0);
             for (int k = 0; k < 12; ++k) leaf.mutable_frame()->add_m(0.0);
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_DEGENERATE, "frame", 8},
        {"unknown optics",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(9, 1, 0.0);
             leaf.mutable_organ()->set_optics("bark");
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "organ.optics", 9},
        {"unknown mesh_ref",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(10, 1, 0.0);
             leaf.mutable_organ()->set_mesh_ref("nope");
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "organ.mesh_ref", 10},
        {"positions not in triples",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(11, 1, 0.0);
             leaf.mutable_organ()->mutable_mesh()->add_positions(1.0);
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "organ.mesh.positions", 11},
        {"triangle beyond the positions",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(12, 1, 0.0);
             leaf.mutable_organ()->mutable_mesh()->set_triangles(5, 40);
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "organ.mesh.triangles[1]", 12},
        {"infinite age",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(13, 1, 0.0);
             leaf.set_age(std::numeric_limits<double>::infinity());
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "age", 13},
        {"NaN attribute",
         [nan](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(14, 1, 0.0);
             (*leaf.mutable_attributes())["vigour"] = nan;
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "attributes[vigour]", 14},
        {"an id added twice",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             *r.mutable_cycle()->mutable_delta()->add_added() = Leaf(15, 1, 0.0);
             *r.mutable_cycle()->mutable_delta()->add_added() = Leaf(15, 1, 1.0);
             return r;
         },
         v1::ERROR_CODE_ALREADY_EXISTS, "", 15},
        {"id zero",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             *r.mutable_cycle()->mutable_delta()->add_added() = Leaf(0, 1, 0.0);
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "nodes.id", 0},
        {"organ name used twice",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(16, 1, 3.0);
             leaf.set_name("leaf2");
             *r.mutable_cycle()->mutable_delta()->add_added() = leaf;
             return r;
         },
         v1::ERROR_CODE_ALREADY_EXISTS, "name", 16},
        {"sun with no direction",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             (*r.mutable_cycle()->add_suns()->mutable_normal_irradiance())["PAR"] = 1.0;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "suns[0].direction", 0},
        {"sun in an unknown band",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Sun* sun = r.mutable_cycle()->add_suns();
             sun->mutable_direction()->set_z(1.0);
             (*sun->mutable_normal_irradiance())["UV"] = 1.0;
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "suns[0].normal_irradiance[UV]", 0},
        {"sun missing a band",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             r.mutable_cycle()->add_suns()->mutable_direction()->set_z(1.0);
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "suns[0].normal_irradiance", 0},
        {"negative sun",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Sun* sun = r.mutable_cycle()->add_suns();
             sun->mutable_direction()->set_z(1.0);
             (*sun->mutable_normal_irradiance())["PAR"] = -3.0;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "suns[0].normal_irradiance[PAR]", 0},
        {"sun as wide as the sky",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Sun* sun = r.mutable_cycle()->add_suns();
             sun->mutable_direction()->set_z(1.0);
             sun->set_angular_radius_deg(45.0);
             (*sun->mutable_normal_irradiance())["PAR"] = 3.0;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "suns[0].angular_radius_deg", 0},
        {"no band at opening",
         [](const std::string&) {
             auto r = OpenRequest();
             r.mutable_open_session()->mutable_scene()->clear_bands();
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "", 0},
        {"epsilon beyond 1",
         [](const std::string&) {
             auto r = OpenRequest();
             r.mutable_open_session()->mutable_settings()->set_epsilon(3.0);
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "settings.epsilon", 0},
        {"negative samples",
         [](const std::string&) {
             auto r = OpenRequest();
             r.mutable_open_session()->mutable_settings()->set_samples(-4);
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "settings.samples", 0},
        {"files to import",
         [](const std::string&) {
             auto r = OpenRequest();
             r.mutable_open_session()->mutable_scene()->add_imports()->set_path("/etc/passwd.obj");
             return r;
         },
         v1::ERROR_CODE_UNSUPPORTED, "scene.imports", 0},
        {"close of an unknown session",
         [](const std::string&) {
             v1::Request r;
             r.mutable_close_session()->set_session("gone");
             return r;
         },
         v1::ERROR_CODE_UNKNOWN_SESSION, "session", 0},
        {"status of an unknown session",
         [](const std::string&) {
             v1::Request r;
             r.mutable_status()->set_session("gone");
             return r;
         },
         v1::ERROR_CODE_UNKNOWN_SESSION, "session", 0},
        {"resync without a session",
         [](const std::string&) {
             v1::Request r;
             *r.mutable_resync()->mutable_scene() = OpenRequest().open_session().scene();
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "session", 0},
        {"optics missing a band",
         [](const std::string&) {
             auto r = OpenRequest();
             r.mutable_open_session()->mutable_scene()->add_bands()->set_name("NIR");
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "optics[leaf].bands", 0},
        {"a band declared twice",
         [](const std::string&) {
             auto r = OpenRequest();
             r.mutable_open_session()->mutable_scene()->add_bands()->set_name("PAR");
             return r;
         },
         v1::ERROR_CODE_ALREADY_EXISTS, "bands[PAR]", 0},
        {"negative sky",
         [](const std::string&) {
             auto r = OpenRequest();
             (*r.mutable_open_session()
                   ->mutable_scene()
                   ->mutable_sky()
                   ->mutable_horizontal_irradiance())["PAR"] = -1;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "sky.horizontal_irradiance[PAR]", 0},
        {"sky in an unknown band",
         [](const std::string&) {
             auto r = OpenRequest();
             (*r.mutable_open_session()
                   ->mutable_scene()
                   ->mutable_sky()
                   ->mutable_horizontal_irradiance())["UV"] = 1;
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "sky.horizontal_irradiance[UV]", 0},
        {"lamp of NaN exitance",
         [nan](const std::string&) {
             auto r = OpenRequest();
             v1::Emitter* lamp = r.mutable_open_session()->mutable_scene()->add_emitters();
             lamp->set_name("lamp");
             *lamp->mutable_mesh() = Leaf(99, 0, 0.0, 2.0).organ().mesh();
             (*lamp->mutable_exitance())["PAR"] = nan;
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "emitters[lamp].exitance[PAR]", 0},
        {"lamp without triangles",
         [](const std::string&) {
             auto r = OpenRequest();
             v1::Emitter* lamp = r.mutable_open_session()->mutable_scene()->add_emitters();
             lamp->set_name("lamp");
             (*lamp->mutable_exitance())["PAR"] = 10;
             return r;
         },
         v1::ERROR_CODE_DEGENERATE, "emitters[lamp].mesh", 0},
        {"ground of unknown optics",
         [](const std::string&) {
             auto r = OpenRequest();
             v1::Surface* ground = r.mutable_open_session()->mutable_scene()->add_environment();
             ground->set_name("ground");
             ground->set_optics("mud");
             *ground->mutable_mesh() = Leaf(99, 0, 0.0, 0.0).organ().mesh();
             return r;
         },
         v1::ERROR_CODE_NOT_FOUND, "environment[ground].optics", 0},
        {"empty periodic domain",
         [](const std::string&) {
             auto r = OpenRequest();
             r.mutable_open_session()->mutable_scene()->mutable_periodic()->set_x_max(1.0);
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "periodic", 0},
        {"latitude beyond the pole",
         [](const std::string&) {
             auto r = OpenRequest();
             v1::Sun* sun = r.mutable_open_session()->mutable_scene()->mutable_suns(0);
             sun->mutable_solar()->set_latitude_deg(95);
             sun->mutable_solar()->set_day_of_year(100);
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "suns[0].solar.latitude_deg", 0},
        {"a period ending before it starts",
         [](const std::string&) {
             auto r = OpenRequest();
             v1::SunPeriod* period = r.mutable_open_session()->mutable_scene()->add_sun_periods();
             period->set_day_of_year(100);
             period->set_start_h(14);
             period->set_end_h(10);
             period->set_step_h(1);
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "sun_periods[0]", 0},
        {"negative threads",
         [](const std::string&) {
             auto r = OpenRequest();
             r.mutable_open_session()->mutable_settings()->set_threads(-2);
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "settings.threads", 0},
        {"subdivision beyond 8",
         [](const std::string&) {
             auto r = OpenRequest();
             r.mutable_open_session()->mutable_settings()->set_subdivision(20);
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "settings.subdivision", 0},
        {"a node its own parent",
         [](const std::string& s) {
             auto r = CycleRequest(s, 1);
             v1::Node leaf = Leaf(2, 2, 0.0);
             *r.mutable_cycle()->mutable_delta()->add_updated() = leaf;
             return r;
         },
         v1::ERROR_CODE_CYCLE, "parent", 2},
        {"NaN reflectance",
         [nan](const std::string&) {
             auto r = OpenRequest();
             (*r.mutable_open_session()->mutable_scene()->mutable_optics(0)->mutable_bands())["PAR"]
                 .set_rho_lower(nan);
             return r;
         },
         v1::ERROR_CODE_INVALID_ARGUMENT, "optics[leaf].bands[PAR].rho_lower", 0},
        {"no body", [](const std::string&) { return v1::Request(); }, v1::ERROR_CODE_UNSUPPORTED,
         "body", 0},
        {"newer protocol",
         [](const std::string&) {
             v1::Request r;
             r.set_version(static_cast<v1::ProtocolVersion>(9));
             r.mutable_status();
             return r;
         },
         v1::ERROR_CODE_UNSUPPORTED, "version", 0},
    };
    for (const BadRequest& bad : cases) {
        SCOPED_TRACE(bad.what);
        const v1::Reply reply = Call(bad.make(session));
        ASSERT_TRUE(reply.has_error()) << reply.DebugString();
        EXPECT_EQ(reply.error().code(), bad.code) << reply.error().DebugString();
        EXPECT_NE(reply.error().field().find(bad.field), std::string::npos)
            << reply.error().DebugString();
        if (bad.node != 0) {
            EXPECT_EQ(reply.error().node(), bad.node);
        }
        // The session is exactly as it was: two nodes, no cycle applied.
        v1::Request status;
        status.mutable_status()->set_session(session);
        const v1::Reply state = Call(status);
        ASSERT_EQ(state.status().sessions_size(), 1);
        EXPECT_EQ(state.status().sessions(0).nodes(), 2);
        EXPECT_EQ(state.status().sessions(0).cycles(), 0);
    }
    // Garbage bytes and an oversized message: typed errors too, and the daemon still serves.
    std::string reply;
    ASSERT_TRUE(client_->Call(std::string("\xff\x01garbage", 9), reply, 60000));
    v1::Reply garbage;
    ASSERT_TRUE(garbage.ParseFromString(reply));
    EXPECT_EQ(garbage.error().code(), v1::ERROR_CODE_PARSE);
    ASSERT_TRUE(client_->Call(std::string(3 << 19, 'x'), reply, 60000));  // 1.5 MiB
    v1::Reply large;
    ASSERT_TRUE(large.ParseFromString(reply));
    EXPECT_EQ(large.error().code(), v1::ERROR_CODE_TOO_LARGE);
    v1::Request status;
    status.mutable_status();
    EXPECT_TRUE(Call(status).has_status());
}

// A slow solve in one session holds back neither the status nor another session's cycles,
// and its client leaving before the reply disturbs nobody.
TEST_F(DaemonOnLoopback, SessionsSolveInParallelAndADepartedClientDisturbsNoOne) {
    v1::Request slowOpen = OpenRequest();
    v1::SolverSettings* settings = slowOpen.mutable_open_session()->mutable_settings();
    settings->set_solver(v1::SOLVER_KIND_MONTE_CARLO);
    settings->set_samples(1 << 24);  // seconds of work for one leaf
    const std::string slow = Call(slowOpen).opened().session();
    const std::string fast = Call(OpenRequest()).opened().session();
    ASSERT_FALSE(slow.empty());
    ASSERT_FALSE(fast.empty());
    {
        // Send the slow cycle and leave without waiting for it.
        zmq::socket_t leaving(context_, zmq::socket_type::dealer);
        leaving.set(zmq::sockopt::linger, 1000);
        leaving.connect(server_->Endpoint());
        std::string bytes;
        CycleRequest(slow, 1).SerializeToString(&bytes);
        leaving.send(zmq::message_t(), zmq::send_flags::sndmore);
        leaving.send(zmq::buffer(bytes), zmq::send_flags::none);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the slow solve is under way
    const auto start = std::chrono::steady_clock::now();
    v1::Request status;
    status.mutable_status();
    const v1::Reply state = Call(status);
    ASSERT_TRUE(state.has_status());
    const v1::Reply other = Call(CycleRequest(fast, 1));
    ASSERT_TRUE(other.has_cycle()) << other.DebugString();
    const double waited =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // Both answered while the slow session was still solving.
    v1::Request slowStatus;
    slowStatus.mutable_status()->set_session(slow);
    EXPECT_EQ(Call(slowStatus).status().sessions(0).cycles(), 0)
        << "answered after " << waited << " s";
    // The departed client's cycle still completes and is kept.
    for (int i = 0; i < 600 && Call(slowStatus).status().sessions(0).cycles() == 0; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    EXPECT_EQ(Call(slowStatus).status().sessions(0).cycles(), 1);
}

// A delta that passes its checks but whose cycle fails later (here: its outputs name no
// band) is taken back: the same delta, asked again with good outputs, is applied.
TEST(DaemonCycles, ADeltaWhoseCycleFailsIsTakenBack) {
    Daemon daemon;
    const std::string session = daemon.Handle(OpenRequest()).opened().session();
    v1::Request grow = CycleRequest(session, 1);
    *grow.mutable_cycle()->mutable_delta()->add_added() = Leaf(7, 1, 0.5);
    v1::Request badOutputs = grow;
    badOutputs.mutable_cycle()->mutable_outputs()->add_bands("UV");
    const v1::Reply failed = daemon.Handle(badOutputs);
    ASSERT_TRUE(failed.has_error());
    EXPECT_EQ(failed.error().code(), v1::ERROR_CODE_NOT_FOUND);
    const v1::Reply grown = daemon.Handle(grow);
    ASSERT_TRUE(grown.has_cycle()) << grown.DebugString();
    EXPECT_EQ(grown.cycle().organs_size(), 2);
}

// A cycle that asks for one band gets that band alone, solved for it alone.
// A cycle that changes nothing and asks what the last one asked gets the last one's light
// again, without solving; other outputs, a delta or new suns are solved.
TEST(DaemonCycles, AnUnchangedCycleGetsTheLastLightWithoutSolving) {
    Daemon daemon;
    const std::string session = daemon.Handle(OpenRequest()).opened().session();
    const v1::Reply first = daemon.Handle(CycleRequest(session, 1));
    ASSERT_TRUE(first.has_cycle()) << first.DebugString();
    EXPECT_FALSE(first.cycle().statistics().reused());

    const v1::Reply again = daemon.Handle(CycleRequest(session, 2));
    ASSERT_TRUE(again.has_cycle()) << again.DebugString();
    EXPECT_TRUE(again.cycle().statistics().reused());
    EXPECT_EQ(again.cycle().number(), 2);
    EXPECT_EQ(again.cycle().statistics().wall_seconds(), 0.0);
    v1::CycleResult expected = first.cycle();
    expected.set_number(2);
    *expected.mutable_statistics() = again.cycle().statistics();
    EXPECT_EQ(again.cycle().SerializeAsString(), expected.SerializeAsString());

    v1::Request leavesOnly = CycleRequest(session, 3);
    leavesOnly.mutable_cycle()->mutable_outputs()->set_structures(false);
    const v1::Reply third = daemon.Handle(leavesOnly);
    EXPECT_FALSE(third.cycle().statistics().reused());
    EXPECT_EQ(third.cycle().structures_size(), 0);

    v1::Request lower = CycleRequest(session, 4);
    lower.mutable_cycle()->mutable_outputs()->set_structures(false);
    v1::Sun* sun = lower.mutable_cycle()->add_suns();
    sun->mutable_direction()->set_z(1.0);
    (*sun->mutable_normal_irradiance())["PAR"] = 500.0;
    const v1::Reply fourth = daemon.Handle(lower);
    EXPECT_FALSE(fourth.cycle().statistics().reused());
    EXPECT_NEAR(fourth.cycle().organs(0).bands(0).irradiance_upper_wm2(), 500.0, 1e-9);

    v1::Request grow = CycleRequest(session, 5);
    grow.mutable_cycle()->mutable_outputs()->set_structures(false);
    *grow.mutable_cycle()->mutable_delta()->add_added() = Leaf(3, 1, 0.02, 0.9);
    const v1::Reply fifth = daemon.Handle(grow);
    EXPECT_FALSE(fifth.cycle().statistics().reused());
    EXPECT_EQ(fifth.cycle().organs_size(), 2);
    v1::Request status;
    status.set_version(v1::PROTOCOL_VERSION_CURRENT);
    status.mutable_status()->set_session(session);
    EXPECT_EQ(daemon.Handle(status).status().sessions(0).cycles(), 5);
}

// --solver-threads caps the cores of every solve; a session asking fewer gets fewer.
TEST(DaemonThreads, SolvesUseAtMostTheDaemonsSolverThreads) {
    for (const auto& [limit, asked, used] : {std::tuple{1, 0, 1}, {1, 2, 1}, {2, 1, 1}}) {
        DaemonLimits limits;
        limits.solverThreads = limit;
        Daemon daemon(limits);
        v1::Request open = OpenRequest();
        open.mutable_open_session()->mutable_settings()->set_threads(asked);
        const std::string session = daemon.Handle(open).opened().session();
        const v1::Reply reply = daemon.Handle(CycleRequest(session, 1));
        ASSERT_TRUE(reply.has_cycle()) << reply.DebugString();
        EXPECT_EQ(reply.cycle().statistics().threads(), used)
            << "limit " << limit << ", asked " << asked;
    }
}

// With a CurveZMQ secret key the daemon answers clients that know its public key, and
// nobody else.
TEST(DaemonCurve, AnswersOnlyClientsThatKnowItsKey) {
    zmq::context_t context;
    const CurveKeyPair keys = CurveKeyPair::Generate();
    RouterServer server(context, "tcp://127.0.0.1:*", {}, keys.secretKey);
    Daemon daemon;
    std::atomic<bool> stop{false};
    std::thread thread([&] {
        server.Serve(
            RouterServer::Synchronous([&](const std::string& r) { return daemon.Handle(r); }),
            [](const OversizedMessage&) { return std::string(); }, [] { return false; }, stop);
    });
    v1::Request status;
    status.set_version(v1::PROTOCOL_VERSION_CURRENT);
    status.mutable_status();
    std::string bytes, reply;
    status.SerializeToString(&bytes);
    ClientConnection trusted(context, server.Endpoint(), keys.publicKey);
    EXPECT_TRUE(trusted.Call(bytes, reply, 10000));
    v1::Reply decoded;
    EXPECT_TRUE(decoded.ParseFromString(reply) && decoded.has_status());
    ClientConnection plain(context, server.Endpoint());
    EXPECT_FALSE(plain.Call(bytes, reply, 500));
    stop = true;
    thread.join();
}

// The daemon dies between cycles; the client, told the session is unknown, resyncs with
// the whole scene it keeps and goes on: the results are those the first daemon gave.
TEST(DaemonRestart, ClientResyncsAndContinuesWithIdenticalResults) {
    v1::Request open = OpenRequest();
    v1::Request grow = CycleRequest("", 2);
    *grow.mutable_cycle()->mutable_delta()->add_added() = Leaf(3, 1, 0.02, 0.9);

    auto first = std::make_unique<Daemon>();
    const std::string session = first->Handle(open).opened().session();
    grow.mutable_cycle()->set_session(session);
    const v1::Reply before = first->Handle(grow);
    ASSERT_TRUE(before.has_cycle()) << before.DebugString();
    first.reset();  // killed

    Daemon second;
    const v1::Reply lost = second.Handle(grow);
    ASSERT_TRUE(lost.has_error());
    EXPECT_EQ(lost.error().code(), v1::ERROR_CODE_UNKNOWN_SESSION);
    v1::Request resync;
    resync.set_version(v1::PROTOCOL_VERSION_CURRENT);
    resync.mutable_resync()->set_session(session);
    *resync.mutable_resync()->mutable_scene() = open.open_session().scene();
    *resync.mutable_resync()->mutable_settings() = open.open_session().settings();
    const v1::Reply again = second.Handle(resync);
    ASSERT_TRUE(again.has_opened()) << again.DebugString();
    EXPECT_EQ(again.opened().session(), session);
    const v1::Reply after = second.Handle(grow);
    ASSERT_TRUE(after.has_cycle()) << after.DebugString();
    ASSERT_EQ(after.cycle().organs_size(), before.cycle().organs_size());
    for (int i = 0; i < after.cycle().organs_size(); ++i) {
        EXPECT_EQ(after.cycle().organs(i).bands(0).irradiance_upper_wm2(),
                  before.cycle().organs(i).bands(0).irradiance_upper_wm2());
        EXPECT_EQ(after.cycle().organs(i).bands(0).irradiance_lower_wm2(),
                  before.cycle().organs(i).bands(0).irradiance_lower_wm2());
    }
}

}  // namespace
}  // namespace leaflux
