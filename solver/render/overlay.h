// Marks drawn over a view to read it by: a scale bar, true at the look point's distance
// (perspective shrinks what lies beyond it), and an arrow towards north (+y).
#pragma once

#include <optional>

#include "solver/render/camera.h"
#include "solver/render/image.h"

namespace leaflux {

struct ScaleBar {
    double metres = 0.0;  // a round length: 1, 2 or 5 × 10^k m
    int pixels = 0;       // its length in the picture
};

// The round length spanning about a fifth of the picture's width at the look point.
ScaleBar ScaleBarOf(const Camera& camera, const View& view, int width);
// The bar at the view's bottom-left corner, labelled "<length> at the look point".
void DrawScaleBar(Image& image, const ScaleBar& bar);

// North (+y) at the look point, as a unit direction in the picture (x right, y down);
// nothing when the camera looks along north or straight away from it.
std::optional<glm::dvec2> NorthInPicture(const Camera& camera, const View& view);
// An arrow at the view's top-right corner towards `north`, an N at its head; without a
// direction, the N alone, with "ahead" or "behind".
void DrawNorthArrow(Image& image, const std::optional<glm::dvec2>& north, bool ahead);

}  // namespace leaflux
