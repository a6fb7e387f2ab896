#include "server/generate_cli.h"

#include <google/protobuf/text_format.h>
#include <spdlog/fmt/fmt.h>

#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>

#include "server/cli_checks.h"
#include "server/progress.h"
#include "server/scene_proto.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

// Peak resident memory of `leaflux generate` per leaf (`/usr/bin/time -f %M`): a 100,000-leaf
// tree 377 MB, 20 trees of 10,000 leaves 711 MB (3.6–3.8 kB a leaf, its axes, phytomers,
// internodes and text in the file included), a 200,000-leaf random canopy 341 MB (1.7 kB).
// Rounded up, with the program's own.
constexpr double kTreeBytesPerLeaf = 4000.0;
constexpr double kCanopyBytesPerLeaf = 2000.0;
constexpr double kBaseBytes = 64.0 * (1 << 20);

SkyDiscretization SkyDiscretizationNamed(const std::string& name) {
    if (name == "turtle46") return SkyDiscretization::kTurtle46;
    if (name == "tetra34") return SkyDiscretization::kTetra34;
    if (name == "tetra130") return SkyDiscretization::kTetra130;
    if (name == "tetra514") return SkyDiscretization::kTetra514;
    return SkyDiscretization::kContinuous;
}

double Leaves(const GenerateCommand& command) {
    if (command.randomCanopy) return command.canopy.leaves;
    const double grid = static_cast<double>(command.rows) * command.columns;
    const double trees = command.trees > 0 ? std::min<double>(command.trees, grid) : grid;
    return trees * command.tree.leafCount;
}

std::string Gigabytes(double bytes) {
    return bytes < 1e12 ? fmt::format("{:.3g} GB", bytes / 1e9)
                        : fmt::format("{:.3g} TB", bytes / 1e12);
}

// SaveSceneFile's file, written node by node: the scene's other fields first, then each
// node, so that a progress bar can follow (writing takes nine tenths of a large tree's
// time) and the text is never held whole.
void WriteScene(const Scene& scene, const std::string& path, SceneWriting writing,
                const std::function<void(double)>& progress) {
    if (IsBinarySceneFile(path)) {  // one message, written whole
        SaveSceneFile(scene, path, writing);
        if (progress) progress(1.0);
        return;
    }
    v1::Scene message = ToProto(scene, writing);
    google::protobuf::RepeatedPtrField<v1::Node> nodes;
    nodes.Swap(message.mutable_nodes());
    std::ofstream out(path);
    std::string text;
    google::protobuf::TextFormat::PrintToString(message, &text);
    out << text;
    google::protobuf::TextFormat::Printer printer;
    printer.SetInitialIndentLevel(1);
    for (int i = 0; i < nodes.size(); ++i) {
        printer.PrintToString(nodes[i], &text);
        out << "nodes {\n" << text << "}\n";
        if (progress && i % 1024 == 0) progress(static_cast<double>(i) / nodes.size());
    }
    if (progress) progress(1.0);
    if (!out.flush()) throw InputError(ErrorCode::kIo, path, "cannot write the scene file");
}

}  // namespace

double GenerateMemoryEstimate(const GenerateCommand& command) {
    return kBaseBytes +
           Leaves(command) * (command.randomCanopy ? kCanopyBytesPerLeaf : kTreeBytesPerLeaf);
}

CLI::App* AddGenerateCommand(CLI::App& app, GenerateCommand& command) {
    CLI::App* generate = app.add_subcommand(
        "generate",
        "Write a procedural poplar-like tree, a plantation, a random canopy or a "
        "greenhouse as a scene file");
    // The kinds of scene, and the options each one reads: any other is refused.
    CLI::Option* canopy =
        generate->add_flag("--random-canopy", command.randomCanopy,
                           "A random canopy of square leaves (spherical angles) instead of trees");
    CLI::Option* greenhouse = generate->add_flag(
        "--greenhouse", command.greenhouse,
        "A greenhouse at night instead: the rows of trees (small plants, see --leaves, "
        "--leaf-length, --spacing) on a white floor, white walls, no roof, a bar of lamps "
        "2.4 m above each row; no sun, no sky");
    canopy->excludes(greenhouse);
    const auto trees = [&](CLI::Option* option) { return option->excludes(canopy); };
    const auto canopyOnly = [&](CLI::Option* option) { return option->needs(canopy); };
    const auto outdoors = [&](CLI::Option* option) { return option->excludes(greenhouse); };

    trees(generate->add_option("--leaves", command.tree.leafCount, "Leaves per tree")
              ->transform(WholeNumber())
              ->check(CLI::Range(1, 10'000'000)));
    generate->add_option("--seed", command.tree.seed, "Random seed")->transform(WholeNumber());
    trees(generate->add_option("--leaf-length", command.tree.leafLengthM, "Mean leaf length (m)")
              ->check(CLI::PositiveNumber));
    trees(generate->add_option("--rows", command.rows, "Rows of trees")
              ->transform(WholeNumber())
              ->check(CLI::Range(1, 1000)));
    trees(generate->add_option("--columns", command.columns, "Trees per row")
              ->transform(WholeNumber())
              ->check(CLI::Range(1, 1000)));
    trees(generate
              ->add_option("--trees", command.trees,
                           "Only this many trees of the rows x columns grid, row by row (0: all)")
              ->transform(WholeNumber())
              ->check(CLI::Range(0, 1'000'000)));
    trees(generate->add_option("--spacing", command.spacing, "Distance between trees (m)")
              ->check(CLI::PositiveNumber));
    trees(generate
              ->add_option("--row-spacing", command.rowSpacing,
                           "Distance between rows (m; 0: --spacing, the distance along a row)")
              ->check(CLI::NonNegativeNumber));
    trees(generate->add_option("--row-azimuth", command.rowAzimuth,
                               "Row direction from north, clockwise (deg)"));
    outdoors(generate->add_option("--sun-elevation", command.sunElevation, "Sun elevation (deg)")
                 ->check(CLI::Range(0.0, 90.0)));
    outdoors(generate->add_option("--sun-azimuth", command.sunAzimuth,
                                  "Sun azimuth from north, clockwise (deg)"));
    outdoors(generate
                 ->add_option("--sun-par", command.sunPar,
                              "Sun: normal irradiance, PAR (W/m²; µmol m⁻² s⁻¹ / 4.57)")
                 ->check(CLI::NonNegativeNumber));
    outdoors(generate->add_option("--sun-nir", command.sunNir, "Sun: normal irradiance, NIR (W/m²)")
                 ->check(CLI::NonNegativeNumber));
    CLI::Option* noSky =
        outdoors(generate->add_flag("--no-sky", command.noSky, "Sun only, no diffuse sky"));
    outdoors(generate
                 ->add_option("--sky-par", command.skyPar,
                              "Sky: diffuse irradiance on a horizontal plane, PAR (W/m²)")
                 ->check(CLI::NonNegativeNumber))
        ->excludes(noSky);
    outdoors(generate
                 ->add_option("--sky-nir", command.skyNir,
                              "Sky: diffuse irradiance on a horizontal plane, NIR (W/m²)")
                 ->check(CLI::NonNegativeNumber))
        ->excludes(noSky);
    outdoors(
        generate
            ->add_option("--sky-cones", command.skyCones,
                         "Sky as continuous radiance or as cones (every solver then sees "
                         "the same cones)")
            ->check(CLI::IsMember({"continuous", "turtle46", "tetra34", "tetra130", "tetra514"})))
        ->excludes(noSky);
    trees(outdoors(generate->add_flag(
        "--no-ground", command.noGround,
        "Trees without the ground under them (as a growth model sends a plant)")));
    generate->add_option("--lamp-par", command.lampPar, "Greenhouse: lamp exitance, PAR (W/m²)")
        ->check(CLI::NonNegativeNumber)
        ->needs(greenhouse);
    generate->add_option("--lamp-nir", command.lampNir, "Greenhouse: lamp exitance, NIR (W/m²)")
        ->check(CLI::NonNegativeNumber)
        ->needs(greenhouse);
    canopyOnly(
        generate->add_option("--canopy-leaves", command.canopy.leaves, "Random canopy: leaves")
            ->transform(WholeNumber())
            ->check(CLI::Range(1, 10'000'000)));
    canopyOnly(
        generate
            ->add_option("--lai", command.canopy.leafAreaIndex, "Random canopy: leaf area index")
            ->check(CLI::PositiveNumber));
    canopyOnly(generate
                   ->add_option("--canopy-width", command.canopy.widthM,
                                "Random canopy: side of its square (m)")
                   ->check(CLI::PositiveNumber));
    trees(generate->add_flag("!--internodes", command.tree.internodes,
                             "No internode geometry (leaves only)"));
    CLI::Option* copies = trees(generate->add_flag(
        "--copies", command.tree.copies,
        "Exact self-similarity: the lateral axes of one order and leaf count are copies of one "
        "prototype (the same organs in the axis's frame), and the trees copies of "
        "--prototypes trees, each turned about z; for instancing tests, and with --instanced "
        "for files that grow with the placements, not the polygons"));
    generate
        ->add_option("--prototypes", command.prototypes,
                     "With --copies: prototype trees of a plantation (tree i is a copy of "
                     "prototype i mod N)")
        ->transform(WholeNumber())
        ->check(CLI::Range(1, 1'000'000))
        ->needs(copies);
    generate->add_flag(
        "--instanced", command.instanced,
        "Write subtrees that are exact copies once, as shared structures placed by a frame and "
        "an id offset (Scene.structures, Scene.placements); leaflux solve reads the same scene "
        "as from the flat file");
    generate->add_flag(
        "--colour-bands", command.colourBands,
        "Also bands B (400–500 nm), G (500–600) and R (600–700): the PAR sun, sky or lamps "
        "split over them, green-leaf, bark and soil optics, for leaflux render --quantity colour");
    generate->add_flag("--quiet", command.quiet, "No progress bar");
    generate
        ->add_option("--out", command.out,
                     "Scene file to write (its folder is made): protobuf text format, or binary if "
                     "its name ends in .binpb (read faster)")
        ->required();
    return generate;
}

namespace {

// Bands B, G and R beside PAR and NIR: each optics' (ρ, τ) in them, and the share of the
// PAR source each takes. Leaves: a fresh green leaf's mean reflectance and transmittance
// over each band (as PROSPECT gives them); bark and soil redder; walls and floor grey.
// The sun's PAR splits as the clear-sky spectrum at the ground does, the sky's bluer, a
// horticultural lamp's mostly red and blue.
struct ColourBand {
    Band band;
    double sun, sky, lamp;
};
const ColourBand kColourBands[] = {{{"B", 400, 500}, 0.31, 0.40, 0.30},
                                   {{"G", 500, 600}, 0.35, 0.33, 0.10},
                                   {{"R", 600, 700}, 0.34, 0.27, 0.60}};
const std::map<std::string, std::array<BandOptics, 3>> kColourOptics = {
    {"leaf", {{{0.05, 0.05, 0.01, 0.01}, {0.15, 0.15, 0.10, 0.10}, {0.06, 0.06, 0.04, 0.04}}}},
    {"stem", {{{0.06, 0.06, 0.0, 0.0}, {0.10, 0.10, 0.0, 0.0}, {0.16, 0.16, 0.0, 0.0}}}},
    {"ground", {{{0.08, 0.08, 0.0, 0.0}, {0.11, 0.11, 0.0, 0.0}, {0.15, 0.15, 0.0, 0.0}}}},
    {"wall", {{{0.80, 0.80, 0.0, 0.0}, {0.80, 0.80, 0.0, 0.0}, {0.80, 0.80, 0.0, 0.0}}}},
    {"floor", {{{0.60, 0.60, 0.0, 0.0}, {0.60, 0.60, 0.0, 0.0}, {0.60, 0.60, 0.0, 0.0}}}}};

// `values` (PAR, NIR) with the colour bands' shares of the PAR one appended.
std::vector<double> WithColour(std::vector<double> values, double ColourBand::*share) {
    const double par = values[0];
    for (const ColourBand& c : kColourBands) values.push_back(par * c.*share);
    return values;
}

}  // namespace

// PAR- and NIR-like optics (leaf ρ, τ), a sun and a CIE overcast sky: a scene ready to solve.
int RunGenerate(const GenerateCommand& command, std::uint64_t availableBytes) {
    const double needed = GenerateMemoryEstimate(command);
    if (availableBytes > 0 && needed > static_cast<double>(availableBytes)) {
        throw InputError(
            ErrorCode::kInvalidArgument, command.randomCanopy ? "--canopy-leaves" : "--leaves",
            fmt::format("{:.4g} leaves need about {} of memory to build and write ({:.3g} kB a "
                        "leaf), and this machine has {} available: give fewer leaves or trees",
                        Leaves(command), Gigabytes(needed),
                        (command.randomCanopy ? kCanopyBytesPerLeaf : kTreeBytesPerLeaf) / 1e3,
                        Gigabytes(static_cast<double>(availableBytes))));
    }
    CheckWritable(command.out, "--out");
    const auto start = std::chrono::steady_clock::now();
    Scene scene;
    scene.bands = {{"PAR", 400, 700}, {"NIR", 700, 2500}};
    scene.optics = {{"leaf", {{0.10, 0.10, 0.05, 0.05}, {0.45, 0.45, 0.45, 0.45}}},
                    {"stem", {{0.10, 0.10, 0.0, 0.0}, {0.40, 0.40, 0.0, 0.0}}},
                    {"ground", {{0.10, 0.10, 0.0, 0.0}, {0.30, 0.30, 0.0, 0.0}}}};
    if (command.greenhouse) {
        scene.optics.push_back({"wall", {{0.80, 0.80, 0.0, 0.0}, {0.85, 0.85, 0.0, 0.0}}});
        scene.optics.push_back({"floor", {{0.60, 0.60, 0.0, 0.0}, {0.70, 0.70, 0.0, 0.0}}});
    }
    const auto bands = [&](std::vector<double> values, double ColourBand::*share) {
        return command.colourBands ? WithColour(std::move(values), share) : values;
    };
    if (command.colourBands) {
        for (const ColourBand& c : kColourBands) scene.bands.push_back(c.band);
        for (Optics& optics : scene.optics)
            for (const BandOptics& o : kColourOptics.at(optics.id)) optics.bands.push_back(o);
    }
    PlantationParameters plantation;
    plantation.tree = command.tree;
    plantation.rows = command.rows;
    plantation.columns = command.columns;
    plantation.trees = command.trees;
    plantation.columnSpacingM = command.spacing;
    plantation.rowSpacingM = command.rowSpacing > 0.0 ? command.rowSpacing : command.spacing;
    plantation.rowAzimuthDeg = command.rowAzimuth;
    plantation.jitterM = 0.1 * command.spacing;
    plantation.prototypes = command.prototypes;
    // A bar for scenes that take more than a few seconds: 100,000 leaves and more.
    if (!command.quiet && Leaves(command) >= 1e5) plantation.progress = ProgressBar("trees");
    if (command.randomCanopy) {
        CanopyParameters canopy = command.canopy;
        canopy.seed = command.tree.seed;
        AddRandomCanopy(scene, canopy);
    } else if (command.greenhouse) {
        GreenhouseParameters greenhouse;
        greenhouse.plantation = plantation;
        greenhouse.lampExitanceWm2 = bands({command.lampPar, command.lampNir}, &ColourBand::lamp);
        AddGreenhouse(scene, greenhouse);
    } else {
        AddPlantation(scene, plantation, command.noGround ? "" : "ground");
    }
    const double h = glm::radians(command.sunElevation), a = glm::radians(command.sunAzimuth);
    if (!command.greenhouse) {
        scene.sources.suns.push_back(
            {{std::cos(h) * std::sin(a), std::cos(h) * std::cos(a), std::sin(h)},
             bands({command.sunPar, command.sunNir}, &ColourBand::sun),
             0.0});
    }
    if (!command.noSky && !command.greenhouse) {
        scene.sources.skies.push_back({SkyModel::kCieOvercast,
                                       bands({command.skyPar, command.skyNir}, &ColourBand::sky),
                                       SkyDiscretizationNamed(command.skyCones)});
    }
    scene.Validate();
    const bool large = !command.quiet && Leaves(command) >= 1e5;
    if (large) {
        std::fprintf(
            stderr, "  built in %.1f s; writing %s\n",
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
            command.out.c_str());
    }
    WriteScene(scene, command.out,
               command.instanced ? SceneWriting::kInstanced : SceneWriting::kFlat,
               large ? ProgressBar("writing") : std::function<void(double)>());
    std::size_t leaves = 0, triangles = 0;
    for (const Node& node : scene.nodes) {
        leaves += node.type() == NodeType::kLeaf;
        if (node.organ()) triangles += node.organ()->mesh->triangles.size();
    }
    std::cout << "wrote " << command.out << ": " << leaves << " leaves, " << scene.nodes.size()
              << " nodes, " << triangles << " organ triangles ("
              << std::filesystem::file_size(command.out) << " bytes"
              << (command.instanced ? ", instanced" : "") << ")" << std::endl;
    return 0;
}

}  // namespace leaflux
