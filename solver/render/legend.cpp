#include "solver/render/legend.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "solver/render/font.h"

namespace leaflux {
namespace {

constexpr Rgb kPaper{255, 255, 255};
constexpr Rgb kInk{30, 30, 30};

std::string Label(double value, double step) {
    char text[32];
    const double magnitude = std::max(std::abs(value), step);
    if (magnitude >= 1e5 || magnitude < 1e-3) {
        std::snprintf(text, sizeof text, "%.2g", value);
    } else {
        const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
        std::snprintf(text, sizeof text, "%.*f", decimals, value);
    }
    return text;
}

}  // namespace

std::vector<double> Ticks(double min, double max, int count) {
    const double raw = (max - min) / std::max(count, 1);
    const double power = std::pow(10.0, std::floor(std::log10(raw)));
    double step = 10.0 * power;
    for (double m : {1.0, 2.0, 5.0})
        if (m * power >= raw) {
            step = m * power;
            break;
        }
    std::vector<double> ticks;
    for (double k = std::ceil(min / step - 1e-9); k * step <= max + 1e-9 * step; ++k)
        ticks.push_back(std::abs(k) < 0.5 ? 0.0 : k * step);
    return ticks;
}

Legend DrawLegend(const Image& view, const ColourScale& scale, const std::string& caption,
                  bool beyond) {
    const int s = view.Width() >= 1600 ? 2 : 1;  // text and marks grow with large pictures
    const int margin = 12 * s, box = beyond ? 14 * s : 0, gap = beyond ? 4 * s : 0;
    const int panel = 48 * s;
    Legend legend{Image(view.Width(), view.Height() + panel, kPaper), 0, 0, 0, 0};
    legend.image.Paste(view, 0, 0);
    const int top = view.Height();
    DrawText(legend.image, margin, top + 4 * s, caption, kInk, s);

    legend.barLeft = margin + box + gap;
    legend.barRight = view.Width() - 1 - margin - box - gap;
    legend.barTop = top + 16 * s;
    legend.barBottom = legend.barTop + 12 * s - 1;
    for (int x = legend.barLeft; x <= legend.barRight; ++x) {
        const double t =
            static_cast<double>(x - legend.barLeft) / (legend.barRight - legend.barLeft);
        for (int y = legend.barTop; y <= legend.barBottom; ++y)
            legend.image.At(x, y) = scale.AtFraction(t);
    }
    if (beyond) {  // the hatching of values beyond the scale, below and above
        const int boxes[2][2] = {{margin, margin + box - 1},
                                 {legend.barRight + gap + 1, legend.barRight + gap + box}};
        const double values[2] = {scale.min - 1.0 - std::abs(scale.min),
                                  scale.max + 1.0 + std::abs(scale.max)};
        for (int e = 0; e < 2; ++e)
            for (int x = boxes[e][0]; x <= boxes[e][1]; ++x)
                for (int y = legend.barTop; y <= legend.barBottom; ++y)
                    legend.image.At(x, y) = scale.Of(values[e], x, y);
    }

    const int width = std::max(1, TextWidth("0.000", s));
    const int count = std::clamp((legend.barRight - legend.barLeft) / (3 * width), 2, 8);
    const std::vector<double> ticks = Ticks(scale.min, scale.max, count);
    const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : scale.max - scale.min;
    for (double value : ticks) {
        const double t = (value - scale.min) / (scale.max - scale.min);
        const int x =
            legend.barLeft + static_cast<int>(std::lround(t * (legend.barRight - legend.barLeft)));
        for (int y = legend.barBottom + 1; y <= legend.barBottom + 3 * s; ++y)
            for (int dx = 0; dx < s; ++dx) legend.image.Set(x + dx, y, kInk);
        const std::string label = Label(value, step);
        const int left =
            std::clamp(x - TextWidth(label, s) / 2, 0, view.Width() - TextWidth(label, s));
        DrawText(legend.image, left, legend.barBottom + 5 * s, label, kInk, s);
    }
    return legend;
}

}  // namespace leaflux
