#include "solver/render/colour_scale.h"

#include <algorithm>
#include <cmath>

namespace leaflux {
namespace {

// matplotlib's viridis at eight evenly spaced points, interpolated linearly between them.
constexpr Rgb kViridis[] = {{68, 1, 84},    {70, 51, 126},  {54, 92, 141},  {39, 127, 142},
                            {31, 161, 135}, {74, 193, 109}, {159, 218, 58}, {253, 231, 37}};

bool Stripe(int x, int y) { return (x + y) / 3 % 2 == 0; }

}  // namespace

Rgb ColourScale::AtFraction(double t) const {
    t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0);
    if (palette == Palette::kGrey) {
        const auto v = static_cast<std::uint8_t>(std::lround(255.0 * t));
        return {v, v, v};
    }
    constexpr int kLast = static_cast<int>(std::size(kViridis)) - 1;
    const double at = t * kLast;
    const int k = std::min(static_cast<int>(at), kLast - 1);
    const double w = at - k;
    const Rgb &a = kViridis[k], &b = kViridis[k + 1];
    const auto mix = [w](std::uint8_t u, std::uint8_t v) {
        return static_cast<std::uint8_t>(std::lround((1.0 - w) * u + w * v));
    };
    return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

Rgb ColourScale::Of(double value, int x, int y) const {
    if (value > max) return Stripe(x, y) ? AtFraction(1.0) : Rgb{0, 0, 0};
    if (value < min) return Stripe(x, y) ? AtFraction(0.0) : Rgb{255, 255, 255};
    return AtFraction(max > min ? (value - min) / (max - min) : 0.0);
}

}  // namespace leaflux
