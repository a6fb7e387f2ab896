#include "solver/render/render.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "solver/render/legend.h"
#include "solver/scene/light_units.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

constexpr long long kMaxRays = 1LL << 28;
constexpr Rgb kSky{232, 236, 240};       // where a ray leaves the scene
constexpr Rgb kLamp{255, 244, 214};      // an emitter's own surface
constexpr Rgb kUnsolved{150, 150, 150};  // an organ of a structure solved whole

// What one ray saw: a receiver and its side; the value is read from the solution once the
// scale is made.
struct Sample {
    enum Kind : std::uint8_t { kMiss, kSurface, kLampSurface, kUnsolvedSurface };
    std::uint32_t receiver = 0;
    Kind kind = kMiss;
    bool upper = false;  // the side seen
};

// The quantity on one side of a receiver (upper: true), in W/m².
double SideValue(const BandLight& light, const BandOptics* optics, bool upper, Quantity quantity) {
    const double own = upper ? light.irradianceUpperWm2 : light.irradianceLowerWm2;
    if (quantity == Quantity::kIrradiance) return own;
    if (optics == nullptr) return 0.0;  // black: it sends nothing
    const double other = upper ? light.irradianceLowerWm2 : light.irradianceUpperWm2;
    return upper ? optics->rhoUpper * own + optics->tauLowerToUpper * other
                 : optics->rhoLower * own + optics->tauUpperToLower * other;
}

// The quantity of band `band` on `receiver`, W/m² (true colour: its radiosity).
double ValueOf(const Scene& scene, const Receiver& receiver, const BandLight& light,
               const RenderSettings& settings, int band, bool upperSeen) {
    if (settings.quantity == Quantity::kAbsorbed)
        return receiver.areaM2 > 0.0 ? light.absorbedW / receiver.areaM2 : 0.0;
    const Quantity quantity =
        settings.quantity == Quantity::kTrueColour ? Quantity::kRadiosity : settings.quantity;
    const BandOptics* optics =
        receiver.optics >= 0 ? &scene.optics[receiver.optics].bands[band] : nullptr;
    switch (settings.side) {
        case Side::kSeenSide:
            return SideValue(light, optics, upperSeen, quantity);
        case Side::kUpperSide:
            return SideValue(light, optics, true, quantity);
        case Side::kLowerSide:
            return SideValue(light, optics, false, quantity);
        case Side::kBothSides:
            // A wall or a ground bounds two spaces: summing its sides would paint a wall's
            // sunlit outside onto its inside. It shows the side in view.
            if (receiver.kind == ReceiverKind::kEnvironment)
                return SideValue(light, optics, upperSeen, quantity);
            return SideValue(light, optics, true, quantity) +
                   SideValue(light, optics, false, quantity);
    }
    return 0.0;
}

// The bands a picture shows: the one asked, or the three of true colour.
std::vector<int> BandsShown(const RenderSettings& settings) {
    if (settings.quantity == Quantity::kTrueColour)
        return {settings.rgb[0], settings.rgb[1], settings.rgb[2]};
    return {settings.band};
}

std::string CaptionOf(const Scene& scene, const RenderSettings& settings) {
    const char* what[] = {"irradiance", "absorbed per area", "radiosity", "radiosity"};
    const char* side[] = {", side facing the camera", ", upper side", ", lower side",
                          ", both sides summed"};
    std::string bands = scene.bands[settings.band].name;
    if (settings.quantity == Quantity::kTrueColour) {
        const auto& b = scene.bands;
        bands = b[settings.rgb[0]].name + ", " + b[settings.rgb[1]].name + ", " +
                b[settings.rgb[2]].name + " as red, green, blue:";
    }
    std::string caption = bands + " " + what[static_cast<int>(settings.quantity)];
    if (settings.quantity != Quantity::kAbsorbed) caption += side[static_cast<int>(settings.side)];
    return caption + (settings.photons ? " (µmol m⁻² s⁻¹)" : " (W/m²)");
}

}  // namespace

int Rendering::BarColumn(double value) const {
    const double t = scale.max > scale.min ? (value - scale.min) / (scale.max - scale.min) : 0.0;
    return barLeft + static_cast<int>(std::lround(std::clamp(t, 0.0, 1.0) * (barRight - barLeft)));
}

void Validate(const RenderSettings& settings, const Scene& scene) {
    Validate(settings.camera);
    if (settings.width < 16 || settings.height < 16 || settings.width > 16384 ||
        settings.height > 16384) {
        throw InputError(ErrorCode::kInvalidArgument, "size",
                         "must be from 16 x 16 to 16384 x 16384 pixels");
    }
    if (settings.samples < 1 || settings.samples > 1024)
        throw InputError(ErrorCode::kInvalidArgument, "samples", "must be from 1 to 1024");
    // Every ray's value is kept until the scale is known (8 bytes each): at most 2 GiB.
    const double rays = static_cast<double>(settings.width) * settings.height * settings.samples;
    if (rays > kMaxRays) {
        throw InputError(ErrorCode::kInvalidArgument, "samples",
                         "size x samples makes " + std::to_string(static_cast<long long>(rays)) +
                             " rays, over the " + std::to_string(kMaxRays) +
                             " a picture may take; fewer pixels or samples");
    }
    const int bands = static_cast<int>(scene.bands.size());
    if (settings.band < 0 || settings.band >= bands)
        throw InputError(ErrorCode::kNotFound, "band", "not a band of the scene");
    for (int b : settings.rgb)
        if (b < 0 || b >= bands)
            throw InputError(ErrorCode::kNotFound, "rgb", "not a band of the scene");
    for (int b : BandsShown(settings))
        if (settings.photons && !PhotonUmolPerJ(scene.bands[b])) {
            throw InputError(ErrorCode::kInvalidArgument, "photons",
                             "band " + scene.bands[b].name + " has no photon factor");
        }
    if (settings.range) {
        const auto [low, high] = *settings.range;
        if (!std::isfinite(low) || !std::isfinite(high) || !(low < high))
            throw InputError(ErrorCode::kInvalidArgument, "range",
                             "must be MIN,MAX with MIN < MAX");
    }
}

Rendering Render(const Scene& scene, const RayScene& rays, const Solution& solution,
                 const RenderSettings& settings) {
    Validate(settings, scene);
    const auto start = std::chrono::steady_clock::now();
    const FlatScene& flat = rays.Flat();
    const int w = settings.width, h = settings.height;
    const int grid = std::max(1, static_cast<int>(std::lround(std::sqrt(settings.samples))));
    const int perPixel = grid * grid;
    const View view(settings.camera, w, h);
    const std::vector<int> bands = BandsShown(settings);
    std::vector<double> units;  // per band shown: W/m² to the picture's unit
    for (int b : bands) units.push_back(settings.photons ? *PhotonUmolPerJ(scene.bands[b]) : 1.0);
    // A sample's value in each band shown (true colour: red, green, blue).
    const auto values = [&](const Sample& s) {
        std::array<double, 3> v{0.0, 0.0, 0.0};
        for (std::size_t k = 0; k < bands.size(); ++k)
            v[k] = units[k] * ValueOf(scene, flat.receivers[s.receiver],
                                      solution.light[s.receiver][bands[k]], settings, bands[k],
                                      s.upper);
        return v;
    };
    const RayStart eye{flat.ToLocal(settings.camera.eye)};

    // First every ray's value, so that the scale can come from what is in view.
    std::vector<Sample> samples(static_cast<std::size_t>(w) * h * perPixel);
    const auto trace = [&] {
        tbb::parallel_for(tbb::blocked_range2d<int>(0, h, 8, 0, w, 64), [&](const auto& block) {
            SetFlushToZero();
            for (int y = block.rows().begin(); y < block.rows().end(); ++y)
                for (int x = block.cols().begin(); x < block.cols().end(); ++x)
                    for (int k = 0; k < perPixel; ++k) {
                        const glm::dvec3 d = view.Direction(x + (k % grid + 0.5) / grid,
                                                            y + (k / grid + 0.5) / grid);
                        const RayHit hit = rays.Trace(eye, d);
                        Sample& s = samples[(static_cast<std::size_t>(y) * w + x) * perPixel + k];
                        if (hit.fate != RayFate::kHit) continue;
                        const Triangle& triangle = flat.triangles[hit.triangle];
                        s.receiver = triangle.receiver;
                        s.upper = glm::dot(triangle.normal, d) < 0.0;
                        s.kind = flat.receivers[s.receiver].kind == ReceiverKind::kEmitter
                                     ? Sample::kLampSurface
                                 : !solution.unsolved.empty() && solution.unsolved[s.receiver]
                                     ? Sample::kUnsolvedSurface
                                     : Sample::kSurface;
                    }
        });
    };
    if (settings.threads > 0) {
        tbb::task_arena(settings.threads).execute(trace);
    } else {
        trace();
    }

    Rendering rendering;
    const bool colour = settings.quantity == Quantity::kTrueColour;
    rendering.scale.palette = colour ? Palette::kGrey : settings.palette;
    if (settings.range) {
        std::tie(rendering.scale.min, rendering.scale.max) = *settings.range;
    } else {
        double largest = 0.0;
        for (const Sample& s : samples)
            if (s.kind == Sample::kSurface)
                for (double v : values(s))
                    if (std::isfinite(v)) largest = std::max(largest, v);
        rendering.scale.min = 0.0;
        rendering.scale.max = largest > 0.0 ? largest : 1.0;
    }
    Image viewImage(w, h);
    std::int64_t surface = 0, beyond = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double r = 0.0, g = 0.0, b = 0.0;
            for (int k = 0; k < perPixel; ++k) {
                const Sample& s = samples[(static_cast<std::size_t>(y) * w + x) * perPixel + k];
                Rgb c = kSky;
                if (s.kind == Sample::kLampSurface) c = kLamp;
                if (s.kind == Sample::kUnsolvedSurface) c = kUnsolved;
                if (s.kind == Sample::kSurface) {
                    const std::array<double, 3> v = values(s);
                    // True colour: each channel on the grey scale (a channel beyond it striped).
                    c = colour ? Rgb{rendering.scale.Of(v[0], x, y).r,
                                     rendering.scale.Of(v[1], x, y).g,
                                     rendering.scale.Of(v[2], x, y).b}
                               : rendering.scale.Of(v[0], x, y);
                    ++surface;
                    beyond += std::any_of(v.begin(), v.begin() + static_cast<long>(bands.size()),
                                          [&](double u) { return rendering.scale.Beyond(u); });
                }
                r += c.r, g += c.g, b += c.b;
            }
            const auto mean = [perPixel](double v) {
                return static_cast<std::uint8_t>(std::lround(v / perPixel));
            };
            viewImage.At(x, y) = {mean(r), mean(g), mean(b)};
        }
    if (settings.scaleBar) {
        rendering.scaleBar = ScaleBarOf(settings.camera, view, w);
        DrawScaleBar(viewImage, rendering.scaleBar);
    }
    if (settings.northArrow) {
        const bool ahead =
            glm::dot(settings.camera.look - settings.camera.eye, {0.0, 1.0, 0.0}) > 0.0;
        DrawNorthArrow(viewImage, NorthInPicture(settings.camera, view), ahead);
    }
    rendering.caption = CaptionOf(scene, settings);
    const Legend legend = DrawLegend(viewImage, rendering.scale, rendering.caption, beyond > 0);
    rendering.image = legend.image;
    rendering.barLeft = legend.barLeft;
    rendering.barRight = legend.barRight;
    rendering.barTop = legend.barTop;
    rendering.barBottom = legend.barBottom;
    rendering.rays = static_cast<std::int64_t>(samples.size());
    rendering.beyondFraction = surface > 0 ? static_cast<double>(beyond) / surface : 0.0;
    rendering.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return rendering;
}

}  // namespace leaflux
