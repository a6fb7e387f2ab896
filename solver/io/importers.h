// Readers of plant and canopy geometry files: Wavefront OBJ, Caribu .can (with its .opt
// optics and .light sources) and the Open Plant Format (OPF) of AMAPStudio.
//
// An importer returns nodes and surfaces whose `opticsId` is still the file's material
// name ("Material.001", "species1", "soil", …); the caller maps material names to the
// scene's optics. Node ids start at 1 and are unique within one import. Errors name the
// file and line (or element) they concern.
#pragma once

#include <string>
#include <vector>

#include "solver/scene/scene.h"

namespace leaflux {

struct ImportedGeometry {
    std::vector<Node> nodes;
    std::vector<Surface> environment;
};

// OBJ: each `o` or `g` is one organ named after it; `usemtl` picks its material (a
// second material inside one group starts a new organ, "<group>/<material>"). Polygons
// are triangulated as fans. Node types come from the name: leaf, internode/stem, fruit,
// else other.
ImportedGeometry ReadObj(const std::string& path);

// Caribu canopy: one polygon a line, `p <n> <label> [n−1 more fields] <nv> x y z …`.
// The label's last 11 digits are plant (5), organ (3; 000 a stem) and polygon (3); the
// digits before are the optical species, 0 for soil. Polygons of one (plant, organ) make
// one organ named "plant<P>_organ<O>", under a plant node "plant<P>"; materials are
// "species<S>" for leaves, "species<S>_stem" for stems; soil becomes environment
// surfaces of material "soil".
ImportedGeometry ReadCan(const std::string& path);

// Caribu optics (.opt) of one band: soil reflectance, then per species stem reflectance and
// the upper and lower leaf faces' reflectance and transmittance.
struct CanOptics {
    double soilRho = 0.0;
    struct Species {
        double stemRho = 0.0;
        BandOptics leaf;
    };
    std::vector<Species> species;  // species 1 is species[0]
};
CanOptics ReadCanOptics(const std::string& path);

// Caribu sources (.light): one directional source a line, `energy vx vy vz`, the vector
// being the direction light travels and energy the irradiance it gives a horizontal plane.
struct CanLight {
    double horizontalIrradiance;
    glm::dvec3 towardSource;
};
std::vector<CanLight> ReadCanLights(const std::string& path);

// OPF: meshes of `meshBDD` shared between the organs that use them (kept shared: it is
// instancing data), the topology of `decomp`/`branch`/`follow` elements, each node placed
// by its 3×4 `mat` (global, in centimetres: converted to metres). Materials are
// "material<Id>" of `materialBDD`.
ImportedGeometry ReadOpf(const std::string& path);

}  // namespace leaflux
