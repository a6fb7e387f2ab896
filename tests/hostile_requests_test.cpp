// leafluxd against hostile requests, on loopback as users run it: each of over 150 bad
// requests gets a typed error (code, field, node) within a bound, the daemon stays up, and
// a victim session is unchanged: its next cycle's light is bit for bit that of a control
// session that saw none of them.
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "server/transport.h"
#include "solver/scene/scene.h"
#include "tests/daemon_process.h"
#include "tests/daemon_requests.h"

namespace leaflux {
namespace {

using test::CycleRequest;
using test::Leaf;
using test::OpenRequest;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// A typed answer, not a hang: generous, as the machine may be busy.
constexpr int kReplyBoundMs = 10000;
// And at once: every check comes before the work it guards, so a check that costs seconds
// (the quadratic duplicate-band check took 7.45 s for 100,000 bands) fails here. The
// slowest takes about 0.1 s.
constexpr double kAnswerBoundS = 2.0;

struct Hostile {
    std::string what;
    std::function<v1::Request(const std::string& victim)> make;
    v1::ErrorCode code;
    std::string field;  // a part of the error's field
    std::uint64_t node = 0;
};

using Make = std::function<v1::Request(const std::string&)>;

// A cycle of the victim (number 2: the victim has run cycle 1) changed by `edit`.
Make VictimCycle(std::function<void(v1::Cycle&)> edit) {
    return [edit](const std::string& victim) {
        v1::Request r = CycleRequest(victim, 2);
        edit(*r.mutable_cycle());
        return r;
    };
}

// The victim's cycle 2 adding leaf 9, edited by `edit`.
Make AddedLeaf(std::function<void(v1::Node&)> edit) {
    return VictimCycle([edit](v1::Cycle& c) {
        v1::Node leaf = Leaf(9, 1, 0.5, 0.5);
        edit(leaf);
        *c.mutable_delta()->add_added() = leaf;
    });
}

// An OpenSession of the victim's scene changed by `edit`.
Make Open(std::function<void(v1::Scene&, v1::SolverSettings&)> edit) {
    return [edit](const std::string&) {
        v1::Request r = OpenRequest(2);
        edit(*r.mutable_open_session()->mutable_scene(),
             *r.mutable_open_session()->mutable_settings());
        return r;
    };
}

v1::Sun* AddSun(v1::Cycle& c) {
    v1::Sun* sun = c.add_suns();
    sun->mutable_direction()->set_z(1.0);
    (*sun->mutable_normal_irradiance())["PAR"] = 500.0;
    return sun;
}

v1::SunPeriod* AddPeriod(v1::Scene& s) {
    v1::SunPeriod* p = s.add_sun_periods();
    p->set_latitude_deg(45.0);
    p->set_day_of_year(172);
    p->set_start_h(6.0);
    p->set_end_h(18.0);
    p->set_step_h(1.0);
    (*p->mutable_normal_irradiance())["PAR"] = 800.0;
    return p;
}

v1::Surface* AddGround(v1::Scene& s, const std::string& optics) {
    v1::Surface* ground = s.add_environment();
    ground->set_name("ground");
    ground->set_optics(optics);
    for (double v : {-1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0})
        ground->mutable_mesh()->add_positions(v);
    for (unsigned i : {0u, 1u, 2u, 0u, 2u, 3u}) ground->mutable_mesh()->add_triangles(i);
    return ground;
}

v1::Optics* AddOpaque(v1::Scene& s, const std::string& id, double tauUpper, double tauLower) {
    v1::Optics* o = s.add_optics();
    o->set_id(id);
    v1::BandOptics& b = (*o->mutable_bands())["PAR"];
    b.set_rho_upper(0.2), b.set_rho_lower(0.2), b.set_tau_upper(tauUpper),
        b.set_tau_lower(tauLower);
    return o;
}

std::string Hex(int digits, char c = 'a') { return std::string(digits, c); }

// A request's bytes with map entries in a fixed order, so that equal requests are equal
// bytes.
std::string Canonical(const v1::Request& request) {
    std::string bytes;
    {
        google::protobuf::io::StringOutputStream stream(&bytes);
        google::protobuf::io::CodedOutputStream coded(&stream);
        coded.SetSerializationDeterministic(true);
        request.SerializeToCodedStream(&coded);
    }
    return bytes;
}

std::vector<Hostile> Table() {
    std::vector<Hostile> t;
    const auto add = [&](std::string what, Make make, v1::ErrorCode code, std::string field,
                         std::uint64_t node = 0) {
        t.push_back({std::move(what), std::move(make), code, std::move(field), node});
    };
    using E = v1::ErrorCode;

    // The envelope: protocol version and body.
    for (int version : {-1, 0, -2147483647}) {
        add(
            "protocol version " + std::to_string(version),
            [version](const std::string& v) {
                v1::Request r = CycleRequest(v, 2);
                r.set_version(static_cast<v1::ProtocolVersion>(version));
                return r;
            },
            E::ERROR_CODE_INVALID_ARGUMENT, "version");
    }
    for (int version : {2, 9, 2147483647}) {
        add(
            "protocol version " + std::to_string(version),
            [version](const std::string& v) {
                v1::Request r = CycleRequest(v, 2);
                r.set_version(static_cast<v1::ProtocolVersion>(version));
                return r;
            },
            E::ERROR_CODE_UNSUPPORTED, "version");
    }
    add(
        "no body",
        [](const std::string&) {
            v1::Request r;
            r.set_version(v1::PROTOCOL_VERSION_CURRENT);
            return r;
        },
        E::ERROR_CODE_UNSUPPORTED, "body");

    // Sessions: unknown ones, and Resync of ids this daemon could never have issued.
    for (const std::string& id : {std::string("nope"), std::string(""), std::string("s1"),
                                  Hex(32, '0'), std::string(4096, 'x')}) {
        add(
            "cycle of unknown session '" + id.substr(0, 8) + "'",
            [id](const std::string&) { return CycleRequest(id, 2); }, E::ERROR_CODE_UNKNOWN_SESSION,
            "session");
        add(
            "close of unknown session '" + id.substr(0, 8) + "'",
            [id](const std::string&) {
                v1::Request r = test::StatusRequest();
                r.mutable_close_session()->set_session(id);
                return r;
            },
            E::ERROR_CODE_UNKNOWN_SESSION, "session");
    }
    for (const std::string& id : {std::string("gone"), Hex(32, 'f')}) {
        add(
            "status of unknown session '" + id.substr(0, 8) + "'",
            [id](const std::string&) { return test::StatusRequest(id); },
            E::ERROR_CODE_UNKNOWN_SESSION, "session");
    }
    for (const std::string& id :
         {std::string(""), std::string("s1"), std::string("s2"), Hex(31), Hex(33), Hex(32, 'A'),
          Hex(31) + "g", Hex(31) + "-", std::string(100000, 'a')}) {
        add(
            "resync of the id '" + id.substr(0, 8) +
                (id.size() > 8 ? "…" + id.substr(id.size() - 1) : "") + "' (" +
                std::to_string(id.size()) + ")",
            [id](const std::string&) { return test::ResyncRequest(id, 2); },
            E::ERROR_CODE_INVALID_ARGUMENT, "session");
    }

    // Cycle numbers: positive and after the session's last (1).
    for (std::int64_t number : {std::int64_t{1}, std::int64_t{0}, std::int64_t{-1},
                                std::numeric_limits<std::int64_t>::min()}) {
        add(
            "cycle number " + std::to_string(number),
            [number](const std::string& v) { return CycleRequest(v, number); },
            E::ERROR_CODE_INVALID_ARGUMENT, "number");
    }

    // Topology deltas.
    add("a duplicate id", AddedLeaf([](v1::Node& n) { n.set_id(2); }), E::ERROR_CODE_ALREADY_EXISTS,
        "delta.added", 2);
    add("removal of what does not exist",
        VictimCycle([](v1::Cycle& c) { c.mutable_delta()->add_removed(77); }),
        E::ERROR_CODE_NOT_FOUND, "delta.removed", 77);
    add("removal of node 0", VictimCycle([](v1::Cycle& c) { c.mutable_delta()->add_removed(0); }),
        E::ERROR_CODE_NOT_FOUND, "delta.removed");
    add("update of what does not exist",
        VictimCycle([](v1::Cycle& c) { *c.mutable_delta()->add_updated() = Leaf(78, 1, 0.0); }),
        E::ERROR_CODE_NOT_FOUND, "delta.updated", 78);
    add("an unknown parent", AddedLeaf([](v1::Node& n) { n.set_parent(99); }),
        E::ERROR_CODE_NOT_FOUND, "parent", 9);
    add("a cycle of parents", VictimCycle([](v1::Cycle& c) {
            v1::Node plant;
            plant.set_id(1);
            plant.set_parent(2);
            *c.mutable_delta()->add_updated() = plant;
        }),
        E::ERROR_CODE_CYCLE, "parent");
    add("a node its own parent",
        VictimCycle([](v1::Cycle& c) { *c.mutable_delta()->add_updated() = Leaf(2, 2, 0.0); }),
        E::ERROR_CODE_CYCLE, "parent", 2);
    add("an id added twice", VictimCycle([](v1::Cycle& c) {
            *c.mutable_delta()->add_added() = Leaf(15, 1, 0.0);
            *c.mutable_delta()->add_added() = Leaf(15, 1, 1.0);
        }),
        E::ERROR_CODE_ALREADY_EXISTS, "", 15);
    add("id zero", AddedLeaf([](v1::Node& n) { n.set_id(0); }), E::ERROR_CODE_INVALID_ARGUMENT,
        "nodes.id");
    add("an organ name used twice", AddedLeaf([](v1::Node& n) { n.set_name("leaf2"); }),
        E::ERROR_CODE_ALREADY_EXISTS, "name", 9);
    add("unknown optics", AddedLeaf([](v1::Node& n) { n.mutable_organ()->set_optics("bark"); }),
        E::ERROR_CODE_NOT_FOUND, "organ.optics", 9);
    add("unknown mesh_ref", AddedLeaf([](v1::Node& n) { n.mutable_organ()->set_mesh_ref("x"); }),
        E::ERROR_CODE_NOT_FOUND, "organ.mesh_ref", 9);
    add("positions not in triples",
        AddedLeaf([](v1::Node& n) { n.mutable_organ()->mutable_mesh()->add_positions(1.0); }),
        E::ERROR_CODE_INVALID_ARGUMENT, "organ.mesh.positions", 9);
    add("triangles not in triples",
        AddedLeaf([](v1::Node& n) { n.mutable_organ()->mutable_mesh()->add_triangles(0); }),
        E::ERROR_CODE_INVALID_ARGUMENT, "organ.mesh.triangles", 9);
    add("a triangle beyond the positions",
        AddedLeaf([](v1::Node& n) { n.mutable_organ()->mutable_mesh()->set_triangles(5, 40); }),
        E::ERROR_CODE_INVALID_ARGUMENT, "organ.mesh.triangles[1]", 9);
    add("an index of 2^32 - 1", AddedLeaf([](v1::Node& n) {
            n.mutable_organ()->mutable_mesh()->set_triangles(0, 0xffffffffu);
        }),
        E::ERROR_CODE_INVALID_ARGUMENT, "organ.mesh.triangles[0]", 9);
    add("a mesh without triangles",
        AddedLeaf([](v1::Node& n) { n.mutable_organ()->mutable_mesh()->clear_triangles(); }),
        E::ERROR_CODE_DEGENERATE, "organ.mesh.triangles", 9);
    add("a collapsed leaf", AddedLeaf([](v1::Node& n) {
            for (int i = 0; i < 12; ++i) n.mutable_organ()->mutable_mesh()->set_positions(i, 0.5);
        }),
        E::ERROR_CODE_DEGENERATE, "organ.mesh.triangles", 9);
    for (int i = 0; i < 12; ++i) {
        for (double bad : {kNaN, kInf}) {
            add("position " + std::to_string(i) + " = " + std::to_string(bad),
                AddedLeaf([i, bad](v1::Node& n) {
                    n.mutable_organ()->mutable_mesh()->set_positions(i, bad);
                }),
                E::ERROR_CODE_INVALID_ARGUMENT, "organ.mesh.positions", 9);
        }
    }
    for (int size : {1, 5, 11, 13, 16}) {
        add("a frame of " + std::to_string(size) + " numbers", AddedLeaf([size](v1::Node& n) {
                for (int k = 0; k < size; ++k) n.mutable_frame()->add_m(k % 5 == 0 ? 1.0 : 0.0);
            }),
            E::ERROR_CODE_INVALID_ARGUMENT, "frame", 9);
    }
    for (int k = 0; k < 12; ++k) {
        for (double bad : {kNaN, kInf, -kInf}) {
            add("frame entry " + std::to_string(k) + " = " + std::to_string(bad),
                AddedLeaf([k, bad](v1::Node& n) {
                    for (int e = 0; e < 12; ++e) n.mutable_frame()->add_m(e % 5 == 0 ? 1.0 : 0.0);
                    n.mutable_frame()->set_m(k, bad);
                }),
                E::ERROR_CODE_INVALID_ARGUMENT, "frame", 9);
        }
    }
    add("a singular frame", AddedLeaf([](v1::Node& n) {
            for (int e = 0; e < 12; ++e) n.mutable_frame()->add_m(0.0);
        }),
        E::ERROR_CODE_DEGENERATE, "frame", 9);
    for (double bad : {kNaN, kInf, -kInf}) {
        add("age " + std::to_string(bad), AddedLeaf([bad](v1::Node& n) { n.set_age(bad); }),
            E::ERROR_CODE_INVALID_ARGUMENT, "age", 9);
        add("attribute " + std::to_string(bad),
            AddedLeaf([bad](v1::Node& n) { (*n.mutable_attributes())["vigour"] = bad; }),
            E::ERROR_CODE_INVALID_ARGUMENT, "attributes[vigour]", 9);
    }

    // A cycle's suns and outputs.
    add("a sun with no direction", VictimCycle([](v1::Cycle& c) {
            (*c.add_suns()->mutable_normal_irradiance())["PAR"] = 1.0;
        }),
        E::ERROR_CODE_INVALID_ARGUMENT, "suns[0].direction");
    for (double bad : {kNaN, kInf}) {
        add("a sun direction of " + std::to_string(bad),
            VictimCycle([bad](v1::Cycle& c) { AddSun(c)->mutable_direction()->set_x(bad); }),
            E::ERROR_CODE_INVALID_ARGUMENT, "suns[0].direction");
    }
    for (double bad : {kNaN, kInf, -3.0}) {
        add("a sun of " + std::to_string(bad) + " W/m²", VictimCycle([bad](v1::Cycle& c) {
                (*AddSun(c)->mutable_normal_irradiance())["PAR"] = bad;
            }),
            E::ERROR_CODE_INVALID_ARGUMENT, "suns[0].normal_irradiance[PAR]");
    }
    add("a sun in an unknown band",
        VictimCycle([](v1::Cycle& c) { (*AddSun(c)->mutable_normal_irradiance())["UV"] = 1.0; }),
        E::ERROR_CODE_NOT_FOUND, "suns[0].normal_irradiance[UV]");
    add("a sun missing a band",
        VictimCycle([](v1::Cycle& c) { c.add_suns()->mutable_direction()->set_z(1.0); }),
        E::ERROR_CODE_NOT_FOUND, "suns[0].normal_irradiance");
    for (double bad : {45.0, -1.0, kNaN}) {
        add("a sun of angular radius " + std::to_string(bad),
            VictimCycle([bad](v1::Cycle& c) { AddSun(c)->set_angular_radius_deg(bad); }),
            E::ERROR_CODE_INVALID_ARGUMENT, "suns[0].angular_radius_deg");
    }
    for (const auto& [what, latitude, day, hour, field] :
         std::vector<std::tuple<std::string, double, int, double, std::string>>{
             {"latitude 95", 95, 100, 12, "latitude_deg"},
             {"latitude -91", -91, 100, 12, "latitude_deg"},
             {"latitude NaN", kNaN, 100, 12, "latitude_deg"},
             {"day 0", 45, 0, 12, "day_of_year"},
             {"day 367", 45, 367, 12, "day_of_year"},
             {"hour -1", 45, 100, -1, "solar_time_h"},
             {"hour 25", 45, 100, 25, "solar_time_h"},
             {"hour NaN", 45, 100, kNaN, "solar_time_h"}}) {
        add("a solar sun at " + what, VictimCycle([latitude, day, hour](v1::Cycle& c) {
                v1::Sun* sun = AddSun(c);
                sun->mutable_solar()->set_latitude_deg(latitude);
                sun->mutable_solar()->set_day_of_year(day);
                sun->mutable_solar()->set_solar_time_h(hour);
            }),
            E::ERROR_CODE_INVALID_ARGUMENT, "suns[0].solar." + field);
    }
    add("2000 suns in a cycle", VictimCycle([](v1::Cycle& c) {
            for (int i = 0; i < 2000; ++i) AddSun(c);
        }),
        E::ERROR_CODE_TOO_LARGE, "suns");
    add("an unknown band in outputs",
        VictimCycle([](v1::Cycle& c) { c.mutable_outputs()->add_bands("UV"); }),
        E::ERROR_CODE_NOT_FOUND, "outputs.bands[UV]");
    add("a band asked twice", VictimCycle([](v1::Cycle& c) {
            c.mutable_outputs()->add_bands("PAR");
            c.mutable_outputs()->add_bands("PAR");
        }),
        E::ERROR_CODE_ALREADY_EXISTS, "outputs.bands[PAR]");
    add("one band more than a session may declare, asked", VictimCycle([](v1::Cycle& c) {
            for (int i = 0; i <= kMaxBands; ++i) c.mutable_outputs()->add_bands("PAR");
        }),
        E::ERROR_CODE_TOO_LARGE, "outputs.bands");
    add("100000 bands asked", VictimCycle([](v1::Cycle& c) {
            for (int i = 0; i < 100000; ++i)
                c.mutable_outputs()->add_bands("b" + std::to_string(i));
        }),
        E::ERROR_CODE_TOO_LARGE, "outputs.bands");
    add("a delta of more nodes than a session may hold", VictimCycle([](v1::Cycle& c) {
            for (int i = 0; i < 1000; ++i) *c.mutable_delta()->add_added() = Leaf(100 + i, 1, i);
        }),
        E::ERROR_CODE_TOO_LARGE, "delta.added");

    // Scenes at opening: bands, optics, environment, sources, periodic domain, settings.
    add("no band", Open([](v1::Scene& s, v1::SolverSettings&) { s.clear_bands(); }),
        E::ERROR_CODE_NOT_FOUND, "");
    add("a band declared twice",
        Open([](v1::Scene& s, v1::SolverSettings&) { s.add_bands()->set_name("PAR"); }),
        E::ERROR_CODE_ALREADY_EXISTS, "bands[PAR]");
    add("a band without a name", Open([](v1::Scene& s, v1::SolverSettings&) { s.add_bands(); }),
        E::ERROR_CODE_NOT_FOUND, "optics[leaf].bands");
    add("one band more than a session may declare", Open([](v1::Scene& s, v1::SolverSettings&) {
            for (int i = 0; i < kMaxBands; ++i) s.add_bands()->set_name("b" + std::to_string(i));
        }),
        E::ERROR_CODE_TOO_LARGE, "bands");
    add("100000 bands", Open([](v1::Scene& s, v1::SolverSettings&) {
            for (int i = 0; i < 100000; ++i) s.add_bands()->set_name("b" + std::to_string(i));
        }),
        E::ERROR_CODE_TOO_LARGE, "bands");
    add("optics missing a band",
        Open([](v1::Scene& s, v1::SolverSettings&) { s.add_bands()->set_name("NIR"); }),
        E::ERROR_CODE_NOT_FOUND, "optics[leaf].bands");
    add("optics in an unknown band", Open([](v1::Scene& s, v1::SolverSettings&) {
            (*s.mutable_optics(0)->mutable_bands())["UV"];
        }),
        E::ERROR_CODE_NOT_FOUND, "optics[leaf].bands[UV]");
    add("optics declared twice",
        Open([](v1::Scene& s, v1::SolverSettings&) { *s.add_optics() = s.optics(0); }),
        E::ERROR_CODE_ALREADY_EXISTS, "optics[leaf]");
    for (const char* property : {"rho_upper", "rho_lower", "tau_upper", "tau_lower"}) {
        for (double bad : {kNaN, -0.1, 1.5}) {
            add(std::string("leaf ") + property + " = " + std::to_string(bad),
                Open([property, bad](v1::Scene& s, v1::SolverSettings&) {
                    v1::BandOptics& b = (*s.mutable_optics(0)->mutable_bands())["PAR"];
                    const auto* field = b.GetDescriptor()->FindFieldByName(property);
                    b.GetReflection()->SetDouble(&b, field, bad);
                }),
                E::ERROR_CODE_INVALID_ARGUMENT, std::string("optics[leaf].bands[PAR].") + property);
        }
    }
    add("rho + tau > 1 on the upper side", Open([](v1::Scene& s, v1::SolverSettings&) {
            (*s.mutable_optics(0)->mutable_bands())["PAR"].set_tau_upper(0.95);
        }),
        E::ERROR_CODE_INVALID_ARGUMENT, "optics[leaf].bands[PAR]");
    add("rho + tau > 1 on the lower side", Open([](v1::Scene& s, v1::SolverSettings&) {
            (*s.mutable_optics(0)->mutable_bands())["PAR"].set_tau_lower(0.95);
        }),
        E::ERROR_CODE_INVALID_ARGUMENT, "optics[leaf].bands[PAR]");
    for (const auto& [upper, lower] : {std::pair{0.3, 0.0}, {0.0, 0.3}, {0.1, 0.1}}) {
        add("an opaque ground of tau " + std::to_string(upper) + ", " + std::to_string(lower),
            Open([upper, lower](v1::Scene& s, v1::SolverSettings&) {
                AddOpaque(s, "soil", upper, lower);
                AddGround(s, "soil");
            }),
            E::ERROR_CODE_INVALID_ARGUMENT, "environment[ground].optics");
    }
    add("a ground of unknown optics",
        Open([](v1::Scene& s, v1::SolverSettings&) { AddGround(s, "mud"); }),
        E::ERROR_CODE_NOT_FOUND, "environment[ground].optics");
    add("a ground without a name", Open([](v1::Scene& s, v1::SolverSettings&) {
            AddOpaque(s, "soil", 0, 0);
            AddGround(s, "soil")->clear_name();
        }),
        E::ERROR_CODE_INVALID_ARGUMENT, "environment[0].name");
    add("two grounds of one name", Open([](v1::Scene& s, v1::SolverSettings&) {
            AddOpaque(s, "soil", 0, 0);
            AddGround(s, "soil");
            AddGround(s, "soil");
        }),
        E::ERROR_CODE_ALREADY_EXISTS, "environment[ground].name");
    add("a ground of NaN", Open([](v1::Scene& s, v1::SolverSettings&) {
            AddOpaque(s, "soil", 0, 0);
            AddGround(s, "soil")->mutable_mesh()->set_positions(0, kNaN);
        }),
        E::ERROR_CODE_INVALID_ARGUMENT, "environment[ground].mesh.positions");
    for (double bad : {kNaN, -1.0, kInf}) {
        add("a sky of " + std::to_string(bad), Open([bad](v1::Scene& s, v1::SolverSettings&) {
                (*s.mutable_sky()->mutable_horizontal_irradiance())["PAR"] = bad;
            }),
            E::ERROR_CODE_INVALID_ARGUMENT, "sky.horizontal_irradiance[PAR]");
    }
    add("a sky in an unknown band", Open([](v1::Scene& s, v1::SolverSettings&) {
            (*s.mutable_sky()->mutable_horizontal_irradiance())["UV"] = 1;
        }),
        E::ERROR_CODE_NOT_FOUND, "sky.horizontal_irradiance[UV]");
    add("a sky missing a band", Open([](v1::Scene& s, v1::SolverSettings&) {
            s.mutable_sky()->set_model(v1::SKY_MODEL_UNIFORM);
        }),
        E::ERROR_CODE_NOT_FOUND, "sky.horizontal_irradiance");
    for (double bad : {kNaN, -5.0}) {
        add("a lamp of exitance " + std::to_string(bad),
            Open([bad](v1::Scene& s, v1::SolverSettings&) {
                v1::Emitter* lamp = s.add_emitters();
                lamp->set_name("lamp");
                *lamp->mutable_mesh() = Leaf(99, 0, 0.0, 2.0).organ().mesh();
                (*lamp->mutable_exitance())["PAR"] = bad;
            }),
            E::ERROR_CODE_INVALID_ARGUMENT, "emitters[lamp].exitance[PAR]");
    }
    add("a lamp without triangles", Open([](v1::Scene& s, v1::SolverSettings&) {
            v1::Emitter* lamp = s.add_emitters();
            lamp->set_name("lamp");
            (*lamp->mutable_exitance())["PAR"] = 10;
        }),
        E::ERROR_CODE_DEGENERATE, "emitters[lamp].mesh");
    add("a lamp of unknown optics", Open([](v1::Scene& s, v1::SolverSettings&) {
            v1::Emitter* lamp = s.add_emitters();
            lamp->set_name("lamp");
            lamp->set_optics("glass");
            *lamp->mutable_mesh() = Leaf(99, 0, 0.0, 2.0).organ().mesh();
            (*lamp->mutable_exitance())["PAR"] = 10;
        }),
        E::ERROR_CODE_NOT_FOUND, "emitters[lamp].optics");
    add("2000 suns", Open([](v1::Scene& s, v1::SolverSettings&) {
            for (int i = 0; i < 2000; ++i) *s.add_suns() = s.suns(0);
        }),
        E::ERROR_CODE_TOO_LARGE, "suns");
    for (const auto& [label, step] :
         {std::pair{"1e-6", 1e-6}, {"1e-9", 1e-9}, {"1e-300", 1e-300}}) {
        add(std::string("a sun period of step ") + label + " h",
            Open([step](v1::Scene& s, v1::SolverSettings&) { AddPeriod(s)->set_step_h(step); }),
            E::ERROR_CODE_TOO_LARGE, "sun_periods[0].step_h");
    }
    add("600 sun periods of 12 steps", Open([](v1::Scene& s, v1::SolverSettings&) {
            for (int i = 0; i < 600; ++i) AddPeriod(s);
        }),
        E::ERROR_CODE_TOO_LARGE, "sun_periods");
    for (const auto& [what, edit] :
         std::vector<std::pair<std::string, std::function<void(v1::SunPeriod&)>>>{
             {"step 0", [](v1::SunPeriod& p) { p.set_step_h(0); }},
             {"step -1", [](v1::SunPeriod& p) { p.set_step_h(-1); }},
             {"step NaN", [](v1::SunPeriod& p) { p.set_step_h(kNaN); }},
             {"end before start", [](v1::SunPeriod& p) { p.set_end_h(5); }},
             {"end after 24 h", [](v1::SunPeriod& p) { p.set_end_h(25); }},
             {"start before 0 h", [](v1::SunPeriod& p) { p.set_start_h(-1); }},
             {"start NaN", [](v1::SunPeriod& p) { p.set_start_h(kNaN); }},
             {"day 0", [](v1::SunPeriod& p) { p.set_day_of_year(0); }},
             {"latitude 100", [](v1::SunPeriod& p) { p.set_latitude_deg(100); }},
             {"latitude NaN", [](v1::SunPeriod& p) { p.set_latitude_deg(kNaN); }}}) {
        add("a sun period of " + what,
            Open([edit](v1::Scene& s, v1::SolverSettings&) { edit(*AddPeriod(s)); }),
            E::ERROR_CODE_INVALID_ARGUMENT, "sun_periods[0]");
    }
    for (const auto& [what, xMax, yMax] :
         std::vector<std::tuple<std::string, double, double>>{{"empty", 1.0, 0.0},
                                                              {"inverted", -1.0, -1.0},
                                                              {"NaN", kNaN, 1.0},
                                                              {"infinite", kInf, 1.0}}) {
        add("a periodic domain " + what, Open([xMax, yMax](v1::Scene& s, v1::SolverSettings&) {
                s.mutable_periodic()->set_x_max(xMax);
                s.mutable_periodic()->set_y_max(yMax);
            }),
            E::ERROR_CODE_INVALID_ARGUMENT, "periodic");
    }
    add("a periodic tile 1 mm wide around a plant", Open([](v1::Scene& s, v1::SolverSettings&) {
            s.mutable_periodic()->set_x_max(0.001);
            s.mutable_periodic()->set_y_max(0.001);
        }),
        E::ERROR_CODE_TOO_LARGE, "periodic");
    add("a scene of more nodes than a session may hold",
        Open([](v1::Scene& s, v1::SolverSettings&) {
            for (int i = 0; i < 1000; ++i) *s.add_nodes() = Leaf(100 + i, 1, i);
        }),
        E::ERROR_CODE_TOO_LARGE, "nodes");
    add("files to import", Open([](v1::Scene& s, v1::SolverSettings&) {
            s.add_imports()->set_path("/etc/passwd.obj");
        }),
        E::ERROR_CODE_UNSUPPORTED, "scene.imports");
    add("Caribu lights to read", Open([](v1::Scene& s, v1::SolverSettings&) {
            s.add_can_lights()->set_path("/etc/passwd");
        }),
        E::ERROR_CODE_UNSUPPORTED, "scene.imports");
    add("a scene of a newer version", Open([](v1::Scene& s, v1::SolverSettings&) {
            s.set_version(static_cast<v1::ProtocolVersion>(7));
        }),
        E::ERROR_CODE_UNSUPPORTED, "version");
    add("a scene of version -1", Open([](v1::Scene& s, v1::SolverSettings&) {
            s.set_version(static_cast<v1::ProtocolVersion>(-1));
        }),
        E::ERROR_CODE_INVALID_ARGUMENT, "version");
    for (double bad : {-1.0, 1.0, 3.0, kNaN, kInf}) {
        add("epsilon " + std::to_string(bad),
            Open([bad](v1::Scene&, v1::SolverSettings& s) { s.set_epsilon(bad); }),
            E::ERROR_CODE_INVALID_ARGUMENT, "settings.epsilon");
    }
    for (int bad : {-1, (1 << 24) + 1, std::numeric_limits<int>::min()}) {
        add("samples " + std::to_string(bad),
            Open([bad](v1::Scene&, v1::SolverSettings& s) { s.set_samples(bad); }),
            E::ERROR_CODE_INVALID_ARGUMENT, "settings.samples");
    }
    for (int bad : {-2, 1025}) {
        add("threads " + std::to_string(bad),
            Open([bad](v1::Scene&, v1::SolverSettings& s) { s.set_threads(bad); }),
            E::ERROR_CODE_INVALID_ARGUMENT, "settings.threads");
    }
    for (int bad : {-1, 9, 20}) {
        add("subdivision " + std::to_string(bad),
            Open([bad](v1::Scene&, v1::SolverSettings& s) { s.set_subdivision(bad); }),
            E::ERROR_CODE_INVALID_ARGUMENT, "settings.subdivision");
    }
    // A Resync of the victim with a bad scene leaves the victim as it was.
    add(
        "a resync of the victim with NaN optics",
        [](const std::string& v) {
            v1::Request r = test::ResyncRequest(v, 2);
            (*r.mutable_resync()->mutable_scene()->mutable_optics(0)->mutable_bands())["PAR"]
                .set_rho_upper(kNaN);
            return r;
        },
        E::ERROR_CODE_INVALID_ARGUMENT, "optics[leaf].bands[PAR].rho_upper");
    add(
        "a resync of the victim with imports",
        [](const std::string& v) {
            v1::Request r = test::ResyncRequest(v, 2);
            r.mutable_resync()->mutable_scene()->add_imports()->set_path("x.obj");
            return r;
        },
        E::ERROR_CODE_UNSUPPORTED, "scene.imports");
    add(
        "a resync of the victim with too many nodes",
        [](const std::string& v) {
            v1::Request r = test::ResyncRequest(v, 2);
            for (int i = 0; i < 1000; ++i)
                *r.mutable_resync()->mutable_scene()->add_nodes() = Leaf(100 + i, 1, i);
            return r;
        },
        E::ERROR_CODE_TOO_LARGE, "nodes");
    add(
        "a resync of the victim with a cycle of parents",
        [](const std::string& v) {
            v1::Request r = test::ResyncRequest(v, 2);
            r.mutable_resync()->mutable_scene()->mutable_nodes(0)->set_parent(2);
            return r;
        },
        E::ERROR_CODE_CYCLE, "parent");
    return t;
}

class HostileRequests : public ::testing::Test {
  protected:
    // A victim and its control, each opened and lit once.
    void SetUp() override {
        ASSERT_FALSE(daemon_.Endpoint().empty());
        connection_ = std::make_unique<ClientConnection>(context_, daemon_.Endpoint());
        victim_ = Call(OpenRequest(2)).opened().session();
        control_ = Call(OpenRequest(2)).opened().session();
        ASSERT_FALSE(victim_.empty());
        ASSERT_FALSE(control_.empty());
        ASSERT_TRUE(Call(CycleRequest(victim_, 1)).has_cycle());
        ASSERT_TRUE(Call(CycleRequest(control_, 1)).has_cycle());
    }

    v1::Reply Call(const v1::Request& request, double* seconds = nullptr) {
        return CallBytes(request.SerializeAsString(), seconds);
    }
    v1::Reply CallBytes(const std::string& bytes, double* seconds = nullptr) {
        std::string answer;
        const auto start = std::chrono::steady_clock::now();
        const bool answered = connection_->Call(bytes, answer, kReplyBoundMs);
        if (seconds) {
            *seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
        v1::Reply reply;
        if (!answered) {
            // A fresh connection: a late reply must not answer the next request.
            connection_ = std::make_unique<ClientConnection>(context_, daemon_.Endpoint());
            reply.mutable_error()->set_message("no reply within the bound");
        } else if (!reply.ParseFromString(answer)) {
            reply.mutable_error()->set_message("the reply is not a leaflux.v1.Reply");
        }
        return reply;
    }

    // The victim as the daemon reports it: three nodes, one cycle.
    void ExpectVictimUnchanged() {
        const v1::Reply state = Call(test::StatusRequest(victim_));
        ASSERT_TRUE(state.has_status()) << state.DebugString();
        ASSERT_EQ(state.status().sessions_size(), 1);
        EXPECT_EQ(state.status().sessions(0).nodes(), 3);
        EXPECT_EQ(state.status().sessions(0).cycles(), 1);
    }

    // Both sessions' cycle 2, a leaf added: the same light, bit for bit.
    void ExpectVictimLitAsControl() {
        const auto grown = [&](const std::string& session) {
            v1::Request r = CycleRequest(session, 2);
            *r.mutable_cycle()->mutable_delta()->add_added() = Leaf(9, 1, 0.05, 0.8);
            const v1::Reply reply = Call(r);
            EXPECT_TRUE(reply.has_cycle()) << reply.DebugString();
            v1::CycleResult result = reply.cycle();
            result.clear_session();
            result.clear_statistics();
            return result.SerializeAsString();
        };
        const std::string victim = grown(victim_), control = grown(control_);
        EXPECT_GT(victim.size(), 100u);
        EXPECT_EQ(victim, control) << "the victim's light differs from its control's";
    }

    test::DaemonProcess daemon_{{"--max-message-mb", "1", "--max-nodes", "500", "--max-suns",
                                 "1000", "--solver-threads", "1"}};
    zmq::context_t context_;
    std::unique_ptr<ClientConnection> connection_;
    std::string victim_, control_;
};

TEST_F(HostileRequests, EachGetsATypedErrorInTimeAndTheVictimIsUnchanged) {
    const std::vector<Hostile> table = Table();
    EXPECT_GE(table.size(), 150u);
    std::set<std::string> names, requests;
    for (const Hostile& hostile : table) {
        EXPECT_TRUE(names.insert(hostile.what).second) << "named twice: " << hostile.what;
        EXPECT_TRUE(requests.insert(Canonical(hostile.make(victim_))).second)
            << "the same request as another: " << hostile.what;
    }
    double slowest = 0.0;
    std::string slowestWhat;
    int wrong = 0;
    for (const Hostile& hostile : table) {
        SCOPED_TRACE(hostile.what);
        double seconds = 0.0;
        const v1::Reply reply = Call(hostile.make(victim_), &seconds);
        const v1::Error& error = reply.error();
        const bool typed = reply.has_error() && error.code() == hostile.code &&
                           error.field().find(hostile.field) != std::string::npos &&
                           (hostile.node == 0 || error.node() == hostile.node);
        if (!typed) {
            ++wrong;
            ADD_FAILURE() << "expected " << v1::ErrorCode_Name(hostile.code) << " ("
                          << hostile.field << ", node " << hostile.node << "), got "
                          << reply.ShortDebugString().substr(0, 300);
        }
        if (typed && seconds > kAnswerBoundS) {
            ++wrong;
            ADD_FAILURE() << "answered after " << seconds << " s, over " << kAnswerBoundS << " s";
        }
        if (seconds > slowest) slowest = seconds, slowestWhat = hostile.what;
        ExpectVictimUnchanged();
    }
    std::printf(
        "%zu distinct hostile requests, %d not answered with the typed error expected "
        "within %g s\n",
        requests.size(), wrong, kAnswerBoundS);
    ExpectVictimLitAsControl();
    std::printf("the slowest answered in %.3f s (%s)\n", slowest, slowestWhat.c_str());
}

// What the transport refuses before decoding: garbage, messages over the cap in one frame
// or in many, too many frames. Each gets a typed error, the too large ones with the
// request id they carried, and the daemon serves on.
TEST_F(HostileRequests, TheTransportAnswersGarbageAndOversizedMessages) {
    for (const std::string& garbage :
         {std::string("\xff\x01garbage", 9), std::string("\x0a\xff\xff\xff", 4),
          std::string(64, '\xff')}) {
        const v1::Reply reply = CallBytes(garbage);
        EXPECT_EQ(reply.error().code(), v1::ERROR_CODE_PARSE) << reply.ShortDebugString();
        ExpectVictimUnchanged();
    }
    v1::Request big = CycleRequest(victim_, 2);
    big.set_request_id(4242);
    v1::Node leaf = Leaf(9, 1, 0.0);
    leaf.set_name(std::string(1536 << 10, 'n'));  // 1.5 MiB, over the 1 MiB cap
    *big.mutable_cycle()->mutable_delta()->add_added() = leaf;
    const v1::Reply large = Call(big);
    EXPECT_EQ(large.error().code(), v1::ERROR_CODE_TOO_LARGE) << large.error().ShortDebugString();
    EXPECT_EQ(large.request_id(), 4242u);
    ExpectVictimUnchanged();

    // Many frames, each under the cap, together over it; and too many small frames.
    for (const auto& [frames, size] : {std::pair{3, 600 << 10}, {12, 10}}) {
        zmq::socket_t raw(context_, zmq::socket_type::dealer);
        raw.set(zmq::sockopt::linger, 0);
        raw.connect(daemon_.Endpoint());
        for (int f = 0; f < frames; ++f) {
            raw.send(zmq::buffer(std::string(size, 'x')),
                     f + 1 < frames ? zmq::send_flags::sndmore : zmq::send_flags::none);
        }
        zmq::pollitem_t items[] = {{raw.handle(), 0, ZMQ_POLLIN, 0}};
        zmq::poll(items, 1, std::chrono::milliseconds(kReplyBoundMs));
        ASSERT_TRUE(items[0].revents & ZMQ_POLLIN) << frames << " frames: no reply";
        std::vector<zmq::message_t> parts;
        ASSERT_TRUE(zmq::recv_multipart(raw, std::back_inserter(parts)));
        v1::Reply reply;
        ASSERT_TRUE(reply.ParseFromArray(parts.back().data(), parts.back().size()));
        EXPECT_EQ(reply.error().code(), v1::ERROR_CODE_TOO_LARGE) << frames << " frames";
        ExpectVictimUnchanged();
    }
    ExpectVictimLitAsControl();
}

}  // namespace
}  // namespace leaflux
