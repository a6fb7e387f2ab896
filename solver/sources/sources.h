// Light sources (Soler 2003 §5): directional suns, a sky of given radiance distribution,
// optionally discretised into cones, and local diffuse emitters (lamps, bright windows).
// All per-band values are in scene band order. World frame: x east, y north, z up.
#pragma once

#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

namespace leaflux {

struct Mesh;

// A sun, possibly one of several weighted positions over a period.
struct Sun {
    glm::dvec3 towardSun{0.0, 0.0, 1.0};      // unit vector from the scene to the sun
    std::vector<double> normalIrradianceWm2;  // on a plane facing the sun, per band
    double angularRadiusRad = 0.0;            // 0: a point source, hard shadows
};

struct SolarAngles {
    double elevationRad;  // above the horizon
    double azimuthRad;    // from north, clockwise (east = π/2)
};

// Solar position from latitude, day of year (1..366) and local apparent solar time (h).
// Declination from Spencer (1971), "Fourier series representation of the position of the
// sun", Search 2(5):172; hour angle 15° per hour from solar noon.
SolarAngles SolarPosition(double latitudeDeg, int dayOfYear, double solarTimeH);
glm::dvec3 DirectionFromAngles(const SolarAngles& angles);

// The suns of a period: one per step, each with normalIrradiance · step / duration, the
// positions below the horizon left out.
std::vector<Sun> SunPositionsOverPeriod(double latitudeDeg, int dayOfYear, double startH,
                                        double endH, double stepH,
                                        const std::vector<double>& normalIrradianceWm2);

enum class SkyModel { kUniform, kCieOvercast };

enum class SkyDiscretization { kContinuous, kTurtle46, kTetra34, kTetra130, kTetra514 };

// A cone of the discretised sky: a directional source of solid angle `solidAngleSr`
// around `direction`, of uniform radiance inside the cone.
struct SkyCone {
    glm::dvec3 direction;
    double solidAngleSr;
    std::vector<double> radianceWm2Sr;  // per band
};

struct Sky {
    SkyModel model = SkyModel::kUniform;
    std::vector<double> horizontalIrradianceWm2;  // diffuse, on a horizontal plane, per band
    SkyDiscretization discretization = SkyDiscretization::kContinuous;

    // Radiance (W m⁻² sr⁻¹) of band `band` arriving from direction `towardSky` (z > 0),
    // normalised so that ∫ L cos θ dω over the upper hemisphere is the horizontal irradiance.
    double Radiance(int band, const glm::dvec3& towardSky) const;

    // The cones of `discretization` (empty when continuous): each a cap of its cell's solid
    // angle around the cell's centroid, of uniform radiance inside. The radiance is the
    // model's mean over the cell, renormalised so that the caps — with the part of a cap
    // below the horizon folded above it — give the horizontal irradiance exactly: the
    // discretisation moves light between directions, it neither adds nor removes any.
    std::vector<SkyCone> Cones() const;
};

// Directions and solid angles of the sky cells of a discretisation (upper hemisphere only).
struct SkyCell {
    glm::dvec3 direction;
    double solidAngleSr;
};
std::vector<SkyCell> SkyCells(SkyDiscretization discretization);

// A lamp or bright window: emits diffusely from the upper side of its triangles.
struct Emitter {
    std::string name;
    std::shared_ptr<const Mesh> mesh;  // world coordinates
    std::vector<double> exitanceWm2;   // per band
    std::string opticsId;              // empty: black (absorbs all it receives)
    // A surface outside a local problem, its radiosity held (ReceiverKind::kHeld).
    bool held = false;
    // Held, pieces of a black lamp: its light is its exitance, even over each (NodeModel::Lamp).
    bool lamp = false;
    // Held: per triangle of the mesh, per band, what each sends (empty: exitanceWm2 all over).
    std::vector<double> triangleExitanceWm2{};

    // What triangle t of the mesh sends in band b (W/m²).
    double Exitance(std::size_t t, std::size_t b) const {
        return triangleExitanceWm2.empty() ? exitanceWm2[b]
                                           : triangleExitanceWm2[t * exitanceWm2.size() + b];
    }
};

struct Sources {
    std::vector<Sun> suns;
    std::vector<Sky> skies;  // zero or one in practice; several add up
    std::vector<Emitter> emitters;

    bool Empty() const { return suns.empty() && skies.empty() && emitters.empty(); }
};

}  // namespace leaflux
