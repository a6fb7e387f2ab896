#include "solver/reference/reference.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numeric>
#include <unordered_map>

#include "solver/util/check.h"
#include "solver/util/cores.h"
#include "solver/util/memory.h"
#include "solver/util/sampling.h"

namespace leaflux {
namespace {

constexpr double kPi = glm::pi<double>();
constexpr int kUpper = 0, kLower = 1;
// Survival probability cap of the Russian roulette: keeps paths finite when ρ + τ → 1
// (the weight is divided by it, so the estimate stays unbiased).
constexpr double kMaxSurvival = 0.995;

// Paths carry their spectrum in fixed-size arrays: a solve takes at most this many bands
// at once, and a scene of more is solved a group of bands at a time (SolveReference).
constexpr int kBandGroup = 8;
using Spectrum = std::array<double, kBandGroup>;

// Everything the paths need to know of the sources, prepared once per solve.
class Lights {
  public:
    Lights(const Scene& scene, const FlatScene& flat)
        : bands_(static_cast<int>(scene.bands.size())) {
        double total = 0.0;
        for (const Sun& sun : scene.sources.suns) {
            const double power = std::accumulate(sun.normalIrradianceWm2.begin(),
                                                 sun.normalIrradianceWm2.end(), 0.0);
            if (power <= 0.0) continue;
            total += power;
            suns_.push_back({&sun, total, std::cos(sun.angularRadiusRad)});
        }
        for (SunEntry& s : suns_) s.cumulative /= total;
        for (const Sky& sky : scene.sources.skies) {
            if (sky.discretization == SkyDiscretization::kContinuous) {
                continuousSkies_.push_back(&sky);
                continue;
            }
            for (const SkyCone& cone : sky.Cones()) {
                cones_.push_back({cone.direction, 1.0 - cone.solidAngleSr / (2.0 * kPi),
                                  ToSpectrum(cone.radianceWm2Sr)});
            }
        }
        double emitted = 0.0;
        for (std::uint32_t r = 0; r < flat.receivers.size(); ++r) {
            const Receiver& receiver = flat.receivers[r];
            if (receiver.kind != ReceiverKind::kEmitter) continue;
            const Emitter& emitter = scene.sources.emitters[receiver.declared];
            const double exitance =
                std::accumulate(emitter.exitanceWm2.begin(), emitter.exitanceWm2.end(), 0.0);
            // A dark lamp is still a surface, but nothing to sample.
            for (std::uint32_t t = receiver.firstTriangle;
                 exitance > 0.0 && t < receiver.firstTriangle + receiver.triangleCount; ++t) {
                emitted += exitance * flat.triangles[t].areaM2;
                emitterTriangles_.push_back({t, emitted});
            }
            exitance_.resize(flat.receivers.size());
            isEmitter_.resize(flat.receivers.size(), false);
            exitance_[r] = ToSpectrum(emitter.exitanceWm2);
            isEmitter_[r] = true;
        }
        for (EmitterTriangle& e : emitterTriangles_) e.cumulative /= emitted;
        for (std::size_t i = 0; i < emitterTriangles_.size(); ++i) {
            const double share = emitterTriangles_[i].cumulative -
                                 (i == 0 ? 0.0 : emitterTriangles_[i - 1].cumulative);
            pdfArea_[emitterTriangles_[i].triangle] =
                share / flat.triangles[emitterTriangles_[i].triangle].areaM2;
        }
    }

    int Bands() const { return bands_; }
    bool HasSuns() const { return !suns_.empty(); }
    bool HasEmitters() const { return !emitterTriangles_.empty(); }

    // A direction towards one sun, picked in proportion to its power, with the normal
    // irradiance it brings divided by the probability of the pick.
    glm::dvec3 SampleSun(Random& random, Spectrum& irradiance) const {
        const double u = random.Uniform();
        std::size_t i = 0;
        while (i + 1 < suns_.size() && u >= suns_[i].cumulative) ++i;
        const double pick = suns_[i].cumulative - (i == 0 ? 0.0 : suns_[i - 1].cumulative);
        for (int b = 0; b < bands_; ++b)
            irradiance[b] = suns_[i].sun->normalIrradianceWm2[b] / pick;
        const double v = random.Uniform(), w = random.Uniform();
        return suns_[i].cosRadius < 1.0
                   ? UniformCone(suns_[i].sun->towardSun, suns_[i].cosRadius, v, w)
                   : suns_[i].sun->towardSun;
    }

    // Sky radiance arriving from `towardSky`. A cone reaching below the horizon folds its
    // lower part back above it, so that every cone delivers its whole power.
    void SkyRadiance(const glm::dvec3& towardSky, Spectrum& radiance) const {
        radiance.fill(0.0);
        if (towardSky.z <= 0.0) return;
        for (const Sky* sky : continuousSkies_) {
            for (int b = 0; b < bands_; ++b) radiance[b] += sky->Radiance(b, towardSky);
        }
        const glm::dvec3 mirrored(towardSky.x, towardSky.y, -towardSky.z);
        for (const ConeEntry& cone : cones_) {
            const int inside = (glm::dot(cone.axis, towardSky) >= cone.cosRadius) +
                               (glm::dot(cone.axis, mirrored) >= cone.cosRadius);
            for (int b = 0; b < bands_; ++b) radiance[b] += inside * cone.radiance[b];
        }
    }

    struct EmitterPoint {
        glm::dvec3 point, normal;
        std::uint32_t triangle;
        double pdfArea;
    };
    EmitterPoint SampleEmitter(const FlatScene& flat, Random& random) const {
        const double u = random.Uniform();
        const auto it = std::lower_bound(
            emitterTriangles_.begin(), emitterTriangles_.end(), u,
            [](const EmitterTriangle& e, double value) { return e.cumulative < value; });
        const std::uint32_t t =
            (it == emitterTriangles_.end() ? emitterTriangles_.back() : *it).triangle;
        const Triangle& tri = flat.triangles[t];
        const glm::dvec3 w = UniformTriangle(random.Uniform(), random.Uniform());
        return {w.x * tri.a + w.y * tri.b + w.z * tri.c, tri.normal, t, pdfArea_.at(t)};
    }
    double PdfArea(std::uint32_t triangle) const {
        const auto it = pdfArea_.find(triangle);
        return it == pdfArea_.end() ? 0.0 : it->second;
    }
    // Exitance (W/m²) of an emitter receiver's upper side; null for other receivers.
    const Spectrum* Exitance(std::uint32_t receiver) const {
        return receiver < isEmitter_.size() && isEmitter_[receiver] ? &exitance_[receiver]
                                                                    : nullptr;
    }

  private:
    Spectrum ToSpectrum(const std::vector<double>& values) const {
        Spectrum s{};
        std::copy(values.begin(), values.end(), s.begin());
        return s;
    }

    struct SunEntry {
        const Sun* sun;
        double cumulative;
        double cosRadius;
    };
    struct ConeEntry {
        glm::dvec3 axis;
        double cosRadius;
        Spectrum radiance;
    };
    struct EmitterTriangle {
        std::uint32_t triangle;
        double cumulative;
    };
    int bands_;
    std::vector<SunEntry> suns_;
    std::vector<const Sky*> continuousSkies_;
    std::vector<ConeEntry> cones_;
    std::vector<EmitterTriangle> emitterTriangles_;
    std::unordered_map<std::uint32_t, double> pdfArea_;
    std::vector<Spectrum> exitance_;  // per receiver, W/m²; set for emitters only
    std::vector<bool> isEmitter_;
};

// Per side reflectance and transmittance of a receiver; black when it has no optics.
struct SideOptics {
    Spectrum rho[2]{};  // light arriving on side s, reflected back to s
    Spectrum tau[2]{};  // light arriving on side s, transmitted to the other side
};

SideOptics OpticsOf(const Scene& scene, int optics) {
    SideOptics o;
    if (optics < 0) return o;
    const auto& bands = scene.optics[optics].bands;
    for (std::size_t b = 0; b < bands.size(); ++b) {
        o.rho[kUpper][b] = bands[b].rhoUpper;
        o.rho[kLower][b] = bands[b].rhoLower;
        o.tau[kUpper][b] = bands[b].tauUpperToLower;
        o.tau[kLower][b] = bands[b].tauLowerToUpper;
    }
    return o;
}

// Power heuristic (Veach 1997) for two strategies.
double PowerHeuristic(double pdfA, double pdfB) {
    const double a = pdfA * pdfA, b = pdfB * pdfB;
    return a + b > 0.0 ? a / (a + b) : 0.0;
}

// Light straight from suns and lamps at a point, per side: next-event estimation.
struct SourceLight {
    Spectrum irradiance[2]{};
    Spectrum radianceIntegral{};
    std::array<glm::dvec3, kBandGroup> radianceMoment{};
};

// The tallies of one replicate of one receiver, per band, as sample means.
struct Tally {
    Spectrum irradiance[2]{};
    Spectrum direct[2]{};  // the part that came straight from a source
    Spectrum radianceIntegral{};
    std::array<glm::dvec3, kBandGroup> radianceMoment{};
    Spectrum escaping{};  // radiosity leaving towards nothing (W/m²), emission aside
};

// How the path tracer draws directions at a point, for the MIS weights of lamps.
constexpr int kUniformSphere = -1;  // otherwise: cosine-weighted on side kUpper or kLower

class PathTracer {
  public:
    PathTracer(const Scene& scene, const FlatScene& flat, const RayScene& rays,
               const ReferenceOptions& options)
        : flat_(flat), rays_(rays), options_(options), lights_(scene, flat) {
        for (const Receiver& receiver : flat.receivers) {
            optics_.push_back(OpticsOf(scene, receiver.optics));
        }
        // Lamps in a periodic scene repeat without end: light reaches from their copies
        // only through the paths that hit them, so next-event estimation is left out.
        emitterEvents_ = lights_.HasEmitters() && !rays.Periodic();
    }

    const SideOptics& Optics(std::uint32_t receiver) const { return optics_[receiver]; }

    // One replicate of a receiver: `samples` points (rounded up to a square) on a
    // jittered grid over its area, each paired with a direction of a jittered grid over
    // the sphere.
    Tally Replicate(std::uint32_t receiverIndex, int samples, std::uint64_t seed,
                    std::int64_t& rays) const {
        const Receiver& receiver = flat_.receivers[receiverIndex];
        Random random(seed);
        const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(samples))));
        const int count = side * side;
        std::vector<int> pairing(count);
        std::iota(pairing.begin(), pairing.end(), 0);
        for (int i = count - 1; i > 0; --i) std::swap(pairing[i], pairing[random.Below(i + 1)]);

        const int bands = lights_.Bands();
        Tally tally;
        for (int i = 0; i < count; ++i) {
            const RayStart x = PointOn(receiver, (i % side + random.Uniform()) / side,
                                       (i / side + random.Uniform()) / side);
            const glm::dvec3& normal = flat_.triangles[x.triangle].normal;
            const SourceLight events = SourceEvents(x, normal, kUniformSphere, random, rays);
            Spectrum here[2]{};  // this sample's irradiance estimate, per side
            for (int s : {kUpper, kLower}) {
                for (int b = 0; b < bands; ++b) {
                    here[s][b] += events.irradiance[s][b];
                    tally.direct[s][b] += events.irradiance[s][b];
                }
            }
            for (int b = 0; b < bands; ++b) {
                tally.radianceIntegral[b] += events.radianceIntegral[b];
                tally.radianceMoment[b] += events.radianceMoment[b];
            }
            // Everything else: one direction over the whole sphere, pdf 1/(4π).
            const int j = pairing[i];
            const glm::dvec3 omega = UniformSphere((j % side + random.Uniform()) / side,
                                                   (j / side + random.Uniform()) / side);
            const double cosine = glm::dot(normal, omega);
            const int s = cosine > 0.0 ? kUpper : kLower;
            Spectrum radiance{}, direct{};
            bool escaped = false;
            Incoming(x, omega, random, rays, radiance, direct, escaped);
            for (int b = 0; b < bands; ++b) {
                here[s][b] += 4.0 * kPi * radiance[b] * std::abs(cosine);
                tally.direct[s][b] += 4.0 * kPi * direct[b] * std::abs(cosine);
                tally.radianceIntegral[b] += 4.0 * kPi * radiance[b];
                tally.radianceMoment[b] += 4.0 * kPi * radiance[b] * omega;
            }
            for (int b = 0; b < bands; ++b) {
                tally.irradiance[kUpper][b] += here[kUpper][b];
                tally.irradiance[kLower][b] += here[kLower][b];
            }
            // Escape, for the energy balance: the radiosity this sample estimates for one
            // side (picked with probability 1/2) times whether an independent
            // cosine-weighted direction leaves the scene — unbiased, as the two estimates
            // are independent at the point.
            const int leaving = random.Uniform() < 0.5 ? kUpper : kLower;
            const glm::dvec3 out = CosineHemisphere(leaving == kUpper ? normal : -normal,
                                                    random.Uniform(), random.Uniform());
            ++rays;
            if (rays_.Trace(x, out).fate != RayFate::kHit) {
                const SideOptics& o = optics_[receiverIndex];
                for (int b = 0; b < bands; ++b) {
                    tally.escaping[b] += 2.0 * (o.rho[leaving][b] * here[leaving][b] +
                                                o.tau[1 - leaving][b] * here[1 - leaving][b]);
                }
            }
        }
        for (int b = 0; b < bands; ++b) {
            for (int s : {kUpper, kLower}) {
                tally.irradiance[s][b] /= count;
                tally.direct[s][b] /= count;
            }
            tally.radianceIntegral[b] /= count;
            tally.radianceMoment[b] /= static_cast<double>(count);
            tally.escaping[b] /= count;
        }
        return tally;
    }

  private:
    // The point of the receiver at (u, v) of the unit square, area-preserving: u first
    // picks a triangle by area, and what is left of it places the point inside.
    RayStart PointOn(const Receiver& receiver, double u, double v) const {
        const double target = u * receiver.areaM2;
        const std::uint32_t last = receiver.firstTriangle + receiver.triangleCount - 1;
        std::uint32_t t = receiver.firstTriangle;
        double before = 0.0;
        while (t < last && before + flat_.triangles[t].areaM2 <= target) {
            before += flat_.triangles[t].areaM2;
            ++t;
        }
        const Triangle& tri = flat_.triangles[t];
        const double rest = std::clamp((target - before) / tri.areaM2, 0.0, 1.0);
        const glm::dvec3 w = UniformTriangle(rest, v);
        return {w.x * tri.a + w.y * tri.b + w.z * tri.c, t, 0};
    }

    // Solid-angle pdf with which the path tracer draws `direction` at a point.
    static double DirectionPdf(int sampling, const glm::dvec3& normal,
                               const glm::dvec3& direction) {
        if (sampling == kUniformSphere) return 1.0 / (4.0 * kPi);
        const double cosine = glm::dot(normal, direction) * (sampling == kUpper ? 1.0 : -1.0);
        return std::max(cosine, 0.0) / kPi;
    }

    // Next-event estimation at x (geometric normal `normal`): one sun and one lamp point.
    SourceLight SourceEvents(const RayStart& x, const glm::dvec3& normal, int sampling,
                             Random& random, std::int64_t& rays) const {
        const int bands = lights_.Bands();
        SourceLight light;
        auto add = [&](const glm::dvec3& toward, const Spectrum& radiance, double weight) {
            const double cosine = glm::dot(normal, toward);
            const int s = cosine > 0.0 ? kUpper : kLower;
            for (int b = 0; b < bands; ++b) {
                light.irradiance[s][b] += weight * radiance[b] * std::abs(cosine);
                light.radianceIntegral[b] += weight * radiance[b];
                light.radianceMoment[b] += weight * radiance[b] * toward;
            }
        };
        if (lights_.HasSuns()) {
            Spectrum irradiance{};
            const glm::dvec3 toward = lights_.SampleSun(random, irradiance);
            ++rays;
            if (glm::dot(normal, toward) != 0.0 && !rays_.Occluded(x, toward)) {
                add(toward, irradiance, 1.0);
            }
        }
        if (emitterEvents_) {
            const Lights::EmitterPoint y = lights_.SampleEmitter(flat_, random);
            const glm::dvec3 d = y.point - x.origin;
            const double distance = glm::length(d);
            const glm::dvec3 toward = d / distance;
            const double cosEmitter = -glm::dot(y.normal, toward);
            if (distance > 0.0 && cosEmitter > 0.0) {
                ++rays;
                if (!rays_.Occluded(x, toward, distance * (1.0 - 1e-6))) {
                    const double pdfLight = y.pdfArea * distance * distance / cosEmitter;
                    const double weight =
                        PowerHeuristic(pdfLight, DirectionPdf(sampling, normal, toward)) / pdfLight;
                    Spectrum radiance = *lights_.Exitance(flat_.triangles[y.triangle].receiver);
                    for (int b = 0; b < bands; ++b) radiance[b] /= kPi;
                    add(toward, radiance, weight);
                }
            }
        }
        return light;
    }

    // Radiance arriving at x from omega, the first direction drawn uniformly over the
    // sphere. `direct` gets the part straight from the sky or a lamp; `escaped` tells
    // whether omega leaves the scene.
    void Incoming(RayStart x, glm::dvec3 omega, Random& random, std::int64_t& rays,
                  Spectrum& radiance, Spectrum& direct, bool& escaped) const {
        const int bands = lights_.Bands();
        Spectrum throughput;
        throughput.fill(1.0);
        double pdf = 1.0 / (4.0 * kPi);
        for (int depth = 0; depth < options_.maxDepth; ++depth) {
            ++rays;
            const RayHit hit = rays_.Trace(x, omega);
            if (hit.fate != RayFate::kHit) {
                Spectrum sky;
                lights_.SkyRadiance(omega, sky);
                for (int b = 0; b < bands; ++b) radiance[b] += throughput[b] * sky[b];
                if (depth == 0) direct = sky;
                escaped = depth == 0;
                return;
            }
            const Triangle& tri = flat_.triangles[hit.triangle];
            const int arriving = glm::dot(tri.normal, omega) < 0.0 ? kUpper : kLower;
            if (const Spectrum* exitance = lights_.Exitance(tri.receiver);
                exitance && arriving == kUpper) {
                double weight = 1.0;
                if (emitterEvents_) {
                    const double pdfLight = lights_.PdfArea(hit.triangle) * hit.distance *
                                            hit.distance / -glm::dot(tri.normal, omega);
                    weight = PowerHeuristic(pdf, pdfLight);
                }
                for (int b = 0; b < bands; ++b) {
                    const double emitted = weight * (*exitance)[b] / kPi;
                    radiance[b] += throughput[b] * emitted;
                    if (depth == 0) direct[b] += emitted;
                }
            }
            if (options_.directOnly) return;
            // The radiance leaving the arriving side is (ρ I_arriving + τ I_other) / π,
            // with τ the transmittance from the other side: gather one side's irradiance,
            // chosen with Russian roulette.
            const SideOptics& optics = optics_[tri.receiver];
            double reflect = 0.0, transmit = 0.0;
            for (int b = 0; b < bands; ++b) {
                reflect = std::max(reflect, optics.rho[arriving][b]);
                transmit = std::max(transmit, optics.tau[1 - arriving][b]);
            }
            if (reflect + transmit > kMaxSurvival) {
                const double scale = kMaxSurvival / (reflect + transmit);
                reflect *= scale;
                transmit *= scale;
            }
            const double u = random.Uniform();
            if (u >= reflect + transmit) return;
            const int gather = u < reflect ? arriving : 1 - arriving;
            for (int b = 0; b < bands; ++b) {
                throughput[b] *= gather == arriving ? optics.rho[arriving][b] / reflect
                                                    : optics.tau[1 - arriving][b] / transmit;
            }
            // radiance += throughput · E_direct(gather side) / π, then continue with a
            // cosine-weighted direction: its π L estimate of the rest cancels the 1/π.
            x = hit.next;
            const SourceLight events = SourceEvents(x, tri.normal, gather, random, rays);
            for (int b = 0; b < bands; ++b) {
                radiance[b] += throughput[b] * events.irradiance[gather][b] / kPi;
            }
            const glm::dvec3 normal = gather == kUpper ? tri.normal : -tri.normal;
            omega = CosineHemisphere(normal, random.Uniform(), random.Uniform());
            pdf = glm::dot(omega, normal) / kPi;
        }
    }

    const FlatScene& flat_;
    const RayScene& rays_;
    const ReferenceOptions& options_;
    Lights lights_;
    std::vector<SideOptics> optics_;
    bool emitterEvents_ = false;
};

// Mean and standard error of the replicate values.
struct Estimate {
    double mean = 0.0, error = 0.0;
};
Estimate Combine(const std::vector<double>& values) {
    const double n = static_cast<double>(values.size());
    Estimate e;
    for (double v : values) e.mean += v / n;
    double squares = 0.0;
    for (double v : values) squares += (v - e.mean) * (v - e.mean);
    e.error = n > 1.0 ? std::sqrt(squares / (n - 1.0) / n) : 0.0;
    return e;
}

Solution SolveGroup(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                    const ReferenceOptions& options) {
    LEAFLUX_CHECK(options.replicates >= 2);
    LEAFLUX_CHECK(scene.bands.size() <= static_cast<std::size_t>(kBandGroup));
    const ResourceClock clock;
    const int bands = static_cast<int>(scene.bands.size());
    const auto receivers = static_cast<std::uint32_t>(flat.receivers.size());
    const int perReplicate =
        std::max(1, (options.samplesPerReceiver + options.replicates - 1) / options.replicates);

    PathTracer tracer(scene, flat, rays, options);
    Solution solution;
    solution.light.assign(receivers, bands);
    solution.error.assign(receivers, bands);
    // Per receiver and band: incident − absorbed − escaped of each replicate, for the
    // standard error of the balance; the sums are made in receiver order afterwards.
    std::vector<std::array<Estimate, kBandGroup>> incident(receivers), absorbed(receivers),
        escaped(receivers), residual(receivers);
    std::atomic<std::int64_t> rayCount{0};
    std::atomic<std::uint32_t> done{0};
    std::mutex progressMutex;
    int reported = 0;

    const int threads = CoresOf(options.threads);
    const auto solved =
        options.only.empty() ? receivers : static_cast<std::uint32_t>(options.only.size());
    for (std::uint32_t r : options.only) LEAFLUX_CHECK(r < receivers);
    OnCores(threads, [&] {
        tbb::parallel_for(std::uint32_t{0}, solved, [&](std::uint32_t i) {
            SetFlushToZero();
            const std::uint32_t r = options.only.empty() ? i : options.only[i];
            const Receiver& receiver = flat.receivers[r];
            const SideOptics& optics = tracer.Optics(r);
            std::int64_t receiverRays = 0;
            std::vector<std::array<std::vector<double>, 6>> series(bands);
            std::vector<Tally> tallies;
            for (int k = 0; k < options.replicates; ++k) {
                tallies.push_back(tracer.Replicate(r, perReplicate, StreamSeed(options.seed, r, k),
                                                   receiverRays));
            }
            for (int b = 0; b < bands; ++b) {
                auto& [upper, lower, absorb, in, out, rest] = series[b];
                BandLight& light = solution.light[r][b];
                for (const Tally& t : tallies) {
                    double absorbedW = 0.0, incidentW = 0.0;
                    for (int s : {kUpper, kLower}) {
                        absorbedW +=
                            (1.0 - optics.rho[s][b] - optics.tau[s][b]) * t.irradiance[s][b];
                        incidentW += t.direct[s][b];
                    }
                    const double escapedW = t.escaping[b];
                    upper.push_back(t.irradiance[kUpper][b]);
                    lower.push_back(t.irradiance[kLower][b]);
                    absorb.push_back(absorbedW * receiver.areaM2);
                    in.push_back(incidentW * receiver.areaM2);
                    out.push_back(escapedW * receiver.areaM2);
                    rest.push_back((incidentW - absorbedW - escapedW) * receiver.areaM2);
                    light.radianceIntegral += t.radianceIntegral[b] / options.replicates;
                    light.radianceMoment +=
                        t.radianceMoment[b] / static_cast<double>(options.replicates);
                }
                const Estimate up = Combine(upper), low = Combine(lower), abs = Combine(absorb);
                light.irradianceUpperWm2 = up.mean;
                light.irradianceLowerWm2 = low.mean;
                light.absorbedW = abs.mean;
                solution.error[r][b] = {up.error, low.error, abs.error};
                incident[r][b] = Combine(in);
                absorbed[r][b] = abs;
                escaped[r][b] = Combine(out);
                residual[r][b] = Combine(rest);
            }
            rayCount += receiverRays;
            const std::uint32_t finished = ++done;
            if (options.progress) {
                const int percent = static_cast<int>(100.0 * finished / solved);
                std::lock_guard lock(progressMutex);
                if (percent > reported) {
                    reported = percent;
                    options.progress(finished / static_cast<double>(solved));
                }
            }
        });
    });

    solution.balance.assign(bands, EnergyBalance{});
    for (int b = 0; b < bands; ++b) {
        EnergyBalance& balance = solution.balance[b];
        double variance = 0.0;
        for (std::uint32_t r = 0; r < receivers; ++r) {
            balance.incidentW += incident[r][b].mean;
            balance.absorbedW += absorbed[r][b].mean;
            balance.escapedW += escaped[r][b].mean;
            variance += residual[r][b].error * residual[r][b].error;
        }
        balance.stderrW = std::sqrt(variance);
    }
    clock.Stamp(solution.stats);
    solution.stats.rays = rayCount;
    solution.stats.threads = threads;
    return solution;
}

}  // namespace

// Bands never mix: a scene of more bands than a path carries is solved a group at a time,
// each group's paths as a scene of those bands alone would take them (the same seed).
Solution SolveReference(const Scene& scene, const FlatScene& flat, const RayScene& rays,
                        const ReferenceOptions& options) {
    const int bands = static_cast<int>(scene.bands.size());
    if (bands <= kBandGroup) return SolveGroup(scene, flat, rays, options);
    const ResourceClock clock;
    Solution solution;
    solution.light.assign(flat.receivers.size(), bands);
    solution.error.assign(flat.receivers.size(), bands);
    for (int first = 0; first < bands; first += kBandGroup) {
        std::vector<int> group;
        for (int b = first; b < std::min(bands, first + kBandGroup); ++b) group.push_back(b);
        const Solution part = SolveGroup(WithBands(scene, group), flat, rays, options);
        for (std::size_t r = 0; r < part.light.size(); ++r) {
            std::ranges::copy(part.light[r], solution.light[r].begin() + first);
            std::ranges::copy(part.error[r], solution.error[r].begin() + first);
        }
        solution.balance.insert(solution.balance.end(), part.balance.begin(), part.balance.end());
        solution.stats.rays += part.stats.rays;
        solution.stats.threads = part.stats.threads;
    }
    clock.Stamp(solution.stats);
    return solution;
}

}  // namespace leaflux
