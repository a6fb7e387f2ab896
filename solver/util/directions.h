// Direction sets on the unit sphere from the recursive subdivision of a tetrahedron
// (Soler 2003 §4.2.2, Fig. 11): 4, 10, 34, 130, 514 directions for levels 0..4.
//
// Invariant: the solid angles of the directions sum to 4π; every direction of the sphere
// lies in exactly one face, whose three vertices interpolate a function linearly. A set is
// immutable once built and shared by every directional function of its resolution.
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <vector>

namespace leaflux {

class DirectionSet {
  public:
    // level 0..4 → 4, 10, 34, 130, 514 directions. One vertex of the tetrahedron is the
    // zenith (0, 0, 1), so every set has a direction straight up.
    static const DirectionSet& OfLevel(int level);
    static int LevelWithCount(int directionCount);  // -1 when no level has that many

    int Size() const { return static_cast<int>(directions_.size()); }
    const glm::dvec3& Direction(int i) const { return directions_[i]; }
    double SolidAngleSr(int i) const { return solidAngles_[i]; }
    // ∫ over the sphere of direction i's interpolation weight (Locate), in sr: a function
    // known at the directions, f_i, interpolated, integrates to Σ f_i HatIntegralSr(i).
    // They sum to 4π.
    double HatIntegralSr(int i) const { return hatIntegrals_[i]; }
    const std::vector<std::array<int, 3>>& Faces() const { return faces_; }

    struct Interpolation {
        std::array<int, 3> vertex;
        std::array<double, 3> weight;  // non-negative, sum to 1
    };
    // The face containing `direction` (any length > 0) and its barycentric weights.
    Interpolation Locate(const glm::dvec3& direction) const;
    // The vertex of the containing face nearest to `direction`: the set's cell partition.
    int Nearest(const glm::dvec3& direction) const;

  private:
    explicit DirectionSet(int level);
    int LocateFace(const glm::dvec3& unitDirection) const;

    std::vector<glm::dvec3> directions_;
    std::vector<double> solidAngles_;
    std::vector<double> hatIntegrals_;
    std::vector<std::array<int, 3>> faces_;
    // faces_ of every level, children of face f of level l at 4f..4f+3 of level l+1, so
    // that Locate descends the subdivision in O(level).
    std::vector<std::vector<std::array<int, 3>>> levels_;
    // By level and face: the normals a × b, b × c, c × a of its three great-circle edges.
    std::vector<std::vector<std::array<glm::dvec3, 3>>> edges_;
};

// The angle in [0, π] with this sine and cosine, both scaled by the same positive factor
// (|a × b| and a · b of two vectors): std::atan2 for a sine ≥ 0, to a few ulp, without its
// general cases. Form factors take one per polygon edge, and refinement finds a dozen form
// factors per link it judges.
double Angle(double sine, double cosine);

// Solid angle (sr) of the spherical triangle with unit vertices a, b, c
// (Van Oosterom & Strackee 1983).
double SphericalTriangleSolidAngle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

}  // namespace leaflux
