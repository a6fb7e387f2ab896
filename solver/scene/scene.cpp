#include "solver/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>

#include "solver/scene/light_units.h"
#include "solver/scene/world_frames.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

bool Finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// For checks made once; the checks made per node, vertex or triangle build their field and
// message only when they fail (a scene has hundreds of thousands).
void Require(bool condition, ErrorCode code, const std::string& field, const std::string& message,
             std::optional<NodeId> node = std::nullopt) {
    if (!condition) throw InputError(code, field, message, node);
}

void RequireFraction(double value, const std::string& field) {
    Require(std::isfinite(value) && value >= 0.0 && value <= 1.0, ErrorCode::kInvalidArgument,
            field, "must be a finite number in [0, 1], got " + std::to_string(value));
}

void RequirePerBand(const Scene& scene, const std::vector<double>& values,
                    const std::string& field) {
    Require(values.size() == scene.bands.size(), ErrorCode::kInvalidArgument, field,
            "needs one value per band (" + std::to_string(scene.bands.size()) + "), got " +
                std::to_string(values.size()));
    for (std::size_t b = 0; b < values.size(); ++b) {
        char got[32];
        std::snprintf(got, sizeof got, "%g", values[b]);
        Require(std::isfinite(values[b]) && values[b] >= 0.0, ErrorCode::kInvalidArgument,
                field + "[" + scene.bands[b].name + "]",
                std::string("must be finite and non-negative, got ") + got);
        Require(values[b] <= kMaxIrradianceWm2, ErrorCode::kInvalidArgument,
                field + "[" + scene.bands[b].name + "]",
                std::string("is out of range: at most 1e12 W/m², got ") + got);
    }
}

void ValidateOptics(const Scene& scene) {
    std::set<std::string> ids;
    for (const Optics& optics : scene.optics) {
        const std::string field = "optics[" + optics.id + "]";
        Require(!optics.id.empty(), ErrorCode::kInvalidArgument, "optics.id", "is empty");
        Require(ids.insert(optics.id).second, ErrorCode::kAlreadyExists, field,
                "is declared twice");
        Require(
            optics.bands.size() == scene.bands.size(), ErrorCode::kNotFound, field + ".bands",
            "needs properties for each of the " + std::to_string(scene.bands.size()) + " bands");
        for (std::size_t b = 0; b < optics.bands.size(); ++b) {
            const BandOptics& o = optics.bands[b];
            const std::string at = field + ".bands[" + scene.bands[b].name + "]";
            RequireFraction(o.rhoUpper, at + ".rho_upper");
            RequireFraction(o.rhoLower, at + ".rho_lower");
            RequireFraction(o.tauUpperToLower, at + ".tau_upper");
            RequireFraction(o.tauLowerToUpper, at + ".tau_lower");
            Require(o.rhoUpper + o.tauUpperToLower <= 1.0, ErrorCode::kInvalidArgument, at,
                    "rho_upper + tau_upper exceeds 1: the upper side would create light");
            Require(o.rhoLower + o.tauLowerToUpper <= 1.0, ErrorCode::kInvalidArgument, at,
                    "rho_lower + tau_lower exceeds 1: the lower side would create light");
        }
    }
}

void RequireOptics(const Scene& scene, const std::string& id, const std::string& field,
                   std::optional<NodeId> node) {
    if (scene.OpticsIndex(id) < 0)
        throw InputError(ErrorCode::kNotFound, field, "names unknown optics '" + id + "'", node);
}

void ValidateTopology(const Scene& scene, std::set<std::string>& names) {
    std::unordered_map<NodeId, const Node*> byId;
    byId.reserve(scene.nodes.size());
    for (const Node& node : scene.nodes) {
        if (!byId.emplace(node.id, &node).second) {
            throw InputError(ErrorCode::kAlreadyExists, "nodes.id", "the id is used by two nodes",
                             node.id);
        }
    }
    for (const Node& node : scene.nodes) {
        ValidateNode(scene, node);
        if (node.parent != kNoParent && !byId.count(node.parent)) {
            throw InputError(ErrorCode::kNotFound, "parent",
                             "names unknown node " + std::to_string(node.parent), node.id);
        }
    }
    // Cycles: walk up from each node; a walk longer than the node count loops.
    std::unordered_set<NodeId> rooted;
    for (const Node& node : scene.nodes) {
        std::vector<NodeId> path;
        NodeId at = node.id;
        while (at != kNoParent && !rooted.count(at)) {
            path.push_back(at);
            if (path.size() > scene.nodes.size()) {
                throw InputError(ErrorCode::kCycle, "parent", "the parent links of this node loop",
                                 node.id);
            }
            at = byId.at(at)->parent;
        }
        rooted.insert(path.begin(), path.end());
    }
    const auto worldFromLocal = WorldFromLocal(scene);
    for (const Node& node : scene.nodes) {
        if (!node.organ) continue;
        ValidateMesh(node.organ->mesh.get(), worldFromLocal.at(node.id), "organ.mesh", node.id);
        std::string name = scene.NodeName(node);
        if (!names.insert(name).second) {
            throw InputError(ErrorCode::kAlreadyExists, "name",
                             "organ name '" + name + "' is used twice", node.id);
        }
    }
}

void ValidateSources(const Scene& scene, std::set<std::string>& names) {
    for (std::size_t i = 0; i < scene.sources.suns.size(); ++i) {
        ValidateSun(scene, scene.sources.suns[i], "suns[" + std::to_string(i) + "]");
    }
    for (const Sky& sky : scene.sources.skies) {
        RequirePerBand(scene, sky.horizontalIrradianceWm2, "sky.horizontal_irradiance");
    }
    for (std::size_t i = 0; i < scene.sources.emitters.size(); ++i) {
        const Emitter& emitter = scene.sources.emitters[i];
        const std::string field = "emitters[" + emitter.name + "]";
        Require(!emitter.name.empty(), ErrorCode::kInvalidArgument,
                "emitters[" + std::to_string(i) + "].name", "is empty");
        ValidateMesh(emitter.mesh.get(), glm::dmat4(1.0), field + ".mesh", std::nullopt);
        RequirePerBand(scene, emitter.exitanceWm2, field + ".exitance");
        if (!emitter.opticsId.empty())
            RequireOptics(scene, emitter.opticsId, field + ".optics", {});
        Require(names.insert(emitter.name).second, ErrorCode::kAlreadyExists, field + ".name",
                "the name is used twice");
    }
}

}  // namespace

bool CarriesLight(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const double twiceArea = glm::length(glm::cross(b - a, c - a));
    const double longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    return twiceArea > 1e-9 * longest * longest && twiceArea > 1e-18;
}

bool InvertibleFrame(const glm::dmat4& frame) {
    for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) {
            if (!std::isfinite(frame[c][r])) return false;
        }
    }
    return std::abs(glm::determinant(glm::dmat3(frame))) > 1e-30;
}

// A shared mesh is named by its declaration (mesh->name) rather than by the organ that
// happens to be checked first; the node still says which placement failed.
void ValidateMesh(const Mesh* mesh, const glm::dmat4& worldFromLocal, const std::string& organField,
                  std::optional<NodeId> node) {
    if (mesh == nullptr)
        throw InputError(ErrorCode::kInvalidArgument, organField, "has no mesh", node);
    // Built only on failure: this runs once per organ.
    const auto field = [&] { return mesh->name.empty() ? organField : mesh->name; };
    const auto placed = [&] {
        return mesh->name.empty() || !node
                   ? std::string()
                   : " (shared mesh, as placed by node " + std::to_string(*node) + ")";
    };
    if (mesh->triangles.empty()) {
        throw InputError(ErrorCode::kDegenerate, field() + ".triangles", "mesh has no triangle",
                         node);
    }
    for (std::size_t i = 0; i < mesh->positions.size(); ++i) {
        if (!Finite(mesh->positions[i])) {
            throw InputError(ErrorCode::kInvalidArgument,
                             field() + ".positions[" + std::to_string(i) + "]", "is not finite",
                             node);
        }
    }
    const auto vertexCount = static_cast<unsigned>(mesh->positions.size());
    const auto inRange = [](const glm::dvec3& p) {
        return std::abs(p.x) <= kMaxCoordinateM && std::abs(p.y) <= kMaxCoordinateM &&
               std::abs(p.z) <= kMaxCoordinateM;
    };
    for (std::size_t t = 0; t < mesh->triangles.size(); ++t) {
        const glm::uvec3& tri = mesh->triangles[t];
        const auto fail = [&](ErrorCode code, const std::string& message) {
            throw InputError(code, field() + ".triangles[" + std::to_string(t) + "]",
                             message + placed(), node);
        };
        if (tri.x >= vertexCount || tri.y >= vertexCount || tri.z >= vertexCount) {
            fail(ErrorCode::kInvalidArgument,
                 "refers to vertex " + std::to_string(std::max({tri.x, tri.y, tri.z})) +
                     ", beyond the " + std::to_string(vertexCount) + " positions");
        }
        const glm::dvec3 a = glm::dvec3(worldFromLocal * glm::dvec4(mesh->positions[tri.x], 1.0));
        const glm::dvec3 b = glm::dvec3(worldFromLocal * glm::dvec4(mesh->positions[tri.y], 1.0));
        const glm::dvec3 c = glm::dvec3(worldFromLocal * glm::dvec4(mesh->positions[tri.z], 1.0));
        if (!Finite(a) || !Finite(b) || !Finite(c))
            fail(ErrorCode::kInvalidArgument, "has non-finite world coordinates");
        if (!inRange(a) || !inRange(b) || !inRange(c)) {
            fail(ErrorCode::kInvalidArgument,
                 "has a world coordinate out of range (|x|, |y|, |z| must be at most 1e6 m)");
        }
        if (!CarriesLight(a, b, c))
            fail(ErrorCode::kDegenerate, "has zero area (collapsed or repeated vertices)");
    }
}

void ValidateNode(const Scene& scene, const Node& node) {
    if (node.id == 0)
        throw InputError(ErrorCode::kInvalidArgument, "nodes.id", "0 is not a valid id");
    if (!InvertibleFrame(node.parentFromLocal)) {
        for (int c = 0; c < 4; ++c) {
            for (int r = 0; r < 3; ++r) {
                if (!std::isfinite(node.parentFromLocal.At(c, r)))
                    throw InputError(ErrorCode::kInvalidArgument, "frame", "is not finite",
                                     node.id);
            }
        }
        throw InputError(ErrorCode::kDegenerate, "frame", "is singular", node.id);
    }
    if (!std::isfinite(node.age))
        throw InputError(ErrorCode::kInvalidArgument, "age", "is not finite", node.id);
    for (const auto& [key, value] : node.attributes) {
        if (!std::isfinite(value)) {
            throw InputError(ErrorCode::kInvalidArgument, "attributes[" + key + "]",
                             "is not finite", node.id);
        }
    }
    if (node.organ) RequireOptics(scene, node.organ->opticsId, "organ.optics", node.id);
}

void ValidateSun(const Scene& scene, const Sun& sun, const std::string& field) {
    Require(Finite(sun.towardSun) && std::abs(glm::length(sun.towardSun) - 1.0) < 1e-6,
            ErrorCode::kInvalidArgument, field + ".direction", "must be a finite unit vector");
    RequirePerBand(scene, sun.normalIrradianceWm2, field + ".normal_irradiance");
    Require(std::isfinite(sun.angularRadiusRad) && sun.angularRadiusRad >= 0.0 &&
                sun.angularRadiusRad <= 0.2,
            ErrorCode::kInvalidArgument, field + ".angular_radius_deg",
            "must be between 0 and about 11 degrees");
}

const char* NodeTypeName(NodeType type) {
    switch (type) {
        case NodeType::kPlant:
            return "plant";
        case NodeType::kAxis:
            return "axis";
        case NodeType::kPhytomer:
            return "phytomer";
        case NodeType::kLeaf:
            return "leaf";
        case NodeType::kInternode:
            return "internode";
        case NodeType::kFruit:
            return "fruit";
        case NodeType::kOther:
            return "other";
    }
    return "other";
}

int Scene::BandIndex(const std::string& name) const {
    for (std::size_t b = 0; b < bands.size(); ++b) {
        if (bands[b].name == name) return static_cast<int>(b);
    }
    return -1;
}

int Scene::OpticsIndex(const std::string& id) const {
    for (std::size_t o = 0; o < optics.size(); ++o) {
        if (optics[o].id == id) return static_cast<int>(o);
    }
    return -1;
}

std::string Scene::NodeName(const Node& node) const {
    return node.name.empty() ? "node" + std::to_string(node.id) : node.name;
}

void Scene::Validate() const {
    Require(!bands.empty(), ErrorCode::kInvalidArgument, "bands", "at least one band is needed");
    Require(bands.size() <= static_cast<std::size_t>(kMaxBands), ErrorCode::kInvalidArgument,
            "bands", "at most " + std::to_string(kMaxBands) + " bands are supported");
    std::set<std::string> bandNames;
    for (const Band& band : bands) {
        Require(!band.name.empty(), ErrorCode::kInvalidArgument, "bands.name", "is empty");
        Require(bandNames.insert(band.name).second, ErrorCode::kAlreadyExists,
                "bands[" + band.name + "]", "is declared twice");
        char got[32];
        std::snprintf(got, sizeof got, "%g", band.photonUmolPerJ);
        Require(std::isfinite(band.photonUmolPerJ) && band.photonUmolPerJ >= 0.0 &&
                    band.photonUmolPerJ <= kMaxPhotonUmolPerJ,
                ErrorCode::kInvalidArgument, "bands[" + band.name + "].photon_umol_per_j",
                std::string("must be 0 (not given) or the band's photons per joule, at most "
                            "1000 µmol/J (daylight PAR: 4.57), got ") +
                    got);
    }
    ValidateOptics(*this);
    std::set<std::string> names;
    ValidateTopology(*this, names);
    for (std::size_t i = 0; i < environment.size(); ++i) {
        const Surface& surface = environment[i];
        const std::string field = "environment[" + surface.name + "]";
        Require(!surface.name.empty(), ErrorCode::kInvalidArgument,
                "environment[" + std::to_string(i) + "].name", "is empty");
        RequireOptics(*this, surface.opticsId, field + ".optics", {});
        // Environment surfaces are opaque (the schema's BandOptics): no light through them.
        const Optics& opaque = optics[OpticsIndex(surface.opticsId)];
        for (std::size_t b = 0; b < opaque.bands.size(); ++b) {
            Require(
                opaque.bands[b].tauUpperToLower == 0.0 && opaque.bands[b].tauLowerToUpper == 0.0,
                ErrorCode::kInvalidArgument, field + ".optics",
                "an environment surface is opaque: optics '" + surface.opticsId +
                    "' must have tau_upper = tau_lower = 0 (band " + bands[b].name + ")");
        }
        ValidateMesh(surface.mesh.get(), glm::dmat4(1.0), field + ".mesh", std::nullopt);
        Require(names.insert(surface.name).second, ErrorCode::kAlreadyExists, field + ".name",
                "the name is used twice");
    }
    ValidateSources(*this, names);
    if (periodic) {
        Require(std::isfinite(periodic->xMin) && std::isfinite(periodic->xMax) &&
                    std::isfinite(periodic->yMin) && std::isfinite(periodic->yMax) &&
                    periodic->xMax > periodic->xMin && periodic->yMax > periodic->yMin,
                ErrorCode::kInvalidArgument, "periodic", "needs x_min < x_max and y_min < y_max");
    }
}

Scene WithBands(const Scene& scene, const std::vector<int>& bands) {
    auto pick = [&](const auto& values) {
        std::decay_t<decltype(values)> picked;
        for (int b : bands) picked.push_back(values.at(b));
        return picked;
    };
    Scene subset = scene;
    subset.bands = pick(scene.bands);
    for (Optics& optics : subset.optics) optics.bands = pick(optics.bands);
    for (Sun& sun : subset.sources.suns) sun.normalIrradianceWm2 = pick(sun.normalIrradianceWm2);
    for (Sky& sky : subset.sources.skies)
        sky.horizontalIrradianceWm2 = pick(sky.horizontalIrradianceWm2);
    for (Emitter& emitter : subset.sources.emitters)
        emitter.exitanceWm2 = pick(emitter.exitanceWm2);
    return subset;
}

double TriangleArea(const glm::dmat4& worldFromLocal, const Mesh& mesh, const glm::uvec3& tri) {
    const glm::dvec3 a = glm::dvec3(worldFromLocal * glm::dvec4(mesh.positions[tri.x], 1.0));
    const glm::dvec3 b = glm::dvec3(worldFromLocal * glm::dvec4(mesh.positions[tri.y], 1.0));
    const glm::dvec3 c = glm::dvec3(worldFromLocal * glm::dvec4(mesh.positions[tri.z], 1.0));
    return 0.5 * glm::length(glm::cross(b - a, c - a));
}

double MeshArea(const Mesh& mesh, const glm::dmat4& worldFromLocal) {
    double area = 0.0;
    for (const glm::uvec3& tri : mesh.triangles) area += TriangleArea(worldFromLocal, mesh, tri);
    return area;
}

}  // namespace leaflux
