// Units of light as users give them: PAR as a photon flux (µmol m⁻² s⁻¹) beside W/m², and
// the source values that are valid but look like a mistake of unit or of position — a
// photon flux given as W/m², a sun below the horizon. Those are warnings, not errors: a
// scene may mean them (a lamp-lit test bench, a low sun through a window).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "solver/scene/scene.h"

namespace leaflux {

// Photons per joule of daylight PAR (µmol J⁻¹): McCree 1972, "Test of current definitions
// of photosynthetically active radiation against leaf photosynthesis data", Agric.
// Meteorol. 10:443; the factor of the solar spectrum's 400–700 nm part.
inline constexpr double kDaylightParUmolPerJ = 4.57;

// The largest photons-per-joule factor a band may declare: 1000 µmol J⁻¹ is light of
// 120 µm, far beyond any band a plant's light is counted in.
inline constexpr double kMaxPhotonUmolPerJ = 1000.0;

// The whole solar spectrum above the atmosphere (W/m² on a plane facing the sun; Kopp and
// Lean 2011), and its 400–700 nm part (about 38 %). No sun or sky band can bring more.
inline constexpr double kSolarConstantWm2 = 1361.0;
inline constexpr double kSolarConstantParWm2 = 530.0;

// Whether a band is PAR: named "PAR" (in any case), or declared as 400–700 nm.
bool IsParBand(const Band& band);

// The band's photons per joule (µmol J⁻¹): its own factor when it gives one, else
// kDaylightParUmolPerJ for a PAR band; none for any other band.
std::optional<double> PhotonUmolPerJ(const Band& band);

// A sun that lights the scene from below the horizon, or whose irradiance in some band is
// more than the sun brings above the atmosphere (a photon flux given as W/m², as often as
// not). `field` names the sun in the messages ("suns[2]").
std::vector<std::string> SunWarnings(const Scene& scene, const Sun& sun, const std::string& field);

// Per-band source values (W/m², scene band order) more than the sun brings above the
// atmosphere in that band; `field` names them ("sky.horizontal_irradiance").
std::vector<std::string> IrradianceWarnings(const Scene& scene,
                                            const std::vector<double>& irradianceWm2,
                                            const std::string& field);

}  // namespace leaflux
