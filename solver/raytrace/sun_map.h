// A sun's light on each organ triangle, from the scene's triangles drawn as the sun sees
// them: a depth buffer on a plane across the light, each pixel keeping the depth nearest
// the sun there. An organ triangle's lit share is the share of the pixels it covers where
// it is that near (to the corners' precision: a triangle in its plane does not shade it)
// — what rays from its points towards the sun find, without their noise, at the cost of
// drawing every triangle once and the organs' twice. The pixel is
// sized so that the organ triangles cover kPixelsPerTriangle pixels on the mean; only the
// tiles of the plane where organs lie are drawn, so a wide ground costs no more than its
// part under them. A sun of some angular radius is drawn from points spread over its disc
// (kDiscDirections of them), its soft shadows the mean of their hard ones.
//
// Read-only once made: read it from any thread.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "solver/raytrace/raytrace.h"

namespace leaflux {

class SunMap {
  public:
    static constexpr double kPixelsPerTriangle = 256.0;
    static constexpr double kLeastPixels = 1 << 20;  // over all the organs, however few
    static constexpr int kDiscDirections = 8;
    // The tiles are drawn in runs of at most this many (triangle, tile) pairs, at least one
    // tile a run: listed all at once, a plantation of 5 M triangles took 35 MB at its peak.
    static constexpr std::uint32_t kMostListed = 1u << 21;

    // Over the scene's first `triangles` triangles (not periodic), of which the first
    // `organTriangles` are lit; `toward`: unit, towards the sun; `cosRadius`: of its angular
    // radius (1: a point). `wanted`, when not empty: per organ triangle, whether its light
    // is asked; the others only cast shadows (Lit −1). Only the tiles where the wanted lie
    // are drawn, on the pixels of the map of all: a wanted triangle's share is the same.
    SunMap(const RayScene& scene, std::uint32_t triangles, std::uint32_t organTriangles,
           const glm::dvec3& toward, double cosRadius,
           double pixelsPerTriangle = kPixelsPerTriangle, std::span<const std::uint8_t> wanted = {},
           std::uint32_t mostListed = kMostListed);

    const glm::dvec3& Toward() const { return toward_; }
    double CosRadius() const { return cosRadius_; }
    // The share of organ triangle t's area across the light that the sun reaches; negative
    // where no pixel of the map falls on t (edge-on, or smaller than a pixel).
    double Lit(std::uint32_t t) const {
        return lit_[t] == kNone ? -1.0 : lit_[t] / static_cast<double>(kWhole);
    }
    // Whether another triangle lies in t's plane, as near the sun, over a pixel of t (the
    // same triangle twice, two crossing in a line): which of the two a ray from a point
    // there meets, or a path of the reference's, is left to rounding, and the map cannot
    // say. Such an organ takes rays.
    bool Tied(std::uint32_t t) const { return tied_[t] != 0; }
    // The side of a pixel (m; the largest of its directions').
    double PixelM() const { return pixelM_; }

  private:
    static constexpr std::uint16_t kWhole = 0xFFFE, kNone = 0xFFFF;

    glm::dvec3 toward_;
    double cosRadius_;
    std::vector<std::uint16_t> lit_;  // per organ triangle: its lit share × kWhole, or kNone
    std::vector<std::uint8_t> tied_;  // per organ triangle: Tied
    double pixelM_ = 0.0;
};

// The maps of a scene's suns, found by the direction they were made for.
struct SunMaps {
    struct Sun {
        glm::dvec3 toward;
        double cosRadius;
    };
    // Over the triangles of `rays`, numbered as the receivers of `receivers` number them,
    // its organs first (Flatten, ReceiversOf); none in a periodic scene. `wanted`: as
    // SunMap's.
    SunMaps(const RayScene& rays, const FlatScene& receivers, const std::vector<Sun>& suns,
            std::span<const std::uint8_t> wanted = {});
    SunMaps() = default;

    std::vector<SunMap> maps;
    // The map of a sun towards `toward` of that cone, or null.
    const SunMap* Of(const glm::dvec3& toward, double cosRadius) const {
        for (const SunMap& map : maps) {
            if (map.Toward() == toward && map.CosRadius() == cosRadius) return &map;
        }
        return nullptr;
    }
};

}  // namespace leaflux
