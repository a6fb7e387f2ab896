// Readers of plant and canopy geometry files: Wavefront OBJ, Caribu .can (with its .opt
// optics and .light sources) and the Open Plant Format (OPF) of AMAPStudio.
//
// An importer returns nodes and surfaces whose `opticsId` is still the file's material
// name ("Material.001", "species1", "soil", …); the caller maps material names to the
// scene's optics. Node ids start at 1 and are unique within one import. Errors are
// InputError naming the file and line ("plant.opf:322") and, where there is one, the node.
//
// Geometry that carries no light (zero-area triangles, organs with a singular frame or a
// NaN diameter) is skipped and listed, or refused under ImportOptions::strict: one rule for
// every format (solver/io/unlit.h).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "solver/scene/scene.h"

namespace leaflux {

struct ImportOptions {
    // Refuse a file that holds geometry carrying no light, instead of skipping it.
    bool strict = false;
};

// One piece of geometry an import skipped.
struct SkippedGeometry {
    std::string where;           // file and line: "plant.opf:1234"
    std::optional<NodeId> node;  // the node (file id) that lost geometry, when there is one
    std::string name;            // that node's name, the surface's, or a shared mesh's
    std::string reason;          // "frame is singular", "dUp is NaN", "zero area"
    std::size_t triangles = 0;   // triangles it had (once per shared mesh, not per use)
};

struct ImportedGeometry {
    std::vector<Node> nodes;
    std::vector<Surface> environment;
    std::vector<SkippedGeometry> skipped;  // always empty under ImportOptions::strict
};

// The warning for a list of skipped geometry: the counts, then the first nodes by name.
std::string SkippedSummary(const std::string& path, const std::vector<SkippedGeometry>& skipped);

// OBJ: each `o` or `g` is one organ named after it; `usemtl` picks its material (a
// second material inside one group starts a new organ, "<group>/<material>"). Polygons
// are triangulated as fans. Node types come from the name: leaf, internode/stem, fruit,
// else other.
ImportedGeometry ReadObj(const std::string& path, const ImportOptions& options = {});

// Caribu canopy: one polygon a line, `p <n> <label> [n−1 more fields] <nv> x y z …`.
// The label's last 11 digits are plant (5), organ (3; 000 a stem) and polygon (3); the
// digits before are the optical species, 0 for soil. Polygons of one (plant, organ) make
// one organ named "plant<P>_organ<O>", under a plant node "plant<P>"; materials are
// "species<S>" for leaves, "species<S>_stem" for stems; soil becomes environment
// surfaces of material "soil".
ImportedGeometry ReadCan(const std::string& path, const ImportOptions& options = {});

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
// "material<Id>" of `materialBDD`. A node whose `mat` is singular or not finite keeps its
// place in the topology (its parent's axes at its own origin) but not its organ; so does a
// node whose `dUp` or `dDwn` diameter is not finite. XML is read with pugixml.
ImportedGeometry ReadOpf(const std::string& path, const ImportOptions& options = {});

}  // namespace leaflux
