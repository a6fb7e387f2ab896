#include "server/session_render.h"

#include <map>

#include "server/scene_proto.h"
#include "solver/render/render.h"
#include "solver/solve.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

glm::dvec3 Point(const v1::Vec3& v) { return {v.x(), v.y(), v.z()}; }

int BandNamed(const Scene& scene, const std::string& name, const std::string& field) {
    const int b = scene.BandIndex(name);
    if (b < 0) throw InputError(ErrorCode::kNotFound, field, "the scene has no band " + name);
    return b;
}

RenderSettings SettingsOf(const v1::RenderRequest& in, const Scene& scene) {
    RenderSettings settings;
    Camera& camera = settings.camera;
    if (!in.camera().has_eye())
        throw InputError(ErrorCode::kInvalidArgument, "camera.eye", "missing");
    if (!in.camera().has_look())
        throw InputError(ErrorCode::kInvalidArgument, "camera.look", "missing");
    camera.eye = Point(in.camera().eye());
    camera.look = Point(in.camera().look());
    if (in.camera().has_up()) camera.up = Point(in.camera().up());
    if (in.camera().fov_deg() != 0.0) camera.fovDeg = in.camera().fov_deg();
    if (in.width() > kMaxPictureSide || in.height() > kMaxPictureSide)
        throw TooLarge(in.width() > kMaxPictureSide ? "render.width" : "render.height",
                       "at most " + std::to_string(kMaxPictureSide) + " pixels a side");
    if (in.width() != 0) settings.width = static_cast<int>(in.width());
    if (in.height() != 0) settings.height = static_cast<int>(in.height());
    // Beyond 1024 it stays beyond (no wrap into an int), for Validate to refuse naming it.
    if (in.pixel_samples() != 0)
        settings.samples = static_cast<int>(std::min(in.pixel_samples(), 1025u));
    if (static_cast<double>(settings.width) * settings.height * settings.samples > kMaxPictureRays)
        throw TooLarge("render.pixel_samples",
                       "width x height x pixel_samples over the " +
                           std::to_string(static_cast<long long>(kMaxPictureRays)) +
                           " rays a daemon's picture may take");
    switch (in.quantity()) {
        case v1::RENDER_QUANTITY_ABSORBED:
            settings.quantity = Quantity::kAbsorbed;
            break;
        case v1::RENDER_QUANTITY_RADIOSITY:
            settings.quantity = Quantity::kRadiosity;
            break;
        case v1::RENDER_QUANTITY_TRUE_COLOUR:
            settings.quantity = Quantity::kTrueColour;
            break;
        default:
            settings.quantity = Quantity::kIrradiance;
    }
    settings.side = in.side() == v1::RENDER_SIDE_UPPER   ? Side::kUpperSide
                    : in.side() == v1::RENDER_SIDE_LOWER ? Side::kLowerSide
                    : in.side() == v1::RENDER_SIDE_BOTH  ? Side::kBothSides
                                                         : Side::kSeenSide;
    if (!in.band().empty()) settings.band = BandNamed(scene, in.band(), "band");
    if (settings.quantity == Quantity::kTrueColour) {
        if (in.rgb_size() != 0 && in.rgb_size() != 3)
            throw InputError(ErrorCode::kInvalidArgument, "rgb", "names three bands or none");
        const char* fallback[] = {"R", "G", "B"};
        for (int k = 0; k < 3; ++k)
            settings.rgb[k] = BandNamed(scene, in.rgb_size() ? in.rgb(k) : fallback[k],
                                        "rgb[" + std::to_string(k) + "]");
    }
    settings.photons = in.photons();
    if (in.has_range()) settings.range = std::pair{in.range().min(), in.range().max()};
    settings.palette = in.palette() == v1::RENDER_PALETTE_GREY ? Palette::kGrey : Palette::kViridis;
    settings.scaleBar = in.scale_bar();
    settings.northArrow = in.north_arrow();
    Validate(settings, scene);
    return settings;
}

// The light `last` returned, by receiver of `flat`; receivers it lacks are unsolved (grey).
// Every band the picture shows must be in it.
Solution SolutionOf(const Scene& scene, const FlatScene& flat, const v1::CycleResult& last,
                    const RenderSettings& settings) {
    if (last.organs_size() == 0)
        throw InputError(ErrorCode::kNotFound, "session",
                         "its last cycle returned no organ light: ask outputs.leaves");
    std::map<std::string, std::size_t> receivers;
    for (std::size_t r = 0; r < flat.receivers.size(); ++r)
        receivers.emplace(ReceiverName(scene, flat.receivers[r]), r);
    Solution solution;
    solution.light.assign(flat.receivers.size(), scene.bands.size());
    solution.unsolved.assign(flat.receivers.size(), 1);
    std::vector<bool> returned(scene.bands.size(), false);
    for (const v1::OrganLight& organ : last.organs()) {
        const auto r = receivers.find(organ.name());
        if (r == receivers.end()) continue;
        solution.unsolved[r->second] = 0;
        for (const v1::BandLight& in : organ.bands()) {
            const int b = scene.BandIndex(in.band());
            if (b < 0) continue;
            returned[b] = true;
            BandLight& light = solution.light[r->second][b];
            light.irradianceUpperWm2 = in.irradiance_upper_wm2();
            light.irradianceLowerWm2 = in.irradiance_lower_wm2();
            light.absorbedW = in.absorbed_w();
        }
    }
    const std::vector<int> shown = settings.quantity == Quantity::kTrueColour
                                       ? std::vector<int>(settings.rgb.begin(), settings.rgb.end())
                                       : std::vector<int>{settings.band};
    for (int b : shown)
        if (!returned[b])
            throw InputError(ErrorCode::kNotFound,
                             settings.quantity == Quantity::kTrueColour ? "rgb" : "band",
                             "the last cycle returned no light in band " + scene.bands[b].name +
                                 ": ask it in outputs.bands");
    return solution;
}

}  // namespace

v1::Picture RenderSession(const Scene& scene, FlatScene flat, const v1::CycleResult* last,
                          const v1::RenderRequest& request) {
    RenderSettings settings;
    Solution solution;
    try {  // errors named within the request
        settings = SettingsOf(request, scene);
        if (last == nullptr)
            throw InputError(ErrorCode::kNotFound, "session",
                             "has run no cycle: nothing to draw yet");
        solution = SolutionOf(scene, flat, *last, settings);
    } catch (const InputError& e) {  // RenderSettings' names as the request's fields
        const std::string field = e.Field() == "samples" ? "pixel_samples"
                                  : e.Field() == "size"  ? "width"
                                                         : e.Field();
        throw InputError(e.Code(), "render." + field, e.Message());
    }
    const PreparedScene prepared(scene, std::move(flat));  // the camera's rays
    const Rendering rendering = Render(scene, prepared.Rays(), solution, settings);
    v1::Picture picture;
    picture.set_png(EncodePng(rendering.image));
    picture.set_width(static_cast<std::uint32_t>(rendering.image.Width()));
    picture.set_height(static_cast<std::uint32_t>(rendering.image.Height()));
    picture.set_caption(rendering.caption);
    picture.set_scale_min(rendering.scale.min);
    picture.set_scale_max(rendering.scale.max);
    picture.set_beyond_fraction(rendering.beyondFraction);
    picture.set_rays(rendering.rays);
    picture.set_seconds(rendering.seconds);
    return picture;
}

}  // namespace leaflux
