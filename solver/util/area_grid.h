// Where a structure's organs lie in its box (AreaGrid).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/glm.hpp>

namespace leaflux {

// Where a structure's organs lie in its box: the share of their area (one side) in each of
// kCells³ cells of the box, in its own frame, together 1. A closed instance's light leaves
// from its organs, not evenly from its box: a branch's leaves fill a part of the box that
// bounds it, and a held sibling's leaves lie above or beside the organs it wraps.
struct AreaGrid {
    static constexpr int kCells = 6;
    static constexpr int kCount = kCells * kCells * kCells;
    std::array<float, kCount> share{};

    // The cell of point x of the box [lo, hi] (instance frame), nearest when outside.
    static int CellOf(const glm::dvec3& x, const glm::dvec3& lo, const glm::dvec3& hi) {
        const glm::dvec3 at = (x - lo) / (hi - lo) * static_cast<double>(kCells);
        const auto axis = [&](int i) {
            return std::clamp(static_cast<int>(std::floor(at[i])), 0, kCells - 1);
        };
        return Index(axis(0), axis(1), axis(2));
    }
    // The cell (i, j, k), each 0..kCells - 1 along x, y, z.
    static int Index(int i, int j, int k) { return i + kCells * (j + kCells * k); }
};

}  // namespace leaflux
