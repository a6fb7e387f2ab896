// Pictures of a solution (paper Fig. 13, 16, 20): primary rays through the ray engine,
// several a pixel (anti-aliased), on every core; each surface they hit drawn in the false
// colour of the quantity asked (or in true colour from three bands), and a colour bar below
// the view naming it; a scale bar and a north arrow over the view when asked.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "solver/raytrace/raytrace.h"
#include "solver/render/camera.h"
#include "solver/render/colour_scale.h"
#include "solver/render/image.h"
#include "solver/render/overlay.h"
#include "solver/results/light.h"
#include "solver/scene/scene.h"

namespace leaflux {

enum class Quantity {
    kIrradiance,  // arriving on the side(s) asked, W/m²
    kAbsorbed,    // absorbed power per area of the organ, both sides, W/m²
    kRadiosity,   // leaving the side(s) asked: ρ E on that side + τ E from the other, W/m²
    kTrueColour,  // the radiosity of three bands (RenderSettings::rgb) as red, green, blue
};

enum class Side {
    kSeenSide,  // the side facing the camera
    kUpperSide,
    kLowerSide,
    kBothSides,  // an organ's two summed (the error tables' value of a leaf); an
                 // environment surface's seen side (its sides face two spaces)
};

struct RenderSettings {
    Camera camera;
    int width = 1024, height = 768;  // the view; the colour bar comes below it
    int samples = 4;                 // rays a pixel, on a stratified grid (rounded to a square)
    Quantity quantity = Quantity::kIrradiance;
    Side side = Side::kSeenSide;
    int band = 0;
    // kTrueColour: the bands shown red, green and blue, each channel linear on one scale
    // (equal radiosities are grey; the colour bar is the grey scale of one channel).
    std::array<int, 3> rgb{0, 0, 0};
    bool photons = false;  // in µmol m⁻² s⁻¹ (the band's photon factor) rather than W/m²
    // The scale: from 0 to the largest value in view, unless given (a series of pictures
    // sharing one scale); values beyond a given range are hatched.
    std::optional<std::pair<double, double>> range;
    Palette palette = Palette::kViridis;  // kTrueColour: grey, always
    bool scaleBar = false;                // a round length at the look point's distance
    bool northArrow = false;              // towards +y
    int threads = 0;                      // 0: every core
};

struct Rendering {
    Image image;        // the view, with the colour bar below it
    ColourScale scale;  // the one the view was drawn on
    std::string caption;
    int barLeft = 0, barRight = 0, barTop = 0, barBottom = 0;  // the bar's pixels, inclusive
    std::int64_t rays = 0;
    double beyondFraction = 0.0;  // of the samples on surfaces, those beyond the scale
    double seconds = 0.0;
    ScaleBar scaleBar;  // when asked

    // The bar's column showing `value`.
    int BarColumn(double value) const;
};

// Checks the settings against the scene (band, photon factor, size, range); the error
// names the setting.
void Validate(const RenderSettings& settings, const Scene& scene);

// `solution` is the one solved on rays.Flat() (its receivers), as every solver returns.
Rendering Render(const Scene& scene, const RayScene& rays, const Solution& solution,
                 const RenderSettings& settings);

}  // namespace leaflux
