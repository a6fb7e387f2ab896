// The colour bar below a rendered view: the quantity's caption, the bar with ticks at round
// values, and, when values in view lie beyond the scale, hatched boxes at its ends.
#pragma once

#include <string>
#include <vector>

#include "solver/render/colour_scale.h"
#include "solver/render/image.h"

namespace leaflux {

struct Legend {
    Image image;                               // the view, the legend's panel below it
    int barLeft, barRight, barTop, barBottom;  // the bar's pixels, inclusive
};

Legend DrawLegend(const Image& view, const ColourScale& scale, const std::string& caption,
                  bool beyond);

// Round tick values within [min, max], about `count` of them (steps of 1, 2 or 5 × 10^k).
std::vector<double> Ticks(double min, double max, int count);

}  // namespace leaflux
