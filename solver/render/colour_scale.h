// False colour: a value's colour on a scale from min to max, values beyond it marked.
#pragma once

#include "solver/render/image.h"

namespace leaflux {

enum class Palette {
    kViridis,  // perceptually uniform, readable in grey and by colour-blind readers
    kGrey,     // black to white, linear in the value: pixel ratios are value ratios
};

struct ColourScale {
    double min = 0.0, max = 1.0;
    Palette palette = Palette::kViridis;

    // The colour at fraction t of the scale (clamped to [0, 1]).
    Rgb AtFraction(double t) const;
    // The colour of `value`. Beyond the scale it is hatched, so that a cut-off value is not
    // read as the end of the scale: above max, diagonal stripes of the top colour and black;
    // below min, of the bottom colour and white. (x, y): the pixel, for the stripes.
    Rgb Of(double value, int x, int y) const;
    bool Beyond(double value) const { return value > max || value < min; }
};

}  // namespace leaflux
