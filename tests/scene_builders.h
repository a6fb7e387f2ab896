// Small scenes with known answers, shared by the tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/constants.hpp>
#include <memory>
#include <string>
#include <vector>

#include "solver/results/light.h"
#include "solver/scene/scene.h"

namespace leaflux::testing {

inline constexpr double kPi = glm::pi<double>();

// A planar quad a, b, c, d (counter-clockwise seen from its upper side).
inline std::shared_ptr<const Mesh> Quad(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
    auto mesh = std::make_shared<Mesh>();
    mesh->positions = {a, b, c, d};
    mesh->triangles = {{0, 1, 2}, {0, 2, 3}};
    return mesh;
}

// A horizontal w × h rectangle centred on (0, 0, z); upper side up, or down if `facingDown`.
inline std::shared_ptr<const Mesh> Rectangle(double w, double h, double z,
                                             bool facingDown = false) {
    const glm::dvec3 a(-w / 2, -h / 2, z), b(w / 2, -h / 2, z), c(w / 2, h / 2, z),
        d(-w / 2, h / 2, z);
    return facingDown ? Quad(a, d, c, b) : Quad(a, b, c, d);
}

// A regular polygon approximating a disc of radius r (same area) centred on (0, 0, z).
inline std::shared_ptr<const Mesh> Disc(double r, double z, bool facingDown, int sides = 256) {
    auto mesh = std::make_shared<Mesh>();
    const double step = 2.0 * kPi / sides;
    const double radius = r * std::sqrt(step / std::sin(step));  // keeps the disc's area
    mesh->positions.push_back({0, 0, z});
    for (int i = 0; i < sides; ++i) {
        mesh->positions.push_back({radius * std::cos(i * step), radius * std::sin(i * step), z});
    }
    for (unsigned i = 0; i < static_cast<unsigned>(sides); ++i) {
        const unsigned a = 1 + i, b = 1 + (i + 1) % sides;
        mesh->triangles.push_back(facingDown ? glm::uvec3(0, b, a) : glm::uvec3(0, a, b));
    }
    return mesh;
}

inline BandOptics Leaf(double rho, double tau) { return {rho, rho, tau, tau}; }
inline BandOptics Opaque(double rho) { return {rho, rho, 0.0, 0.0}; }

// A scene with one band "PAR" and the given optics.
inline Scene OneBandScene(std::vector<std::pair<std::string, BandOptics>> optics) {
    Scene scene;
    scene.bands = {{"PAR"}};
    for (auto& [id, o] : optics) scene.optics.push_back({id, {o}});
    return scene;
}

inline Node OrganNode(NodeId id, const std::string& name, std::shared_ptr<const Mesh> mesh,
                      const std::string& optics, NodeId parent = kNoParent) {
    Node node;
    node.id = id;
    node.parent = parent;
    node.Edit().type = NodeType::kLeaf;
    node.Edit().name = name;
    node.Edit().organ = leaflux::Organ{std::move(mesh), optics};
    return node;
}

inline Sun SunAt(double elevationDeg, double azimuthDeg, double irradiance) {
    const double h = glm::radians(elevationDeg), a = glm::radians(azimuthDeg);
    return {glm::dvec3(std::cos(h) * std::sin(a), std::cos(h) * std::cos(a), std::sin(h)),
            {irradiance},
            0.0};
}

// A closed unit cube whose inner faces ("face0".."face5") emit `exitance` and reflect ρ:
// B = E / (1 − ρ) everywhere (the form factors of a closed box sum to 1).
inline Scene Furnace(double rho, double exitance) {
    Scene scene = OneBandScene({{"wall", Opaque(rho)}});
    const glm::dvec3 p[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                             {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    // Counter-clockwise seen from inside: upper sides face into the box.
    const int faces[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1},
                             {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 4, 0}};
    for (int f = 0; f < 6; ++f) {
        scene.sources.emitters.push_back(
            {"face" + std::to_string(f),
             Quad(p[faces[f][0]], p[faces[f][1]], p[faces[f][2]], p[faces[f][3]]),
             {exitance},
             "wall"});
    }
    return scene;
}

// Two 10 cm square leaves (ρ = τ = 0.45), one `gap` above the other and shifted 3 cm
// sideways, at z = 1 m, the whole moved by `offset`; no sources.
inline Scene TwoLeaves(double gap, glm::dvec3 offset) {
    Scene scene = OneBandScene({{"leaf", Leaf(0.45, 0.45)}});
    auto square = [&](double x0, double x1, double z) {
        return Quad(offset + glm::dvec3(x0, -0.05, z), offset + glm::dvec3(x1, -0.05, z),
                    offset + glm::dvec3(x1, 0.05, z), offset + glm::dvec3(x0, 0.05, z));
    };
    scene.nodes.push_back(OrganNode(1, "top", square(-0.05, 0.05, 1.0 + gap), "leaf"));
    scene.nodes.push_back(OrganNode(2, "bottom", square(-0.02, 0.08, 1.0), "leaf"));
    return scene;
}

// Every receiver's irradiance, each band and side, is a finite, non-negative number.
inline void ExpectFiniteLight(const Solution& solution) {
    for (const auto& bands : solution.light) {
        for (const BandLight& light : bands) {
            EXPECT_TRUE(std::isfinite(light.irradianceUpperWm2) && light.irradianceUpperWm2 >= 0.0);
            EXPECT_TRUE(std::isfinite(light.irradianceLowerWm2) && light.irradianceLowerWm2 >= 0.0);
        }
    }
}

// Two solutions give every receiver the same light, to the last bit: irradiance on each
// side and absorbed power, in every band.
inline void ExpectIdenticalLight(const Solution& a, const Solution& b) {
    ASSERT_EQ(a.light.size(), b.light.size());
    for (std::size_t r = 0; r < a.light.size(); ++r) {
        ASSERT_EQ(a.light[r].size(), b.light[r].size()) << "receiver " << r;
        for (std::size_t k = 0; k < a.light[r].size(); ++k) {
            EXPECT_EQ(a.light[r][k].irradianceUpperWm2, b.light[r][k].irradianceUpperWm2)
                << "receiver " << r << ", band " << k;
            EXPECT_EQ(a.light[r][k].irradianceLowerWm2, b.light[r][k].irradianceLowerWm2)
                << "receiver " << r << ", band " << k;
            EXPECT_EQ(a.light[r][k].absorbedW, b.light[r][k].absorbedW)
                << "receiver " << r << ", band " << k;
        }
    }
}

}  // namespace leaflux::testing
