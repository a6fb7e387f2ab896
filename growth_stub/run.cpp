#include "growth_stub/run.h"

#include <google/protobuf/text_format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <unordered_map>

#include "server/text_format.h"

namespace leaflux::grow {
namespace {

// The session's scene: the scenario's (bands, optics, environment, sources), the model's
// shared meshes and room, and the given nodes.
v1::Scene SessionScene(const Scenario& scenario, const GrowthModel& model,
                       const std::map<NodeId, v1::Node>& nodes) {
    v1::Scene scene = scenario.scene();
    scene.set_version(leaflux::v1::PROTOCOL_VERSION_CURRENT);
    for (const auto& [name, mesh] : GrowthModel::Meshes()) (*scene.mutable_meshes())[name] = mesh;
    for (const v1::Surface& surface : model.Environment()) *scene.add_environment() = surface;
    for (const auto& [id, node] : nodes) *scene.add_nodes() = node;
    return scene;
}

const v1::BandLight* BandOf(const google::protobuf::RepeatedPtrField<v1::BandLight>& bands,
                            const std::string& band) {
    for (const v1::BandLight& b : bands) {
        if (b.band() == band) return &b;
    }
    return nullptr;
}

LeafLight FromBand(const v1::BandLight& b) {
    return {b.absorbed_w(),
            b.irradiance_upper_wm2() + b.irradiance_lower_wm2(),
            {b.light_vector().x(), b.light_vector().y(), b.light_vector().z()}};
}

// The PAR of every leaf: its own, or with branch-level light its axis's mean irradiance
// and light vector, and its axis's absorbed power per m² times its area (stems included:
// a coarser answer, for models that only need it). An axis the instanced solver solved
// whole has no irradiance of its own (NaN): its leaves' is then what they absorb over
// `leafAbsorptance`. A leaf whose axis has no light of its own (a shoot too small for the
// policy to instantiate, inside an axis solved whole) takes that of the nearest axis
// bearing it that has.
std::map<NodeId, LeafLight> LeafLightOf(const v1::CycleResult& result, const GrowthModel& model,
                                        const std::string& band, bool branchLight,
                                        double leafAbsorptance) {
    std::unordered_map<NodeId, LeafLight> byNode;
    if (branchLight) {
        for (const v1::StructureLight& s : result.structures()) {
            const v1::BandLight* b = BandOf(s.bands(), band);
            if (s.type() != v1::NODE_TYPE_AXIS || !b || s.area_m2() <= 0.0) continue;
            LeafLight perM2 = FromBand(*b);
            perM2.absorbedW /= s.area_m2();
            if (std::isnan(perM2.irradianceWm2))
                perM2.irradianceWm2 = perM2.absorbedW / std::max(leafAbsorptance, 1e-6);
            byNode[s.node()] = perM2;
        }
    } else {
        for (const v1::OrganLight& organ : result.organs()) {
            if (const v1::BandLight* b = BandOf(organ.bands(), band))
                byNode[organ.node()] = FromBand(*b);
        }
    }
    std::map<NodeId, LeafLight> light;
    for (const GrowthModel::LeafInfo& leaf : model.Leaves()) {
        auto it = byNode.find(branchLight ? leaf.axis : leaf.leaf);
        for (std::size_t a = 1; branchLight && it == byNode.end() && a < leaf.axes.size(); ++a)
            it = byNode.find(leaf.axes[a]);
        if (it == byNode.end()) {
            throw std::runtime_error("cycle " + std::to_string(result.number()) + ": leaf " +
                                     std::to_string(leaf.leaf) + " got no light");
        }
        light[leaf.leaf] = it->second;
        if (branchLight) light[leaf.leaf].absorbedW *= leaf.areaM2;
    }
    return light;
}

// Every plant triangle with the PAR irradiance of its organ (upper, lower), and the
// scene's surfaces and lamps with −1 (drawn grey).
void WritePly(const std::string& path, const Scenario& scenario, const GrowthModel& model,
              const std::map<NodeId, LeafLight>& light, const v1::CycleResult& result) {
    struct Face {
        glm::dvec3 p[3];
        double upper, lower;
    };
    std::unordered_map<NodeId, std::pair<double, double>> organLight;
    for (const v1::OrganLight& organ : result.organs()) {
        if (const v1::BandLight* b = BandOf(organ.bands(), scenario.par_band())) {
            organLight[organ.node()] = {b->irradiance_upper_wm2(), b->irradiance_lower_wm2()};
        }
    }
    std::vector<Face> faces;
    for (const WorldTriangle& t : model.Triangles()) {
        std::pair<double, double> e{-1.0, -1.0};
        if (const auto it = organLight.find(t.organ); it != organLight.end()) {
            e = it->second;
        } else if (const auto leaf = light.find(t.organ); leaf != light.end()) {
            e = {leaf->second.irradianceWm2, 0.0};
        }
        faces.push_back({{t.a, t.b, t.c}, e.first, e.second});
    }
    const auto addMesh = [&](const v1::Mesh& mesh) {
        const auto vertex = [&](std::uint32_t i) {
            return glm::dvec3(mesh.positions(3 * i), mesh.positions(3 * i + 1),
                              mesh.positions(3 * i + 2));
        };
        for (int t = 0; t + 2 < mesh.triangles_size(); t += 3) {
            faces.push_back({{vertex(mesh.triangles(t)), vertex(mesh.triangles(t + 1)),
                              vertex(mesh.triangles(t + 2))},
                             -1.0,
                             -1.0});
        }
    };
    for (const v1::Surface& s : scenario.scene().environment()) addMesh(s.mesh());
    for (const v1::Surface& s : model.Environment()) addMesh(s.mesh());
    for (const v1::Emitter& e : scenario.scene().emitters()) addMesh(e.mesh());

    std::ofstream out(path);
    out << "ply\nformat ascii 1.0\ncomment leaflux-grow: PAR irradiance per face, -1: not a "
           "plant\nelement vertex "
        << 3 * faces.size()
        << "\nproperty double x\nproperty double y\nproperty double z\nelement face "
        << faces.size()
        << "\nproperty list uchar int vertex_indices\nproperty double irradiance_upper\n"
           "property double irradiance_lower\nend_header\n";
    for (const Face& f : faces) {
        for (const glm::dvec3& p : f.p) out << p.x << ' ' << p.y << ' ' << p.z << '\n';
    }
    for (std::size_t i = 0; i < faces.size(); ++i) {
        out << "3 " << 3 * i << ' ' << 3 * i + 1 << ' ' << 3 * i + 2 << ' ' << faces[i].upper << ' '
            << faces[i].lower << '\n';
    }
    if (!out) throw std::runtime_error(path + ": cannot write");
}

// The scene the daemon solved at this cycle (cycle<N>.scene.txtpb) and the light it sent
// back for it (cycle<N>.csv, the columns `leaflux solve --out` begins with), so that
// `leaflux render --scene … --from …` draws the cycle as it was lit.
void WriteCycleScene(const std::string& stem, const v1::Scene& scene,
                     const v1::CycleResult& result) {
    std::string text;
    google::protobuf::TextFormat::PrintToString(scene, &text);
    std::ofstream(stem + ".scene.txtpb") << text;
    std::ofstream csv(stem + ".csv");
    csv.precision(9);
    const auto quoted = [](const std::string& name) {
        if (name.find_first_of(",\"\n") == std::string::npos) return name;
        std::string q = "\"";
        for (char c : name) q += c == '"' ? std::string("\"\"") : std::string(1, c);
        return q + "\"";
    };
    csv << "organ,band,area_m2,irradiance_upper_wm2,irradiance_lower_wm2,absorbed_w\n";
    for (const v1::OrganLight& organ : result.organs()) {
        for (const v1::BandLight& b : organ.bands()) {
            csv << quoted(organ.name()) << ',' << quoted(b.band()) << ',' << organ.area_m2() << ','
                << b.irradiance_upper_wm2() << ',' << b.irradiance_lower_wm2() << ','
                << b.absorbed_w() << '\n';
        }
    }
    if (!csv) throw std::runtime_error(stem + ".csv: cannot write");
}

}  // namespace

Scenario LoadScenario(const std::string& path) {
    Scenario scenario;
    if (const auto error = ReadTextFormat(path, scenario)) {
        throw std::invalid_argument(error->where + ": " + error->what);
    }
    return scenario;
}

std::set<int> CycleList(const std::string& list, const std::string& option) {
    std::set<int> cycles;
    std::size_t begin = 0;
    while (begin < list.size()) {
        const std::size_t end = std::min(list.find(',', begin), list.size());
        const std::string item = list.substr(begin, end - begin);
        std::size_t used = 0;
        long value = 0;
        try {
            value = std::stol(item, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (item.empty() || used != item.size() || value < 1 || value > 1'000'000) {
            throw std::invalid_argument(option + ": '" + item +
                                        "' is not a cycle number; give cycle numbers (1 or " +
                                        "more) separated by commas, such as 2,9,13");
        }
        cycles.insert(static_cast<int>(value));
        begin = end + 1;
    }
    return cycles;
}

// The mean over both sides of what the leaves absorb of the light reaching them, in `band`.
double LeafAbsorptance(const Scenario& scenario, const std::string& band) {
    for (const v1::Optics& optics : scenario.scene().optics()) {
        if (optics.id() != scenario.leaf_optics()) continue;
        const auto it = optics.bands().find(band);
        if (it == optics.bands().end()) break;
        const v1::BandOptics& b = it->second;
        return 1.0 - 0.5 * (b.rho_upper() + b.rho_lower() + b.tau_upper() + b.tau_lower());
    }
    return 1.0;
}

std::vector<CycleRecord> Run(const Scenario& scenario, GrowthModel& model,
                             const RunOptions& options, Client& client) {
    const double absorptance = LeafAbsorptance(scenario, scenario.par_band());
    v1::OpenSession open;
    *open.mutable_scene() = SessionScene(scenario, model, {});
    *open.mutable_settings() = scenario.settings();
    open.set_species(scenario.name());
    const std::string session = client.Open(open);

    std::ofstream cyclesCsv, plantsCsv, phytomersCsv;
    if (!options.outDir.empty()) {
        std::filesystem::create_directories(options.outDir);
        cyclesCsv.open(options.outDir + "/cycles.csv");
        plantsCsv.open(options.outDir + "/plants.csv");
        phytomersCsv.open(options.outDir + "/phytomers.csv");
        cyclesCsv << "cycle,leaves,leaf_area_m2,biomass_g,absorbed_par_w,added,updated,removed,"
                     "solve_s,round_trip_s,daemon_peak_mib,phase_computed,phase_reused,"
                     "phase_compute_s\n";
        plantsCsv << "cycle,plant,leaves,leaf_area_m2,biomass_g,absorbed_par_w,centroid_x,"
                     "centroid_y,centroid_z\n";
        phytomersCsv << "cycle,address,internode_g,leaf_g\n";
    }
    std::vector<CycleRecord> records;
    std::map<NodeId, v1::Node> sent;
    for (int c = 1; c <= options.cycles; ++c) {
        const std::map<NodeId, v1::Node> nodes = model.Nodes();
        v1::Cycle cycle;
        cycle.set_session(session);
        cycle.set_number(c);
        *cycle.mutable_delta() = Diff(sent, nodes);
        cycle.mutable_outputs()->set_leaves(!options.branchLight);
        cycle.mutable_outputs()->set_structures(options.branchLight);
        cycle.mutable_outputs()->add_bands(scenario.par_band());

        const auto start = std::chrono::steady_clock::now();
        // Unanswered in time, or lost by a restarted daemon: the client reconnects, gives
        // the daemon the scene as it was before this cycle, and sends the cycle again.
        const v1::CycleResult result = client.Cycle(cycle, [&] {
            v1::Resync resync;
            resync.set_session(session);
            *resync.mutable_scene() = SessionScene(scenario, model, sent);
            *resync.mutable_settings() = scenario.settings();
            resync.set_last_cycle(c - 1);
            resync.set_species(scenario.name());
            return resync;
        });
        sent = nodes;
        const std::map<NodeId, LeafLight> light =
            LeafLightOf(result, model, scenario.par_band(), options.branchLight, absorptance);

        CycleRecord record;
        record.cycle = c;
        record.added = cycle.delta().added_size();
        record.updated = cycle.delta().updated_size();
        record.removed = cycle.delta().removed_size();
        record.roundTripSeconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        record.solveSeconds = result.statistics().wall_seconds();
        record.daemonPeakMib = result.statistics().peak_rss_bytes() / 1048576.0;
        record.phaseComputed = result.statistics().phase_functions_computed();
        record.phaseReused = result.statistics().phase_functions_reused();
        record.phaseComputeSeconds = result.statistics().phase_compute_seconds();
        // The rows and pictures tell the plants as they were lit; then they grow.
        record.plants = model.Summaries();
        std::map<NodeId, PlantSummary*> byPlant;
        for (PlantSummary& plant : record.plants) byPlant[plant.id] = &plant;
        for (const GrowthModel::LeafInfo& leaf : model.Leaves()) {
            byPlant.at(leaf.plant)->absorbedParW += light.at(leaf.leaf).absorbedW;
        }
        for (const PlantSummary& plant : record.plants) {
            record.leaves += plant.leaves;
            record.leafAreaM2 += plant.leafAreaM2;
            record.biomassG += plant.biomassG;
            record.absorbedParW += plant.absorbedParW;
        }
        if (!options.outDir.empty()) {
            cyclesCsv << c << ',' << record.leaves << ',' << record.leafAreaM2 << ','
                      << record.biomassG << ',' << record.absorbedParW << ',' << record.added << ','
                      << record.updated << ',' << record.removed << ',' << record.solveSeconds
                      << ',' << record.roundTripSeconds << ',' << record.daemonPeakMib << ','
                      << record.phaseComputed << ',' << record.phaseReused << ','
                      << record.phaseComputeSeconds << '\n';
            for (const PlantSummary& plant : record.plants) {
                plantsCsv << c << ',' << plant.id << ',' << plant.leaves << ',' << plant.leafAreaM2
                          << ',' << plant.biomassG << ',' << plant.absorbedParW << ','
                          << plant.leafCentroid.x << ',' << plant.leafCentroid.y << ','
                          << plant.leafCentroid.z << '\n';
            }
            for (const GrowthModel::PhytomerSize& p : model.Phytomers()) {
                phytomersCsv << c << ',' << p.address << ',' << p.internodeG << ',' << p.leafG
                             << '\n';
            }
            if (options.plyCycles.count(c)) {
                const std::string stem = options.outDir + "/cycle" + std::to_string(c);
                WritePly(stem + ".ply", scenario, model, light, result);
                WriteCycleScene(stem, SessionScene(scenario, model, sent), result);
            }
            if (options.pngCycles.count(c)) {
                v1::RenderRequest render = scenario.picture();
                render.set_session(session);
                if (render.band().empty()) render.set_band(scenario.par_band());
                const std::string path = options.outDir + "/cycle" + std::to_string(c) + ".png";
                std::ofstream png(path, std::ios::binary);
                png << client.Render(render).png();
                if (!png) throw std::runtime_error(path + ": cannot write the picture");
            }
        }
        if (!options.quiet) {
            std::printf(
                "cycle %3d: %5d leaves, %7.4f m², %8.3f g, PAR absorbed %8.3f W; "
                "+%d ~%d -%d nodes; solve %.3f s, round trip %.3f s, daemon %.0f MiB\n",
                c, record.leaves, record.leafAreaM2, record.biomassG, record.absorbedParW,
                record.added, record.updated, record.removed, record.solveSeconds,
                record.roundTripSeconds, record.daemonPeakMib);
            std::fflush(stdout);
        }
        model.Grow(light);
        records.push_back(record);
    }
    client.Close(session);
    return records;
}

}  // namespace leaflux::grow
