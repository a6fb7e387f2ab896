// Text on pictures: a 5 × 7 pixel font of printable ASCII and the few other characters
// units and labels need (² ¹ ⁻ µ ε °), drawn at an integer scale.
#pragma once

#include <string>

#include "solver/render/image.h"

namespace leaflux {

// Pixels a character takes across (glyph and gap) and a line down, at scale 1.
inline constexpr int kGlyphAdvance = 6;
inline constexpr int kGlyphLine = 9;

// The width of `utf8` in pixels at `scale`.
int TextWidth(const std::string& utf8, int scale = 1);
// Draws `utf8` with its top-left corner at (x, y); a character the font lacks shows as '?'.
void DrawText(Image& image, int x, int y, const std::string& utf8, Rgb colour, int scale = 1);

}  // namespace leaflux
