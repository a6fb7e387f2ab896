#include "solver/results/export.h"

#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "solver/scene/light_units.h"

namespace leaflux {
std::string Number(double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.9g", value);
    return buffer;
}

std::string CsvQuoted(const std::string& text) {
    if (text.find_first_of(",\"\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
}

namespace {

// `photons`: the band's µmol per J (solver/scene/light_units.h); none leaves the photon
// columns empty.
// `error`: its standard errors, if the solver gave them.
void WriteLight(std::ostream& out, const BandLight& light, const BandError* error,
                std::optional<double> photons) {
    const glm::dvec3 v = light.LightVector();
    // NaN: not solved (a structure solved whole), an empty cell.
    const auto irradiance = [](double value) { return std::isnan(value) ? "" : Number(value); };
    out << irradiance(light.irradianceUpperWm2) << ',' << irradiance(light.irradianceLowerWm2)
        << ',' << Number(light.absorbedW) << ',' << Number(v.x) << ',' << Number(v.y) << ','
        << Number(v.z) << ',';
    if (error != nullptr) {
        out << Number(error->upperWm2) << ',' << Number(error->lowerWm2);
    } else {
        out << ',';
    }
    out << ',';
    if (photons) {
        out << irradiance(*photons * light.irradianceUpperWm2) << ','
            << irradiance(*photons * light.irradianceLowerWm2) << ','
            << Number(*photons * light.absorbedW);
    } else {
        out << ",,";
    }
    out << '\n';
}

// The photon columns follow the W columns, so that readers by position keep theirs.
constexpr const char* kLightColumns =
    "irradiance_upper_wm2,irradiance_lower_wm2,absorbed_w,light_x,light_y,light_z,"
    "stderr_upper_wm2,stderr_lower_wm2,photon_irradiance_upper_umol_m2_s,"
    "photon_irradiance_lower_umol_m2_s,absorbed_umol_s\n";

}  // namespace

void WriteLeafCsvHeader(std::ostream& out) { out << "organ,band,area_m2," << kLightColumns; }

void WriteLeafRows(std::ostream& out, const Scene& scene, const Receiver& receiver,
                   std::span<const BandLight> light, std::span<const BandError> error) {
    const std::string name = CsvQuoted(ReceiverName(scene, receiver));
    for (std::size_t b = 0; b < scene.bands.size(); ++b) {
        out << name << ',' << CsvQuoted(scene.bands[b].name) << ',' << Number(receiver.areaM2)
            << ',';
        WriteLight(out, light[b], error.empty() ? nullptr : &error[b],
                   PhotonUmolPerJ(scene.bands[b]));
    }
}

void WriteLeafCsv(std::ostream& out, const Scene& scene, const FlatScene& flat,
                  const Solution& solution) {
    WriteLeafCsvHeader(out);
    for (std::size_t r = 0; r < flat.receivers.size(); ++r) {
        if (!solution.unsolved.empty() && solution.unsolved[r]) continue;
        WriteLeafRows(out, scene, flat.receivers[r], solution.light[r], solution.ErrorOf(r));
    }
}

void WriteStructureCsv(std::ostream& out, const Scene& scene,
                       const std::vector<StructureLight>& structures) {
    out << "node,name,type,organs,band,area_m2," << kLightColumns;
    for (const StructureLight& s : structures) {
        for (std::size_t b = 0; b < scene.bands.size(); ++b) {
            out << s.node << ',' << CsvQuoted(s.name) << ',' << NodeTypeName(s.type) << ','
                << s.organCount << ',' << CsvQuoted(scene.bands[b].name) << ',' << Number(s.areaM2)
                << ',';
            WriteLight(out, s.bands[b], s.errors.empty() ? nullptr : &s.errors[b],
                       PhotonUmolPerJ(scene.bands[b]));
        }
    }
}

void WritePly(std::ostream& out, const FlatScene& flat, const Solution& solution, int band) {
    out << "ply\nformat ascii 1.0\ncomment leaflux light, band " << band << "\n"
        << "element vertex " << 3 * flat.triangles.size() << "\n"
        << "property double x\nproperty double y\nproperty double z\n"
        << "element face " << flat.triangles.size() << "\n"
        << "property list uchar int vertex_indices\nproperty float irradiance_upper\n"
        << "property float irradiance_lower\nproperty int receiver\nend_header\n";
    for (const Triangle& t : flat.triangles) {
        for (const glm::dvec3& p : {t.a, t.b, t.c}) {
            const glm::dvec3 world = p + flat.origin;
            out << Number(world.x) << ' ' << Number(world.y) << ' ' << Number(world.z) << '\n';
        }
    }
    for (std::size_t i = 0; i < flat.triangles.size(); ++i) {
        const BandLight& light = solution.light[flat.triangles[i].receiver][band];
        out << "3 " << 3 * i << ' ' << 3 * i + 1 << ' ' << 3 * i + 2 << ' '
            << Number(light.irradianceUpperWm2) << ' ' << Number(light.irradianceLowerWm2) << ' '
            << flat.triangles[i].receiver << '\n';
    }
}

std::string Summary(const std::string& solver, const Scene& scene, const FlatScene& flat,
                    const Solution& solution) {
    std::ostringstream text;
    const SolveStats& stats = solution.stats;
    text << solver << ": " << flat.receivers.size() << " receivers x " << scene.bands.size()
         << " bands in " << Number(stats.wallSeconds) << " s (cpu " << Number(stats.cpuSeconds)
         << " s, " << stats.threads << " threads), peak " << stats.peakRssBytes / (1 << 20)
         << " MiB";
    if (stats.loadedRssBytes > 0 && stats.solvingPeakRssBytes > 0) {
        text << " (" << stats.loadedRssBytes / (1 << 20) << " MiB with the scene loaded, "
             << stats.solvingPeakRssBytes / (1 << 20) << " MiB at most while solving)";
    }
    text << ", " << stats.rays << " rays";
    if (stats.links > 0) {
        text << ", " << stats.links << " links, " << stats.elements << " elements, "
             << stats.refinementDepth << " levels, " << stats.iterations << " iterations, residual "
             << Number(stats.residual);
        if (stats.warmOrgans > 0) text << " (" << stats.warmOrgans << " organs warm-started)";
    }
    for (std::size_t b = 0; b < solution.balance.size(); ++b) {
        const EnergyBalance& e = solution.balance[b];
        text << "; " << scene.bands[b].name << ": incident " << Number(e.incidentW)
             << " W, absorbed " << Number(e.absorbedW) << " W";
        if (const auto photons = PhotonUmolPerJ(scene.bands[b])) {
            text << " (" << Number(*photons * e.absorbedW) << " umol/s)";
        }
        text << ", escaped " << Number(e.escapedW) << " W, residual "
             << Number(100.0 * e.RelativeResidual()) << " %";
        if (e.stderrW >= 0.0 && e.incidentW > 0.0) {
            text << " +- " << Number(100.0 * e.stderrW / e.incidentW) << " %";
        }
    }
    return text.str();
}

}  // namespace leaflux
