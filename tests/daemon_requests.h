// Small leaflux.v1 requests for the daemon's tests: a plant of one leaf under a vertical
// sun, and cycles of it.
#pragma once

#include <cstdint>
#include <string>

#include "leaflux.pb.h"

namespace leaflux::test {

// A 10 cm square leaf at height z, its corner at (x, 0).
inline v1::Node Leaf(std::uint64_t id, std::uint64_t parent, double x, double z = 1.0) {
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

// A plant (node 1) with `leaves` leaves (nodes 2, 3, …, 20 cm apart along x), one band
// (PAR), a sun at the zenith; HRC.
inline v1::Request OpenRequest(int leaves = 1) {
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
    for (int i = 0; i < leaves; ++i) *scene->add_nodes() = Leaf(2 + i, 1, 0.2 * i, 1.0 - 0.05 * i);
    v1::Sun* sun = scene->add_suns();
    sun->mutable_direction()->set_x(0.2);
    sun->mutable_direction()->set_z(1.0);
    (*sun->mutable_normal_irradiance())["PAR"] = 1000.0;
    open->mutable_settings()->set_solver(v1::SOLVER_KIND_HRC);
    return request;
}

// The Resync that recreates what OpenRequest(leaves) opened, under `session`.
inline v1::Request ResyncRequest(const std::string& session, int leaves = 1) {
    const v1::Request open = OpenRequest(leaves);
    v1::Request request;
    request.set_version(v1::PROTOCOL_VERSION_CURRENT);
    request.mutable_resync()->set_session(session);
    *request.mutable_resync()->mutable_scene() = open.open_session().scene();
    *request.mutable_resync()->mutable_settings() = open.open_session().settings();
    return request;
}

inline v1::Request CycleRequest(const std::string& session, std::int64_t number) {
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

inline v1::Request StatusRequest(const std::string& session = "") {
    v1::Request request;
    request.set_version(v1::PROTOCOL_VERSION_CURRENT);
    request.mutable_status()->set_session(session);
    return request;
}

}  // namespace leaflux::test
