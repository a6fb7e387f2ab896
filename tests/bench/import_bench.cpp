// Import time of plant files: OBJ, Caribu .can and OPF files of 10⁴, 10⁵ and 10⁶ triangles,
// generated into a temporary directory, and an OPF the size of a measured plant (4,191
// organs). OPF meshes are shared as in AMAPStudio files (a 48-triangle internode cylinder
// and a 20-triangle leaf in meshBDD, placed by each organ's `mat`); its triangle count is
// that of the placed organs. Prints a table and writes CSV.
// Run: build/release/tests/leaflux_bench_import [out.csv, default out/bench/import_bench.csv]
// [largest triangle count, 1e6]
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "solver/io/importers.h"

namespace leaflux {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kCylinderSegments = 24;  // 48 triangles
constexpr int kLeafSegments = 10;      // 20 triangles
constexpr int kPhytomersPerAxis = 50;

// OBJ: leaves of 50 quads (100 triangles), each its own group.
void WriteObj(const std::string& path, long triangles) {
    std::FILE* out = std::fopen(path.c_str(), "w");
    const long organs = triangles / 100;
    long base = 1;
    for (long k = 0; k < organs; ++k) {
        std::fprintf(out, "g leaf%ld\nusemtl green\n", k);
        const double x0 = 0.05 * static_cast<double>(k % 100), y0 = 0.05 * (k / 100 % 100);
        const double z0 = 0.01 * static_cast<double>(k / 10000);
        for (int i = 0; i <= 50; ++i) {
            const double t = i / 50.0;
            const double w = 0.01 * std::sin(kPi * t) + 1e-3;
            std::fprintf(out, "v %.6f %.6f %.6f\nv %.6f %.6f %.6f\n", x0 + 0.04 * t, y0 - w,
                         z0 + 0.005 * t, x0 + 0.04 * t, y0 + w, z0 + 0.005 * t);
        }
        for (int i = 0; i < 50; ++i) {
            const long a = base + 2 * i;
            std::fprintf(out, "f %ld %ld %ld %ld\n", a, a + 2, a + 3, a + 1);
        }
        base += 102;
    }
    std::fclose(out);
}

// .can: one triangle a line, organs of 100 triangles, 999 organs a plant.
void WriteCan(const std::string& path, long triangles) {
    std::FILE* out = std::fopen(path.c_str(), "w");
    for (long t = 0; t < triangles; ++t) {
        const long organ = t / 100;
        const long plant = 1 + organ / 999, leaf = 1 + organ % 999, polygon = t % 100;
        const double x =
            0.05 * static_cast<double>(organ % 100) + 4e-4 * static_cast<double>(polygon);
        const double y = 0.05 * static_cast<double>(organ / 100 % 100);
        const double z = 0.01 * static_cast<double>(organ / 10000);
        std::fprintf(out, "p 1 1%05ld%03ld%03ld 3 %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f\n",
                     plant, leaf, polygon, x, y, z, x + 4e-4, y, z, x, y + 0.01, z + 1e-3);
    }
    std::fclose(out);
}

void WriteOpfMesh(std::FILE* out, int id, const std::vector<double>& xyz,
                  const std::vector<int>& faces) {
    std::fprintf(
        out, "\t\t<mesh name=\"\" shape=\"\" Id=\"%d\" enableScale=\"true\">\n\t\t\t<points>", id);
    for (std::size_t i = 0; i < xyz.size(); ++i)
        std::fprintf(out, "%s%.7g", i % 12 == 0 ? "\n\t\t\t\t" : " ", xyz[i]);
    std::fprintf(out, "\n\t\t\t</points>\n\t\t\t<faces>\n");
    for (std::size_t f = 0; f < faces.size(); f += 3) {
        std::fprintf(out, "\t\t\t\t<face Id=\"%zu\">\n\t\t\t\t\t%d %d %d\n\t\t\t\t</face>\n", f / 3,
                     faces[f], faces[f + 1], faces[f + 2]);
    }
    std::fprintf(out, "\t\t\t</faces>\n\t\t</mesh>\n");
}

// One organ's node: rows of [R·S | t] in centimetres, as AMAPStudio writes them.
void WriteOpfOrgan(std::FILE* out, const char* element, const char* opfClass, long id, int shape,
                   const double (&m)[12], double lengthM, double widthM, int depth,
                   bool nanDiameter = false) {
    const std::string tab(static_cast<std::size_t>(depth), '\t');
    std::fprintf(out, "%s<%s class=\"%s\" scale=\"3\" id=\"%ld\">\n", tab.c_str(), element,
                 opfClass, id);
    std::fprintf(out, "%s\t<Length>%.7g</Length>\n%s\t<Width>%.7g</Width>\n", tab.c_str(), lengthM,
                 tab.c_str(), widthM);
    std::fprintf(out, "%s\t<geometry class=\"Mesh\">\n%s\t\t<shapeIndex>%d</shapeIndex>\n",
                 tab.c_str(), tab.c_str(), shape);
    std::fprintf(out, "%s\t\t<mat>\n", tab.c_str());
    for (int r = 0; r < 3; ++r) {
        std::fprintf(out, "%s\t\t\t%.7g %.7g %.7g %.7g\n", tab.c_str(), m[4 * r], m[4 * r + 1],
                     m[4 * r + 2], m[4 * r + 3]);
    }
    char diameter[32] = "NaN";
    if (!nanDiameter) std::snprintf(diameter, sizeof diameter, "%.7g", 100 * widthM);
    std::fprintf(out, "%s\t\t</mat>\n%s\t\t<dUp>%s</dUp>\n%s\t\t<dDwn>%s</dDwn>\n", tab.c_str(),
                 tab.c_str(), diameter, tab.c_str(), diameter);
    std::fprintf(out, "%s\t</geometry>\n", tab.c_str());
}

// Axes of 50 phytomers (an internode followed by the next, a leaf in branch) radiating
// from the plant's base; `phytomers` in all. With `zeroLengthEvery` = k, every k-th
// internode has zero length (a singular `mat`) and NaN diameters, as measured plants do.
void WriteOpf(const std::string& path, long phytomers, long zeroLengthEvery = 0) {
    std::FILE* out = std::fopen(path.c_str(), "w");
    std::fprintf(out,
                 "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<opf version=\"2.0\" "
                 "editable=\"true\">\n\t<meshBDD>\n");
    std::vector<double> xyz;
    std::vector<int> faces;
    for (int end = 0; end < 2; ++end) {  // a unit cylinder along x, radius 0.5
        for (int s = 0; s < kCylinderSegments; ++s) {
            const double a = 2 * kPi * s / kCylinderSegments;
            xyz.insert(xyz.end(), {double(end), 0.5 * std::cos(a), 0.5 * std::sin(a)});
        }
    }
    for (int s = 0; s < kCylinderSegments; ++s) {
        const int n = (s + 1) % kCylinderSegments;
        faces.insert(faces.end(), {s, n, kCylinderSegments + n, s, kCylinderSegments + n,
                                   kCylinderSegments + s});
    }
    WriteOpfMesh(out, 0, xyz, faces);
    xyz.clear(), faces.clear();
    for (int i = 0; i <= kLeafSegments; ++i) {  // a unit leaf along x in the xy plane
        const double t = double(i) / kLeafSegments, w = 0.5 * std::sin(kPi * t) + 0.01;
        xyz.insert(xyz.end(), {t, -w, 0.0, t, w, 0.0});
    }
    for (int i = 0; i < kLeafSegments; ++i) {
        faces.insert(faces.end(), {2 * i, 2 * i + 2, 2 * i + 3, 2 * i, 2 * i + 3, 2 * i + 1});
    }
    WriteOpfMesh(out, 1, xyz, faces);
    std::fprintf(out,
                 "\t</meshBDD>\n\t<materialBDD>\n\t\t<material Id=\"0\">\n\t\t\t<diffuse>0.5 0.38 "
                 "0.24 1.0</diffuse>\n\t\t</material>\n\t\t<material Id=\"1\">\n\t\t\t<diffuse>0.0 "
                 "0.53 0.24 1.0</diffuse>\n\t\t</material>\n\t</materialBDD>\n\t<shapeBDD>\n"
                 "\t\t<shape Id=\"0\"><meshIndex>0</meshIndex><materialIndex>0</materialIndex>"
                 "</shape>\n\t\t<shape Id=\"1\"><meshIndex>1</meshIndex><materialIndex>1"
                 "</materialIndex></shape>\n\t</shapeBDD>\n\t<attributeBDD>\n\t\t<attribute "
                 "name=\"Length\" class=\"Metre_100\" />\n\t\t<attribute name=\"Width\" "
                 "class=\"Metre_100\" />\n\t</attributeBDD>\n");
    std::fprintf(out,
                 "\t<topology class=\"Scene\" scale=\"0\" id=\"1\">\n\t\t<decomp "
                 "class=\"Individual\" scale=\"1\" id=\"2\">\n");
    long id = 3;
    const long axes = (phytomers + kPhytomersPerAxis - 1) / kPhytomersPerAxis;
    for (long a = 0; a < axes; ++a) {
        std::fprintf(out, "\t\t\t<decomp class=\"Axis\" scale=\"2\" id=\"%ld\">\n", id++);
        const double azimuth = 2.39996 * static_cast<double>(a);  // golden angle
        const double tilt = 0.3 + 0.5 * static_cast<double>(a % 7) / 7.0;
        const glm::dvec3 along(std::sin(tilt) * std::cos(azimuth),
                               std::sin(tilt) * std::sin(azimuth), std::cos(tilt));
        const glm::dvec3 side = glm::normalize(glm::cross(glm::dvec3(0, 0, 1), along));
        const glm::dvec3 third = glm::cross(along, side);
        const long count = std::min<long>(kPhytomersPerAxis, phytomers - a * kPhytomersPerAxis);
        int depth = 4;
        for (long p = 0; p < count; ++p) {
            const bool zero = zeroLengthEvery > 0 && (p + 1) % zeroLengthEvery == 0;
            const double lengthCm = zero ? 0.0 : 2.0 + 0.01 * static_cast<double>(p % 13);
            const double diameterCm = 0.5;
            const glm::dvec3 base = 2.0 * static_cast<double>(p) * along;
            const double internode[12] = {
                lengthCm * along.x, diameterCm * side.x, diameterCm * third.x, base.x,
                lengthCm * along.y, diameterCm * side.y, diameterCm * third.y, base.y,
                lengthCm * along.z, diameterCm * side.z, diameterCm * third.z, base.z};
            WriteOpfOrgan(out, p == 0 ? "decomp" : "follow", "Internode", id++, 0, internode,
                          lengthCm / 100, diameterCm / 100, depth, zero);
            const double turn = 2.39996 * static_cast<double>(p);
            const glm::dvec3 out1 = std::cos(turn) * side + std::sin(turn) * third;
            const glm::dvec3 leafAxis = glm::normalize(out1 + 0.3 * along);
            const glm::dvec3 leafSide = glm::normalize(glm::cross(along, leafAxis));
            const glm::dvec3 top = base + lengthCm * along;
            const double leafCm = 8.0, leafWidthCm = 3.0;
            const double leaf[12] = {leafCm * leafAxis.x, leafWidthCm * leafSide.x, along.x, top.x,
                                     leafCm * leafAxis.y, leafWidthCm * leafSide.y, along.y, top.y,
                                     leafCm * leafAxis.z, leafWidthCm * leafSide.z, along.z, top.z};
            WriteOpfOrgan(out, "branch", "Leaf", id++, 1, leaf, leafCm / 100, leafWidthCm / 100,
                          depth + 1);
            std::fprintf(out, "%s</branch>\n", std::string(depth + 1, '\t').c_str());
            ++depth;  // the next internode follows inside this one
        }
        for (long p = count; p-- > 0;) {
            std::fprintf(out, "%s</%s>\n", std::string(--depth, '\t').c_str(),
                         p == 0 ? "decomp" : "follow");
        }
        std::fprintf(out, "\t\t\t</decomp>\n");
    }
    std::fprintf(out, "\t\t</decomp>\n\t</topology>\n</opf>\n");
    std::fclose(out);
}

long Triangles(const ImportedGeometry& g) {
    long count = 0;
    for (const Node& node : g.nodes)
        count += node.organ() ? static_cast<long>(node.organ()->mesh->triangles.size()) : 0;
    for (const Surface& s : g.environment) count += static_cast<long>(s.mesh->triangles.size());
    return count;
}

struct Row {
    std::string format;
    long triangles, organs, skipped;
    double megabytes, seconds, cpuSeconds;
};

template <typename Read>
Row Measure(const std::string& format, const std::string& path, Read read) {
    const int repeats = std::filesystem::file_size(path) < 20'000'000 ? 3 : 1;
    double best = 1e300, bestCpu = 1e300;
    ImportedGeometry g;
    for (int r = 0; r < repeats; ++r) {
        const auto start = std::chrono::steady_clock::now();
        const std::clock_t cpuStart = std::clock();
        g = read(path);
        bestCpu = std::min(bestCpu, static_cast<double>(std::clock() - cpuStart) / CLOCKS_PER_SEC);
        best = std::min(
            best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    long organs = 0;
    for (const Node& node : g.nodes) organs += node.organ().has_value();
    return {format,
            Triangles(g),
            organs,
            static_cast<long>(g.skipped.size()),
            static_cast<double>(std::filesystem::file_size(path)) / 1e6,
            best,
            bestCpu};
}

}  // namespace
}  // namespace leaflux

int main(int argc, char** argv) {
    using namespace leaflux;
    const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                      ("leaflux_import_bench_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::vector<Row> rows;
    spdlog::set_level(spdlog::level::err);  // the skipped geometry's warnings, on every read
    // The measured plant of the OPF report: 4,191 organs; then with a zero-length internode
    // (NaN diameters) in 25.
    const std::string plant = (dir / "plant.opf").string();
    WriteOpf(plant, 4191 / 2);
    rows.push_back(Measure("opf-plant", plant, [](const std::string& p) { return ReadOpf(p); }));
    WriteOpf(plant, 4191 / 2, 25);
    rows.push_back(Measure("opf-plant-z", plant, [](const std::string& p) { return ReadOpf(p); }));
    const long largest = argc > 2 ? std::atol(argv[2]) : 1'000'000L;
    for (long triangles : {10'000L, 100'000L, 1'000'000L}) {
        if (triangles > largest) break;
        const std::string n = std::to_string(triangles);
        const std::string obj = (dir / ("t" + n + ".obj")).string();
        const std::string can = (dir / ("t" + n + ".can")).string();
        const std::string opf = (dir / ("t" + n + ".opf")).string();
        WriteObj(obj, triangles);
        WriteCan(can, triangles);
        WriteOpf(opf, triangles / 68);  // 48 + 20 triangles a phytomer
        rows.push_back(Measure("obj", obj, [](const std::string& p) { return ReadObj(p); }));
        rows.push_back(Measure("can", can, [](const std::string& p) { return ReadCan(p); }));
        rows.push_back(Measure("opf", opf, [](const std::string& p) { return ReadOpf(p); }));
        std::filesystem::remove(obj), std::filesystem::remove(can), std::filesystem::remove(opf);
    }
    std::filesystem::remove_all(dir);

    const char* path = argc > 1 ? argv[1] : "out/bench/import_bench.csv";
    if (const auto folder = std::filesystem::path(path).parent_path(); !folder.empty())
        std::filesystem::create_directories(folder);  // out/ from the checkout root
    std::ofstream csv(path);
    csv << "format,triangles,organs,skipped,file_mb,read_s,cpu_s,mb_per_s,mtriangles_per_s\n";
    std::printf("%-12s %10s %8s %8s %9s %9s %9s %8s %10s\n", "format", "triangles", "organs",
                "skipped", "file_MB", "read_s", "cpu_s", "MB/s", "Mtri/s");
    for (const Row& r : rows) {
        const double mbps = r.megabytes / r.seconds;
        const double mtps = static_cast<double>(r.triangles) / r.seconds / 1e6;
        csv << r.format << ',' << r.triangles << ',' << r.organs << ',' << r.skipped << ','
            << r.megabytes << ',' << r.seconds << ',' << r.cpuSeconds << ',' << mbps << ',' << mtps
            << '\n';
        std::printf("%-12s %10ld %8ld %8ld %9.2f %9.4f %9.4f %8.1f %10.2f\n", r.format.c_str(),
                    r.triangles, r.organs, r.skipped, r.megabytes, r.seconds, r.cpuSeconds, mbps,
                    mtps);
    }
    std::printf(
        "opf-plant-z: the plant with every 25th internode of zero length, NaN diameters\n"
        "opf: triangles placed by organs sharing a 48- and a 20-triangle mesh\nCSV: %s\n",
        path);
    return 0;
}
