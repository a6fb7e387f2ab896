#include "solver/instancing/phase_photons.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numbers>

#include "solver/util/check.h"
#include "solver/util/sampling.h"

namespace leaflux {
namespace {
constexpr double kFourPi = 4.0 * std::numbers::pi;
// The Russian roulette's survival is capped below one, so that a path among leaves of
// ρ + τ → 1 ends (as the reference solver's).
constexpr double kMaxSurvival = 0.995;

// Per receiver and arriving side: the reflectance back to that side and the
// transmittance through to the other, per band.
struct SideOptics {
    std::vector<double> rho[2], tau[2];
};

std::vector<SideOptics> OpticsOfReceivers(const StructureAlone& structure) {
    const Scene& scene = structure.Alone();
    std::vector<SideOptics> optics;
    for (const Receiver& receiver : structure.Flat().receivers) {
        SideOptics o;
        for (int s = 0; s < 2; ++s) {
            o.rho[s].assign(scene.bands.size(), 0.0);
            o.tau[s].assign(scene.bands.size(), 0.0);
        }
        if (receiver.optics >= 0) {
            const auto& bands = scene.optics[receiver.optics].bands;
            for (std::size_t b = 0; b < bands.size(); ++b) {
                o.rho[0][b] = bands[b].rhoUpper;
                o.rho[1][b] = bands[b].rhoLower;
                o.tau[0][b] = bands[b].tauUpperToLower;
                o.tau[1][b] = bands[b].tauLowerToUpper;
            }
        }
        optics.push_back(std::move(o));
    }
    return optics;
}

// The mean and standard error of replicate estimates.
void MeanAndError(const double* groups, int count, double& mean, double& error) {
    mean = 0.0;
    for (int g = 0; g < count; ++g) mean += groups[g];
    mean /= count;
    double spread = 0.0;
    for (int g = 0; g < count; ++g) spread += (groups[g] - mean) * (groups[g] - mean);
    error = std::sqrt(spread / (count * (count - 1.0)));
}

// Directions drawn with density hat_v(ω) / ∫hat_v: uniform in the cap round v that holds
// the faces around it (the whole sphere when they reach past a hemisphere), kept with
// probability v's interpolation weight there.
class HatSampler {
  public:
    explicit HatSampler(const DirectionSet& set) : set_(set), capCosine_(set.Size(), 1.0) {
        for (const auto& face : set.Faces()) {
            for (int k = 0; k < 3; ++k) {
                for (int j = 0; j < 3; ++j) {
                    double& cap = capCosine_[face[k]];
                    cap = std::min(cap, glm::dot(set.Direction(face[k]), set.Direction(face[j])));
                }
            }
        }
        for (double& cap : capCosine_) cap = cap > 0.0 ? cap : -1.0;
    }
    glm::dvec3 Sample(int v, Random& random) const {
        for (;;) {
            const glm::dvec3 d =
                UniformCone(set_.Direction(v), capCosine_[v], random.Uniform(), random.Uniform());
            const DirectionSet::Interpolation at = set_.Locate(d);
            for (int k = 0; k < 3; ++k) {
                if (at.vertex[k] == v && random.Uniform() < at.weight[k]) return d;
            }
        }
    }

  private:
    const DirectionSet& set_;
    std::vector<double> capCosine_;
};

class BeamTracer {
  public:
    BeamTracer(const StructureAlone& structure, const PhotonOptions& options)
        : structure_(structure),
          options_(options),
          optics_(OpticsOfReceivers(structure)),
          bands_(static_cast<int>(structure.Alone().bands.size())),
          outgoing_(options.kind == PhaseKind::kBiDirectional
                        ? DirectionSet::OfLevel(options.level).Size()
                        : 0),
          incoming_(DirectionSet::OfLevel(options.level)) {}

    // Beam i: fills its balance, and its row of f and of the errors (per outgoing
    // direction and band; empty unless bi-directional).
    void Trace(int i, BeamBalance& balance, float* row, float* errorRow) {
        SetFlushToZero();
        const DirectionSet& set = DirectionSet::OfLevel(options_.level);
        const int groups = options_.replicates, n = options_.photonsPerBeam;
        // Tallies per replicate group: [group][outgoing][band], and [group][band] of the
        // scattered, intercepted and absorbed weights.
        std::vector<double> tally(static_cast<std::size_t>(groups) * outgoing_ * bands_, 0.0);
        std::vector<double> scattered(groups * bands_, 0.0), absorbed(groups * bands_, 0.0),
            intercepted(groups * bands_, 0.0);
        double entered = 0.0, transmitted = 0.0;
        std::int64_t rays = 0;
        Random random(StreamSeed(options_.seed, 0x9f, static_cast<std::uint64_t>(i)));
        std::vector<double> weight(bands_);
        for (int p = 0; p < n; ++p) {
            const int group = p % groups;
            // A photon carries the box's cross-section along its direction: the power of a
            // unit irradiance on the box.
            const glm::dvec3 along =
                options_.hatIncoming ? -incoming_.Sample(i, random) : -set.Direction(i);
            const double area = structure_.ProjectedArea(along);
            entered += area;
            RayStart start{structure_.Entry(along, (p + random.Uniform()) / n, random.Uniform(),
                                            random.Uniform())};
            glm::dvec3 direction = along;
            std::fill(weight.begin(), weight.end(), area);
            bool met = false;
            for (;;) {
                const RayHit hit = structure_.Rays().Trace(start, direction);
                ++rays;
                if (hit.fate != RayFate::kHit) {
                    if (met) Escape(direction, weight, group, tally, scattered);
                    if (!met) transmitted += area;
                    break;
                }
                if (!met) {
                    for (int b = 0; b < bands_; ++b) intercepted[group * bands_ + b] += area;
                }
                met = true;
                const Triangle& triangle = structure_.Flat().triangles[hit.triangle];
                const int arriving = glm::dot(triangle.normal, direction) < 0.0 ? 0 : 1;
                const SideOptics& optics = optics_[triangle.receiver];
                double reflect = 0.0, transmit = 0.0;
                for (int b = 0; b < bands_; ++b) {
                    absorbed[group * bands_ + b] +=
                        weight[b] * (1.0 - optics.rho[arriving][b] - optics.tau[arriving][b]);
                    reflect = std::max(reflect, optics.rho[arriving][b]);
                    transmit = std::max(transmit, optics.tau[arriving][b]);
                }
                if (reflect + transmit > kMaxSurvival) {
                    const double scale = kMaxSurvival / (reflect + transmit);
                    reflect *= scale;
                    transmit *= scale;
                }
                const double u = random.Uniform();
                if (u >= reflect + transmit) break;
                const bool back = u < reflect;
                for (int b = 0; b < bands_; ++b) {
                    weight[b] *= back ? optics.rho[arriving][b] / reflect
                                      : optics.tau[arriving][b] / transmit;
                }
                const glm::dvec3 facing = arriving == 0 ? triangle.normal : -triangle.normal;
                direction =
                    CosineHemisphere(back ? facing : -facing, random.Uniform(), random.Uniform());
                start = hit.next;
            }
        }
        rays_ += rays;
        // Each photon is 1/N of the beam; a group's photons, 1/(N/groups).
        const double photon = 1.0 / n, groupPhoton = photon * groups;
        balance.enteredW = entered * photon;
        balance.transmittedW = transmitted * photon;
        for (auto* v : {&balance.interceptedW, &balance.scatteredW, &balance.absorbedW,
                        &balance.scatteredErrorW, &balance.closureErrorW})
            v->assign(bands_, 0.0);
        std::vector<double> estimates(groups), residuals(groups);
        for (int b = 0; b < bands_; ++b) {
            for (int g = 0; g < groups; ++g) {
                const int k = g * bands_ + b;
                balance.interceptedW[b] += intercepted[k] * photon;
                balance.absorbedW[b] += absorbed[k] * photon;
                estimates[g] = scattered[k] * groupPhoton;
                residuals[g] = (intercepted[k] - scattered[k] - absorbed[k]) * groupPhoton;
            }
            MeanAndError(estimates.data(), groups, balance.scatteredW[b],
                         balance.scatteredErrorW[b]);
            double residual;
            MeanAndError(residuals.data(), groups, residual, balance.closureErrorW[b]);
        }
        for (int o = 0; o < outgoing_; ++o) {
            const double perSr = groupPhoton / set.HatIntegralSr(o);
            for (int b = 0; b < bands_; ++b) {
                for (int g = 0; g < groups; ++g)
                    estimates[g] =
                        tally[(static_cast<std::size_t>(g) * outgoing_ + o) * bands_ + b] * perSr;
                double mean, error;
                MeanAndError(estimates.data(), groups, mean, error);
                row[o * bands_ + b] = static_cast<float>(mean);
                errorRow[o * bands_ + b] = static_cast<float>(error);
            }
        }
    }

    std::int64_t Rays() const { return rays_; }

  private:
    void Escape(const glm::dvec3& direction, const std::vector<double>& weight, int group,
                std::vector<double>& tally, std::vector<double>& scattered) const {
        for (int b = 0; b < bands_; ++b) scattered[group * bands_ + b] += weight[b];
        if (outgoing_ == 0) return;
        const DirectionSet::Interpolation at =
            DirectionSet::OfLevel(options_.level).Locate(direction);
        for (int k = 0; k < 3; ++k) {
            double* cell =
                &tally[(static_cast<std::size_t>(group) * outgoing_ + at.vertex[k]) * bands_];
            for (int b = 0; b < bands_; ++b) cell[b] += at.weight[k] * weight[b];
        }
    }

    const StructureAlone& structure_;
    const PhotonOptions& options_;
    const std::vector<SideOptics> optics_;
    const int bands_;
    const int outgoing_;
    const HatSampler incoming_;
    std::atomic<std::int64_t> rays_{0};
};
}  // namespace

PhaseEstimate PhaseFromPhotons(const StructureAlone& structure, const PhotonOptions& options) {
    LEAFLUX_CHECK(options.photonsPerBeam >= options.replicates && options.replicates >= 2);
    const auto start = std::chrono::steady_clock::now();
    const int bands = static_cast<int>(structure.Alone().bands.size());
    const DirectionSet& set = DirectionSet::OfLevel(options.level);
    const int n = set.Size();
    PhaseEstimate estimate;
    estimate.phase = PhaseFunction(options.kind, options.level, bands);
    estimate.standardError = PhaseFunction(options.kind, options.level, bands);
    estimate.beams.resize(n);
    BeamTracer tracer(structure, options);
    const bool bi = options.kind == PhaseKind::kBiDirectional;
    const std::size_t rowSize = bi ? static_cast<std::size_t>(n) * bands : 0;
    float* values = estimate.phase.MutableValues().data();
    float* errors = estimate.standardError.MutableValues().data();
    tbb::parallel_for(0, n, [&](int i) {
        tracer.Trace(i, estimate.beams[i], bi ? values + i * rowSize : nullptr,
                     bi ? errors + i * rowSize : nullptr);
    });
    if (!bi) {
        // Scattered evenly over 4π: per incoming direction, or its mean over them.
        for (int b = 0; b < bands; ++b) {
            double mean = 0.0, meanError = 0.0;
            for (int i = 0; i < n; ++i) {
                const BeamBalance& beam = estimate.beams[i];
                const double value = beam.scatteredW[b] / kFourPi;
                const double error = beam.scatteredErrorW[b] / kFourPi;
                const double share = set.HatIntegralSr(i) / kFourPi;
                mean += share * value;
                meanError += share * share * error * error;
                if (options.kind == PhaseKind::kMonoDirectional) {
                    values[i * bands + b] = static_cast<float>(value);
                    errors[i * bands + b] = static_cast<float>(error);
                }
            }
            if (options.kind == PhaseKind::kConstant) {
                values[b] = static_cast<float>(mean);
                errors[b] = static_cast<float>(std::sqrt(meanError));
            }
        }
    }
    estimate.rays = tracer.Rays();
    estimate.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return estimate;
}

}  // namespace leaflux
