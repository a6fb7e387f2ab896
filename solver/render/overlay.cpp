#include "solver/render/overlay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "solver/render/font.h"

namespace leaflux {
namespace {

constexpr Rgb kInk{20, 20, 20};
constexpr Rgb kHalo{255, 255, 255};

// Marks grow with large pictures, as the legend's do.
int MarkScale(const Image& image) { return image.Width() >= 1600 ? 2 : 1; }

void FillBox(Image& image, int x0, int y0, int x1, int y1, Rgb colour) {
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) image.Set(x, y, colour);
}

// A line `thickness` pixels wide from a to b.
void DrawLine(Image& image, glm::dvec2 a, glm::dvec2 b, int thickness, Rgb colour) {
    const int steps = static_cast<int>(std::ceil(glm::length(b - a))) + 1;
    for (int i = 0; i <= steps; ++i) {
        const glm::dvec2 p = a + (b - a) * (static_cast<double>(i) / steps);
        const int x = static_cast<int>(std::lround(p.x)), y = static_cast<int>(std::lround(p.y));
        FillBox(image, x - thickness / 2, y - thickness / 2, x + (thickness - 1) / 2,
                y + (thickness - 1) / 2, colour);
    }
}

// Text with a one-pixel light halo, readable on any colour of the view.
void HaloText(Image& image, int x, int y, const std::string& text, int s) {
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            if (dx != 0 || dy != 0) DrawText(image, x + dx * s, y + dy * s, text, kHalo, s);
    DrawText(image, x, y, text, kInk, s);
}

std::string Metres(double metres) {
    char text[32];
    if (metres >= 1.0)
        std::snprintf(text, sizeof text, "%g m", metres);
    else if (metres >= 0.01)
        std::snprintf(text, sizeof text, "%g cm", metres * 100.0);
    else
        std::snprintf(text, sizeof text, "%g mm", metres * 1000.0);
    return text;
}

}  // namespace

ScaleBar ScaleBarOf(const Camera& camera, const View& view, int width) {
    const double perMetre = view.PixelsPerMetre(glm::length(camera.look - camera.eye));
    const double wanted = 0.2 * width / perMetre;  // metres in a fifth of the width
    const double power = std::pow(10.0, std::floor(std::log10(wanted)));
    double metres = power;
    for (double m : {2.0, 5.0, 10.0})
        if (m * power <= wanted) metres = m * power;
    return {metres, static_cast<int>(std::lround(metres * perMetre))};
}

void DrawScaleBar(Image& image, const ScaleBar& bar) {
    const int s = MarkScale(image);
    const int left = 12 * s, bottom = image.Height() - 12 * s;
    const int top = bottom - 4 * s + 1, right = left + bar.pixels - 1;
    FillBox(image, left - s, top - s, right + s, bottom + s, kHalo);
    FillBox(image, left, top, right, bottom, kInk);
    HaloText(image, left, top - 10 * s, Metres(bar.metres) + " at the look point", s);
}

std::optional<glm::dvec2> NorthInPicture(const Camera& camera, const View& view) {
    // The picture's image of a short step north from the look point.
    const double step = 1e-3 * glm::length(camera.look - camera.eye);
    const auto from = view.Project(camera.look);
    const auto to = view.Project(camera.look + glm::dvec3(0.0, step, 0.0));
    if (!from || !to) return std::nullopt;
    const glm::dvec2 d = *to - *from;
    // Under a thousandth of the step's pixels: north runs along the view.
    const double span = step * view.PixelsPerMetre(glm::length(camera.look - camera.eye));
    if (glm::length(d) < 1e-3 * span) return std::nullopt;
    return glm::normalize(d);
}

void DrawNorthArrow(Image& image, const std::optional<glm::dvec2>& north, bool ahead) {
    const int s = MarkScale(image);
    const glm::dvec2 centre(image.Width() - 40.0 * s, 40.0 * s);
    if (!north) {
        const std::string text = ahead ? "N ahead" : "N behind";
        HaloText(image, image.Width() - 12 * s - TextWidth(text, s), 12 * s, text, s);
        return;
    }
    const glm::dvec2 tip = centre + 16.0 * s * *north, tail = centre - 16.0 * s * *north;
    const glm::dvec2 side(-north->y, north->x);
    const glm::dvec2 barbs[2] = {tip - 7.0 * s * *north + 5.0 * s * side,
                                 tip - 7.0 * s * *north - 5.0 * s * side};
    for (const auto& [colour, width] : {std::pair{kHalo, 4 * s}, std::pair{kInk, 2 * s}}) {
        DrawLine(image, tail, tip, width, colour);
        for (const glm::dvec2& barb : barbs) DrawLine(image, tip, barb, width, colour);
    }
    const glm::dvec2 label = tip + 9.0 * s * *north;
    HaloText(image, static_cast<int>(std::lround(label.x)) - TextWidth("N", s) / 2,
             static_cast<int>(std::lround(label.y)) - 7 * s / 2, "N", s);
}

}  // namespace leaflux
