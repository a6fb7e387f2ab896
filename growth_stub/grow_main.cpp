// leaflux-grow: grows the plants of a scenario for a number of cycles, lit by leafluxd.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <sstream>

#include "growth_stub/run.h"
#include "server/cli_checks.h"
#include "server/text_format.h"

int main(int argc, char** argv) {
    using namespace leaflux;
    CLI::App app{"leaflux-grow: the reference growth model, a client of leafluxd"};
    app.option_defaults()->always_capture_default();  // --help shows every default
    std::string scenarioPath, endpoint = "tcp://127.0.0.1:5555", curveKeyFile, solver, pictures,
                              pngs, policyFile;
    grow::RunOptions options;
    int cycles = 0;
    double epsilon = 0.0, spacing = 0.0, rowAzimuth = -1.0;
    int samples = 0;
    std::int64_t mergeTriangles = -1;
    bool directOnly = false, warmStart = false;
    double statusTimeoutS = 30.0, cycleTimeoutS = 60.0, perOrganMs = 10.0;
    app.add_option("--scenario", scenarioPath, "Scenario file (growth_stub/scenarios/*.txtpb)")
        ->required()
        ->check(CLI::ExistingFile);
    app.add_option("--cycles", cycles, "Growth cycles (0: the scenario's, else 25)")
        ->transform(WholeNumber())
        ->check(CLI::Range(0, 100000));
    app.add_option("--out", options.outDir,
                   "Output folder: cycles.csv, plants.csv, phytomers.csv (organ masses by "
                   "topological address), cycle<N>.ply");
    app.add_option("--ply-cycles", pictures,
                   "Cycles whose PLY, scene and light (cycle<N>.scene.txtpb and cycle<N>.csv, "
                   "for leaflux render --scene ... --from ...) are written into --out, as numbers "
                   "separated by commas, e.g. 2,9,13,17,25");
    app.add_option("--png-cycles", pngs,
                   "Cycles whose picture leafluxd draws into --out as cycle<N>.png, with the "
                   "scenario's picture settings (camera, size, scale: one for every cycle), "
                   "e.g. 2,9,13,17,25");
    app.add_option("--endpoint", endpoint, "leafluxd's address");
    app.add_option("--curve-server-key", curveKeyFile,
                   "File with leafluxd's CurveZMQ public key (when it has one)")
        ->check(CLI::ExistingFile);
    app.add_option("--solver", solver,
                   "Override the scenario's solver: hrc, mc or instanced (hierarchical "
                   "instantiation, its phase functions kept in leafluxd's database; empty: the "
                   "scenario's)")
        ->check(CLI::IsMember({"hrc", "mc", "instanced"}));
    app.add_option("--policy", policyFile,
                   "With --solver instanced: the instantiation policy file to send (protobuf "
                   "text format, leaflux.v1.InstancingPolicy; default: the daemon's for the "
                   "scenario's species, else its built-in one)")
        ->check(CLI::ExistingFile);
    app.add_option("--epsilon", epsilon, "Override the scenario's HRC ε (0: the scenario's)")
        ->check(CLI::Range(0.0, 1.0));
    app.add_option("--samples", samples,
                   "Override the scenario's MC paths per receiver (0: the "
                   "scenario's)")
        ->transform(WholeNumber())
        ->check(CLI::Range(0, 1 << 24));
    app.add_flag("--direct-only", directOnly,
                 "Light straight from the sources only, no scattering (paper Fig. 19)");
    app.add_flag("--warm-start", warmStart,
                 "hrc, instanced: each cycle starts from the light of the last one "
                 "(SolverSettings.warm_start): the same light within a small part of what "
                 "epsilon costs, a few sweeps fewer");
    app.add_option("--merge-triangles", mergeTriangles,
                   "instanced: each opened instance of at most this many organ triangles is "
                   "solved as one problem with the smaller instances it holds "
                   "(InstancedSettings.merge_triangles; -1: the scenario's)")
        ->check(CLI::Range(std::int64_t{-1}, std::int64_t{1} << 40));
    app.add_flag("--branch-light", options.branchLight,
                 "Ask for per-axis light only; each leaf gets its axis's (with --solver "
                 "instanced, instances are opened down to axes only)");
    app.add_option("--spacing", spacing,
                   "Override the stand's spacing within rows (m; 0: the scenario's); "
                   "refused for a scenario without a stand")
        ->check(CLI::NonNegativeNumber);
    app.add_option("--row-azimuth", rowAzimuth,
                   "Override the stand's row direction (deg from +y; -1: the scenario's); "
                   "refused for a scenario without a stand")
        ->check(CLI::Range(-1.0, 360.0));
    app.add_option("--status-timeout", statusTimeoutS,
                   "Seconds to wait for the daemon's answer to a close")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--cycle-timeout", cycleTimeoutS,
                   "Seconds to wait for a cycle's light (and an open's or a resync's answer), "
                   "plus --per-organ-ms for each organ; then the client reconnects, resyncs the "
                   "session and sends the cycle once more")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--per-organ-ms", perOrganMs, "See --cycle-timeout")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_flag("--quiet", options.quiet, "No line per cycle");
    CLI11_PARSE(app, argc, argv);

    try {
        grow::Scenario scenario = grow::LoadScenario(scenarioPath);
        options.cycles = cycles > 0 ? cycles : (scenario.cycles() > 0 ? scenario.cycles() : 25);
        options.plyCycles = grow::CycleList(pictures, "--ply-cycles");
        if (!options.plyCycles.empty() && options.outDir.empty())
            throw std::invalid_argument("--ply-cycles: the pictures need a folder: give --out");
        options.pngCycles = grow::CycleList(pngs, "--png-cycles");
        if (!options.pngCycles.empty()) {
            if (options.outDir.empty())
                throw std::invalid_argument("--png-cycles: the pictures need a folder: give --out");
            if (!scenario.has_picture())
                throw std::invalid_argument("--png-cycles: scenario " + scenario.name() +
                                            " has no picture block (its camera, size and scale)");
            if (options.branchLight)
                throw std::invalid_argument(
                    "--png-cycles: the pictures show each organ's light, which --branch-light "
                    "does not ask for");
        }
        v1::SolverSettings& settings = *scenario.mutable_settings();
        if (solver == "hrc") settings.set_solver(v1::SOLVER_KIND_HRC);
        if (solver == "mc") settings.set_solver(v1::SOLVER_KIND_MONTE_CARLO);
        if (solver == "instanced") settings.set_solver(v1::SOLVER_KIND_INSTANCED);
        const bool instanced = settings.solver() == v1::SOLVER_KIND_INSTANCED;
        if (!policyFile.empty()) {
            if (!instanced)
                throw std::invalid_argument("--policy: only the instanced solver takes a policy");
            if (const auto error = ReadTextFormat(
                    policyFile, *settings.mutable_instanced()->mutable_inline_policy()))
                throw std::invalid_argument(error->where + ": " + error->what);
        }
        if (mergeTriangles >= 0) {
            if (!instanced)
                throw std::invalid_argument("--merge-triangles: only the instanced solver merges");
            if (options.branchLight)
                throw std::invalid_argument(
                    "--merge-triangles: --branch-light keeps the small structures closed");
            settings.mutable_instanced()->set_merge_triangles(mergeTriangles);
        }
        if (instanced && options.branchLight)
            settings.mutable_instanced()->set_output_level(v1::NODE_TYPE_AXIS);
        if (epsilon > 0.0) settings.set_epsilon(epsilon);
        if (samples > 0) settings.set_samples(samples);
        if (directOnly) settings.set_direct_only(true);
        if (warmStart) settings.set_warm_start(true);
        // A stand's options on a scenario that places its plants one by one would be ignored.
        for (const auto& [given, option] : {std::pair{spacing > 0.0, "--spacing"},
                                            std::pair{rowAzimuth >= 0.0, "--row-azimuth"}}) {
            if (given && !scenario.has_stand()) {
                throw std::invalid_argument(
                    std::string(option) + ": scenario " + scenario.name() +
                    " has no stand (it places its plants one by one), so there is nothing "
                    "for " +
                    option + " to change");
            }
        }
        if (spacing > 0.0) scenario.mutable_stand()->set_spacing(spacing);
        if (rowAzimuth >= 0.0) scenario.mutable_stand()->set_row_azimuth_deg(rowAzimuth);

        std::string serverKey;
        if (!curveKeyFile.empty()) {
            const auto key = ReadCurveKey(curveKeyFile);
            if (!key) throw std::invalid_argument(curveKeyFile + ": not a Z85 CurveZMQ public key");
            serverKey = *key;
        }
        spdlog::set_default_logger(spdlog::stderr_color_mt("leaflux-grow"));
        const ClientTimeouts timeouts{static_cast<int>(1000 * statusTimeoutS),
                                      static_cast<int>(1000 * cycleTimeoutS),
                                      static_cast<int>(perOrganMs)};
        Client client(endpoint, serverKey, timeouts);
        grow::GrowthModel model(scenario);
        const auto records = grow::Run(scenario, model, options, client);
        const grow::CycleRecord& last = records.back();
        std::printf("%s: %d cycles, %d leaves, %.4f m² of leaves, %.3f g of biomass\n",
                    scenario.name().c_str(), last.cycle, last.leaves, last.leafAreaM2,
                    last.biomassG);
        return 0;
    } catch (const ClientError& e) {
        std::fprintf(stderr, "leafluxd: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 3;
    }
}
