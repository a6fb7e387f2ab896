#include "server/client_cli.h"

#include <fcntl.h>
#include <google/protobuf/text_format.h>
#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "server/cli_checks.h"
#include "server/scene_proto.h"
#include "solver/results/export.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

// Full precision, as Python's repr reads it back.
std::string Repr(double value) { return fmt::format("{}", value); }

void WriteBand(std::ostream& out, const v1::BandLight& b) {
    out << CsvQuoted(b.band()) << ',' << Repr(b.irradiance_upper_wm2()) << ','
        << Repr(b.irradiance_lower_wm2()) << ',' << Repr(b.absorbed_w()) << ',';
    if (b.has_light_vector()) {
        out << Repr(b.light_vector().x()) << ',' << Repr(b.light_vector().y()) << ','
            << Repr(b.light_vector().z());
    } else {
        out << ",,";
    }
    out << ',' << Repr(b.stderr_upper_wm2()) << ',' << Repr(b.stderr_lower_wm2());
    // Unset for a band without a photon unit: empty cells, as in `leaflux solve --out`.
    const auto photons = [&](bool has, double value) {
        out << ',';
        if (has) out << Repr(value);
    };
    photons(b.has_photon_irradiance_upper_umol_m2_s(), b.photon_irradiance_upper_umol_m2_s());
    photons(b.has_photon_irradiance_lower_umol_m2_s(), b.photon_irradiance_lower_umol_m2_s());
    photons(b.has_absorbed_umol_s(), b.absorbed_umol_s());
    out << '\n';
}

v1::Request OpenFromFile(const ClientCommand& command) {
    // The scene file's imports are read here: the daemon reads no files.
    v1::Request request;
    *request.mutable_open_session()->mutable_scene() =
        ToProto(LoadSceneFile(command.scene, ImportOptions{command.strict}));
    v1::SolverSettings* settings = request.mutable_open_session()->mutable_settings();
    settings->set_solver(command.solver == "mc" ? v1::SOLVER_KIND_MONTE_CARLO
                                                : v1::SOLVER_KIND_HRC);
    settings->set_epsilon(command.epsilon);
    return request;
}

v1::Request CycleFromFile(const ClientCommand& command) {
    v1::Request request;
    v1::Cycle* cycle = request.mutable_cycle();
    cycle->set_session(command.session);
    cycle->set_number(command.number);
    cycle->mutable_outputs()->set_leaves(command.leaves);
    cycle->mutable_outputs()->set_structures(command.structures);
    if (!command.delta.empty()) {
        std::ifstream in(command.delta);
        std::stringstream text;
        text << in.rdbuf();
        if (!in ||
            !google::protobuf::TextFormat::ParseFromString(text.str(), cycle->mutable_delta())) {
            throw InputError(ErrorCode::kParse, command.delta,
                             "not a leaflux.v1.TopologyDelta in text format");
        }
    }
    return request;
}

// Sends one request to leafluxd; prints the reply in protobuf text format, or, for a cycle
// with --out, writes its light as CSV and prints a summary.
int RunClient(const ClientCommand& command, const v1::Request& request) {
    std::string serverKey;
    if (!command.curveServerKeyFile.empty()) {
        const auto key = ReadCurveKey(command.curveServerKeyFile);
        if (!key) {
            throw InputError(ErrorCode::kParse, command.curveServerKeyFile,
                             "not a Z85 CurveZMQ public key");
        }
        serverKey = *key;
    }
    const bool csv = request.has_cycle() && !command.out.empty();
    if (csv) CheckWritable(command.out, "--out");  // before the daemon solves
    ClientTimeouts timeouts = command.timeouts;
    if (command.timeoutS > 0.0)
        timeouts = ClientTimeouts::All(static_cast<int>(1000 * command.timeoutS));
    v1::Reply reply;
    try {
        Client client(command.endpoint, serverKey, timeouts);
        reply = client.Call(request);
    } catch (const ClientError& e) {
        spdlog::error("{}", e.what());  // names the endpoint
        return 4;
    }
    if (csv && reply.has_cycle()) {
        std::ofstream file(command.out);
        WriteCycleCsv(file, reply.cycle());
        if (!file.flush()) throw InputError(ErrorCode::kIo, command.out, "cannot be written");
        std::cout << CycleSummary(reply.cycle()) << "\nwrote " << command.out << std::endl;
        return 0;
    }
    std::string text;
    google::protobuf::TextFormat::PrintToString(reply, &text);
    std::cout << text;
    return reply.has_error() ? 2 : 0;
}

}  // namespace

void WriteCycleCsv(std::ostream& out, const v1::CycleResult& cycle) {
    out << "cycle,kind,node,name,type,organs,area_m2,band,irradiance_upper_wm2,"
           "irradiance_lower_wm2,absorbed_w,light_vector_x,light_vector_y,light_vector_z,"
           "stderr_upper_wm2,stderr_lower_wm2,photon_irradiance_upper_umol_m2_s,"
           "photon_irradiance_lower_umol_m2_s,absorbed_umol_s\n";
    for (const v1::OrganLight& organ : cycle.organs()) {
        for (const v1::BandLight& b : organ.bands()) {
            out << cycle.number() << ",organ," << organ.node() << ',' << CsvQuoted(organ.name())
                << ",,1," << Repr(organ.area_m2()) << ',';
            WriteBand(out, b);
        }
    }
    for (const v1::StructureLight& s : cycle.structures()) {
        for (const v1::BandLight& b : s.bands()) {
            out << cycle.number() << ",structure," << s.node() << ',' << CsvQuoted(s.name()) << ','
                << v1::NodeType_Name(s.type()) << ',' << s.organs() << ',' << Repr(s.area_m2())
                << ',';
            WriteBand(out, b);
        }
    }
}

std::string CycleSummary(const v1::CycleResult& cycle) {
    std::map<std::string, double> absorbedW;  // by the plants' organs (node ≠ 0)
    std::vector<std::string> bands;
    double areaM2 = 0.0;
    int plantOrgans = 0;
    for (const v1::OrganLight& organ : cycle.organs()) {
        if (organ.node() == 0) continue;
        ++plantOrgans;
        areaM2 += organ.area_m2();
        for (const v1::BandLight& b : organ.bands()) {
            if (!absorbedW.count(b.band())) bands.push_back(b.band());
            absorbedW[b.band()] += b.absorbed_w();
        }
    }
    const v1::SolveStatistics& stats = cycle.statistics();
    std::string text = fmt::format(
        "cycle {}: {} organs ({} of plants, {:.6g} m²), {} structures; solved in {:.3g} s "
        "on {} threads{}",
        cycle.number(), cycle.organs_size(), plantOrgans, areaM2, cycle.structures_size(),
        stats.wall_seconds(), stats.threads(), stats.reused() ? " (the last cycle's light)" : "");
    for (const std::string& band : bands) {
        text += fmt::format("\n  {}: the plants absorbed {:.6g} W", band, absorbedW[band]);
        for (const v1::EnergyBalance& e : stats.balance()) {
            if (e.band() != band || !(e.incident_w() > 0.0)) continue;
            text += fmt::format(
                " (incident {:.6g} W, escaped {:.6g} W, residual {:.2g} %)", e.incident_w(),
                e.escaped_w(),
                100.0 * (e.incident_w() - e.absorbed_w() - e.escaped_w()) / e.incident_w());
        }
    }
    return text;
}

ClientApps AddClientCommand(CLI::App& app, ClientCommand& command) {
    ClientApps apps{};
    apps.client = app.add_subcommand("client", "Talk to a running leafluxd by hand");
    CLI::App& client = *apps.client;
    client.require_subcommand(1);
    client.add_option("--endpoint", command.endpoint, "leafluxd's endpoint");
    client.add_option("--timeout", command.timeoutS,
                      "Seconds to wait for any reply (0: as the next three say)");
    client.add_option("--status-timeout-ms", command.timeouts.statusMs,
                      "Status, close, shutdown: milliseconds to wait for the reply");
    client.add_option("--scene-timeout-ms", command.timeouts.sceneMs,
                      "open, cycle: milliseconds to wait for the reply, plus --per-organ-ms for "
                      "each organ of the scene");
    client.add_option("--per-organ-ms", command.timeouts.perOrganMs, "See --scene-timeout-ms");
    client
        .add_option("--curve-server-key", command.curveServerKeyFile,
                    "File with the daemon's CurveZMQ public key, when it uses one")
        ->check(CLI::ExistingFile);
    apps.open = client.add_subcommand("open", "Open a session from a scene file");
    apps.open->add_option("--scene", command.scene, "Scene file")
        ->required()
        ->check(CLI::ExistingFile);
    apps.open
        ->add_option("--solver", command.solver,
                     "hrc (hierarchical radiosity with clustering, as leaflux solve) or mc "
                     "(Monte Carlo)")
        ->check(CLI::IsMember({"mc", "hrc"}));
    apps.open->add_flag("--strict", command.strict,
                        "Refuse imported files holding geometry that carries no light "
                        "(zero-area faces, zero-length organs, NaN diameters) instead of "
                        "skipping it with a warning");
    apps.open
        ->add_option("--epsilon", command.epsilon,
                     "hrc: link error bound, a fraction of the power reaching the organs")
        ->check(CLI::Range(1e-9, 1.0));
    apps.cycle = client.add_subcommand("cycle", "Send a cycle, with a delta file");
    apps.cycle->add_option("--session", command.session, "Session id")->required();
    apps.cycle->add_option("--number", command.number, "Cycle number")
        ->transform(WholeNumber())
        ->check(CLI::PositiveNumber);
    apps.cycle->add_option("--delta", command.delta, "leaflux.v1.TopologyDelta in text format")
        ->check(CLI::ExistingFile);
    apps.cycle->add_flag("!--no-leaves", command.leaves, "No per-organ results");
    apps.cycle->add_flag("--structures", command.structures, "Per-structure results");
    apps.cycle->add_option(
        "--out", command.out,
        "Write the cycle's light to this CSV file (its folder is made; the Python package's "
        "columns, which leaflux.CycleLight.read_csv reads: cycle,kind,node,name,type,organs,"
        "area_m2,band,irradiance_upper_wm2,irradiance_lower_wm2,absorbed_w,light_vector_x,"
        "light_vector_y,light_vector_z,stderr_upper_wm2,stderr_lower_wm2, then PAR in photons: "
        "photon_irradiance_upper_umol_m2_s,photon_irradiance_lower_umol_m2_s,absorbed_umol_s, "
        "empty for a band without a photon unit) and print a summary, not the reply");
    apps.status = client.add_subcommand("status", "The daemon's or a session's status");
    apps.status->add_option("--session", command.session, "Session id (empty: the daemon's)");
    apps.close = client.add_subcommand("close", "Close a session");
    apps.close->add_option("--session", command.session, "Session id")->required();
    apps.shutdown = client.add_subcommand("shutdown", "Stop the daemon");
    return apps;
}

int RunClientCommand(const ClientApps& apps, const ClientCommand& command) {
    if (apps.open->parsed()) return RunClient(command, OpenFromFile(command));
    if (apps.cycle->parsed()) return RunClient(command, CycleFromFile(command));
    v1::Request request;
    if (apps.status->parsed()) request.mutable_status()->set_session(command.session);
    if (apps.close->parsed()) request.mutable_close_session()->set_session(command.session);
    if (apps.shutdown->parsed()) request.mutable_shutdown();
    return RunClient(command, request);
}

}  // namespace leaflux
