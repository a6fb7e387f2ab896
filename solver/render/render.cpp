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

// What one ray saw.
struct Sample {
    enum Kind : std::uint8_t { kMiss, kSurface, kLampSurface, kUnsolvedSurface };
    Kind kind = kMiss;
    float value = 0.0f;
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

double ValueOf(const Scene& scene, const Receiver& receiver, const BandLight& light,
               const RenderSettings& settings, bool upperSeen) {
    if (settings.quantity == Quantity::kAbsorbed)
        return receiver.areaM2 > 0.0 ? light.absorbedW / receiver.areaM2 : 0.0;
    const BandOptics* optics =
        receiver.optics >= 0 ? &scene.optics[receiver.optics].bands[settings.band] : nullptr;
    switch (settings.side) {
        case Side::kSeenSide:
            return SideValue(light, optics, upperSeen, settings.quantity);
        case Side::kUpperSide:
            return SideValue(light, optics, true, settings.quantity);
        case Side::kLowerSide:
            return SideValue(light, optics, false, settings.quantity);
        case Side::kBothSides:
            // A wall or a ground bounds two spaces: summing its sides would paint a wall's
            // sunlit outside onto its inside. It shows the side in view.
            if (receiver.kind == ReceiverKind::kEnvironment)
                return SideValue(light, optics, upperSeen, settings.quantity);
            return SideValue(light, optics, true, settings.quantity) +
                   SideValue(light, optics, false, settings.quantity);
    }
    return 0.0;
}

std::string CaptionOf(const Scene& scene, const RenderSettings& settings) {
    const char* what[] = {"irradiance", "absorbed per area", "radiosity"};
    const char* side[] = {", side facing the camera", ", upper side", ", lower side",
                          ", both sides summed"};
    std::string caption =
        scene.bands[settings.band].name + " " + what[static_cast<int>(settings.quantity)];
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
    if (settings.band < 0 || settings.band >= static_cast<int>(scene.bands.size()))
        throw InputError(ErrorCode::kNotFound, "band", "not a band of the scene");
    if (settings.photons && !PhotonUmolPerJ(scene.bands[settings.band])) {
        throw InputError(ErrorCode::kInvalidArgument, "photons",
                         "band " + scene.bands[settings.band].name + " has no photon factor");
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
    const double unit = settings.photons ? *PhotonUmolPerJ(scene.bands[settings.band]) : 1.0;
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
                        const std::uint32_t r = triangle.receiver;
                        const Receiver& receiver = flat.receivers[r];
                        if (receiver.kind == ReceiverKind::kEmitter) {
                            s.kind = Sample::kLampSurface;
                        } else if (!solution.unsolved.empty() && solution.unsolved[r]) {
                            s.kind = Sample::kUnsolvedSurface;
                        } else {
                            s.kind = Sample::kSurface;
                            const bool upper = glm::dot(triangle.normal, d) < 0.0;
                            s.value = static_cast<float>(
                                unit * ValueOf(scene, receiver, solution.light[r][settings.band],
                                               settings, upper));
                        }
                    }
        });
    };
    if (settings.threads > 0) {
        tbb::task_arena(settings.threads).execute(trace);
    } else {
        trace();
    }

    Rendering rendering;
    rendering.scale.palette = settings.palette;
    if (settings.range) {
        std::tie(rendering.scale.min, rendering.scale.max) = *settings.range;
    } else {
        double largest = 0.0;
        for (const Sample& s : samples)
            if (s.kind == Sample::kSurface && std::isfinite(s.value))
                largest = std::max(largest, static_cast<double>(s.value));
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
                    c = rendering.scale.Of(s.value, x, y);
                    ++surface;
                    beyond += rendering.scale.Beyond(s.value);
                }
                r += c.r, g += c.g, b += c.b;
            }
            const auto mean = [perPixel](double v) {
                return static_cast<std::uint8_t>(std::lround(v / perPixel));
            };
            viewImage.At(x, y) = {mean(r), mean(g), mean(b)};
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
