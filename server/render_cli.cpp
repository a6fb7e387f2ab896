#include "server/render_cli.h"

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <iostream>
#include <sstream>

#include "server/cli_checks.h"
#include "server/scene_proto.h"
#include "solver/render/render.h"
#include "solver/results/read_leaf_csv.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

// "WxH" as two whole numbers.
std::pair<int, int> ParseSize(const std::string& text) {
    const std::size_t x = text.find('x');
    char* end = nullptr;
    const long w = x == std::string::npos ? 0 : std::strtol(text.c_str(), &end, 10);
    const bool widthRead = x != std::string::npos && end == text.c_str() + x;
    const long h = widthRead ? std::strtol(text.c_str() + x + 1, &end, 10) : 0;
    if (!widthRead || end != text.c_str() + text.size() || x + 1 == text.size())
        throw InputError(ErrorCode::kParse, "--size",
                         "expects WIDTHxHEIGHT, such as 1024x768, got '" + text + "'");
    return {static_cast<int>(std::min(w, 1L << 20)), static_cast<int>(std::min(h, 1L << 20))};
}

// "MIN,MAX" as two numbers.
std::pair<double, double> ParseRange(const std::string& text) {
    const std::size_t comma = text.find(',');
    char* end = nullptr;
    const double low = std::strtod(text.c_str(), &end);
    const bool lowRead = comma != std::string::npos && end == text.c_str() + comma && comma > 0;
    const double high = lowRead ? std::strtod(text.c_str() + comma + 1, &end) : 0.0;
    if (!lowRead || end != text.c_str() + text.size() || comma + 1 == text.size())
        throw InputError(ErrorCode::kParse, "--range",
                         "expects MIN,MAX, such as 0,500, got '" + text + "'");
    return {low, high};
}

RenderSettings SettingsOf(const RenderCommand& command, const Scene& scene) {
    RenderSettings settings;
    settings.camera = ParseCamera(command.camera);
    std::tie(settings.width, settings.height) = ParseSize(command.size);
    settings.samples = command.pixelSamples;
    settings.quantity = command.quantity == "absorbed"    ? Quantity::kAbsorbed
                        : command.quantity == "radiosity" ? Quantity::kRadiosity
                        : command.quantity == "colour"    ? Quantity::kTrueColour
                                                          : Quantity::kIrradiance;
    settings.side = command.side == "upper"   ? Side::kUpperSide
                    : command.side == "lower" ? Side::kLowerSide
                    : command.side == "both"  ? Side::kBothSides
                                              : Side::kSeenSide;
    const auto bandIndex = [&](const std::string& name, const std::string& option) {
        const int b = scene.BandIndex(name);
        if (b < 0) throw InputError(ErrorCode::kNotFound, option, "the scene has no band " + name);
        return b;
    };
    settings.band = command.band.empty() ? 0 : bandIndex(command.band, "--band");
    if (settings.quantity == Quantity::kTrueColour) {
        std::stringstream names(command.rgb);
        std::string name;
        int k = 0;
        while (std::getline(names, name, ',')) {
            if (k == 3) break;
            settings.rgb[k++] = bandIndex(name, "--rgb");
        }
        if (k != 3 || std::getline(names, name))
            throw InputError(ErrorCode::kParse, "--rgb",
                             "expects three band names, such as R,G,B, got '" + command.rgb + "'");
    }
    settings.photons = command.photons;
    if (!command.range.empty()) settings.range = ParseRange(command.range);
    settings.palette = command.palette == "grey" ? Palette::kGrey : Palette::kViridis;
    settings.scaleBar = command.scaleBar;
    settings.northArrow = command.northArrow;
    settings.threads = command.solve.threads;
    Validate(settings, scene);
    return settings;
}

}  // namespace

CLI::App* AddRenderCommand(CLI::App& app, RenderCommand& command) {
    CLI::App* render = app.add_subcommand(
        "render",
        "Draw a picture of the light on a scene: solved now (the solve command's options) or "
        "read from a per-organ CSV (--from); false colour with a colour bar below the view");
    AddSolverOptions(*render, command.solve);
    render
        ->add_option("--camera", command.camera,
                     "\"eye=x,y,z look=x,y,z up=x,y,z fov=deg\" (world metres; up defaults to "
                     "0,0,1, fov, the vertical field of view, to 45)")
        ->required();
    render->add_option("--size", command.size,
                       "The view's WIDTHxHEIGHT in pixels (the colour bar adds a panel below)");
    render->add_option("--out", command.out, "PNG file (its folder is made)")->required();
    render->add_option(
        "--from", command.from,
        "Per-organ CSV written by leaflux solve --out on this scene: drawn as it is, "
        "nothing solved (organs it lacks drawn grey)");
    render
        ->add_option("--quantity", command.quantity,
                     "irradiance (arriving), absorbed (absorbed power per area of the organ), "
                     "radiosity (leaving: ρ E + τ E from the other side) or colour (the "
                     "radiosity of the --rgb bands as red, green and blue, linear on one scale)")
        ->check(CLI::IsMember({"irradiance", "absorbed", "radiosity", "colour"}));
    render
        ->add_option("--side", command.side,
                     "irradiance, radiosity: seen (the side facing the camera), upper, lower or "
                     "both (summed)")
        ->check(CLI::IsMember({"seen", "upper", "lower", "both"}));
    render->add_option("--band", command.band, "Band by name (default: the scene's first)");
    render->add_option("--rgb", command.rgb,
                       "colour: the three bands shown red, green and blue, by name");
    render->add_flag(
        "--photons", command.photons,
        "In µmol m⁻² s⁻¹ (the band's photon factor, 4.57 µmol/J for PAR) instead of W/m²");
    render->add_option("--range", command.range,
                       "MIN,MAX of the colour scale, so that pictures share one (default: 0 to the "
                       "largest value in view); values beyond it are hatched");
    render
        ->add_option("--palette", command.palette,
                     "viridis, or grey (black to white, linear: pixel ratios are value ratios)")
        ->check(CLI::IsMember({"viridis", "grey"}));
    render->add_flag("--scale-bar", command.scaleBar,
                     "A round length at the view's bottom-left, true at the look point's distance");
    render->add_flag("--north-arrow", command.northArrow,
                     "An arrow towards north (+y) at the look point, top right");
    render->add_flag("--open-in-view", command.openInView,
                     "instanced: open only the instances whose boxes are in view (Soler 2003 "
                     "§7.1); the others are solved whole, from their phase functions");
    render
        ->add_option("--pixel-samples", command.pixelSamples,
                     "Rays a pixel, on a stratified grid (rounded to a square: 1, 4, 9, 16, …)")
        ->transform(WholeNumber())
        ->check(CLI::Range(1, 1024));
    return render;
}

int RunRender(const RenderCommand& command) {
    CheckWritable(command.out, "--out");
    // The camera and the picture's settings are checked before the scene is read, those
    // that need the scene (the band) before it is solved.
    ParseCamera(command.camera);
    ParseSize(command.size);
    if (!command.range.empty()) ParseRange(command.range);
    std::unique_ptr<SolvedScene> solved;
    const auto check = [&](const Scene& scene) { SettingsOf(command, scene); };
    if (command.from.empty()) {
        SolveCommand solve = command.solve;
        if (command.openInView) {
            if (solve.solver != "instanced")
                throw InputError(ErrorCode::kInvalidArgument, "--open-in-view",
                                 "is for --solver instanced");
            const auto [width, height] = ParseSize(command.size);
            const View view(ParseCamera(command.camera), width, height);
            solve.instanced.inView = [view](const glm::dvec3& low, const glm::dvec3& high) {
                return view.MaySee(low, high);
            };
        }
        solved = SolveScene(solve, check);
    } else {
        solved = std::make_unique<SolvedScene>();
        solved->scene = LoadSceneFile(command.solve.scene, command.solve.file);
        check(solved->scene);
    }
    if (!solved->prepared) solved->prepared.emplace(solved->scene);  // the camera's rays
    if (!command.from.empty())
        solved->solution = ReadLeafCsv(command.from, solved->scene, solved->prepared->Flat());
    const Rendering rendering = Render(solved->scene, solved->prepared->Rays(), solved->solution,
                                       SettingsOf(command, solved->scene));
    WritePng(rendering.image, command.out);
    std::cout << "wrote " << command.out << ": " << rendering.image.Width() << " x "
              << rendering.image.Height() << ", " << rendering.caption << " from "
              << rendering.scale.min << " to " << rendering.scale.max << ", " << rendering.rays
              << " rays in " << rendering.seconds << " s";
    if (rendering.beyondFraction > 0.0)
        std::cout << "; " << 100.0 * rendering.beyondFraction
                  << " % of the surface in view beyond the scale (hatched)";
    std::cout << std::endl;
    return 0;
}

}  // namespace leaflux
