#include "solver/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <type_traits>
#include <unordered_set>

#include "solver/scene/light_units.h"
#include "solver/scene/topology.h"
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
    Require(scene.optics.size() <= static_cast<std::size_t>(kMaxOptics),
            ErrorCode::kInvalidArgument, "optics",
            "at most " + std::to_string(kMaxOptics) + " optics are supported");
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

// The names receivers answer to, which must differ: the organs' (Scene::NodeName), held as
// their hashes and node indices in hash order, 16 bytes an organ (a std::set of the names
// took about 100, on a plantation of 233 trees 190 MB), and the few surfaces' and
// emitters' in a set.
class ReceiverNames {
  public:
    explicit ReceiverNames(const Scene& scene) : scene_(scene) {
        for (std::uint32_t i = 0; i < scene.nodes.size(); ++i) {
            if (scene.nodes[i].organ())
                organs_.push_back({Hash(scene.NodeName(scene.nodes[i])), i});
        }
        std::sort(organs_.begin(), organs_.end());
    }
    // The first organ, in the nodes' order, whose name an organ before it has; none if all
    // differ.
    std::optional<std::size_t> FirstRepeated() const {
        std::optional<std::size_t> first;
        for (std::size_t a = 0; a < organs_.size();) {
            std::size_t b = a + 1;
            while (b < organs_.size() && organs_[b].first == organs_[a].first) ++b;
            // Equal hashes, in index order: names compared (a hash may be shared).
            for (std::size_t k = a + 1; k < b; ++k) {
                const std::string name = NameOf(k);
                for (std::size_t e = a; e < k; ++e) {
                    if (NameOf(e) == name && (!first || organs_[k].second < *first)) {
                        first = organs_[k].second;
                        break;
                    }
                }
            }
            a = b;
        }
        return first;
    }
    // Takes a surface's or emitter's name; false when an organ or another receiver has it.
    bool Insert(const std::string& name) {
        const std::uint64_t hash = Hash(name);
        for (auto at = std::lower_bound(organs_.begin(), organs_.end(), std::pair{hash, 0u});
             at != organs_.end() && at->first == hash; ++at) {
            if (NameOf(static_cast<std::size_t>(at - organs_.begin())) == name) return false;
        }
        return others_.insert(name).second;
    }

  private:
    static std::uint64_t Hash(const std::string& name) { return std::hash<std::string>{}(name); }
    std::string NameOf(std::size_t k) const {
        return scene_.NodeName(scene_.nodes[organs_[k].second]);
    }

    const Scene& scene_;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> organs_;
    std::set<std::string> others_;
};

// Ids, parents, cycles, organ meshes and names, in memory that grows by some 30 bytes a node
// at its peak (the scene's Topology): hash maps of the nodes by id and of the ids rooted,
// with every node's world frame kept, took about 230 bytes a node (on the 4.3 M nodes of
// the paper's plantation, more than the scene itself). Each check reports the first node
// in the nodes' order that fails it.
void ValidateTopology(const Scene& scene, ReceiverNames& names) {
    {
        std::vector<NodeId> ids(scene.nodes.size());
        for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = scene.nodes[i].id;
        std::sort(ids.begin(), ids.end());
        // The id used twice that the nodes' order meets second first.
        std::optional<std::size_t> repeated;
        if (std::adjacent_find(ids.begin(), ids.end()) != ids.end()) {
            std::unordered_set<NodeId> seen;
            for (std::size_t i = 0; i < scene.nodes.size() && !repeated; ++i) {
                if (!seen.insert(scene.nodes[i].id).second) repeated = i;
            }
        }
        if (repeated) {
            throw InputError(ErrorCode::kAlreadyExists, "nodes.id", "the id is used by two nodes",
                             scene.nodes[*repeated].id);
        }
    }
    const Topology topology(scene);
    for (std::size_t i = 0; i < scene.nodes.size(); ++i) {
        const Node& node = scene.nodes[i];
        ValidateNode(scene, node);
        if (node.parent != kNoParent && topology.Parent(i) == Topology::kNone) {
            throw InputError(ErrorCode::kNotFound, "parent",
                             "names unknown node " + std::to_string(node.parent), node.id);
        }
    }
    // Cycles: every parent is a node, so a node the walk from the roots does not reach has
    // parent links that loop above it. And the organs' meshes where they are placed: the
    // first failing in the nodes' order is reported, as the names below.
    std::vector<std::uint8_t> reached(scene.nodes.size(), 0);
    std::optional<std::size_t> badMesh;
    std::optional<InputError> meshError;
    ForEachWorldFrame(scene, topology, [&](const Node& node, const glm::dmat4& worldFromLocal) {
        const auto i = static_cast<std::size_t>(&node - scene.nodes.data());
        reached[i] = 1;
        if (!node.organ() || (badMesh && *badMesh < i)) return;
        try {
            ValidateMesh(node.organ()->mesh.get(), worldFromLocal, "organ.mesh", node.id);
        } catch (const InputError& e) {
            badMesh = i;
            meshError.emplace(e);
        }
    });
    const auto loop = std::find(reached.begin(), reached.end(), 0);
    if (loop != reached.end()) {
        throw InputError(ErrorCode::kCycle, "parent", "the parent links of this node loop",
                         scene.nodes[static_cast<std::size_t>(loop - reached.begin())].id);
    }
    const std::optional<std::size_t> repeated = names.FirstRepeated();
    if (badMesh && (!repeated || *badMesh <= *repeated)) throw *meshError;
    if (repeated) {
        const Node& node = scene.nodes[*repeated];
        throw InputError(ErrorCode::kAlreadyExists, "name",
                         "organ name '" + scene.NodeName(node) + "' is used twice", node.id);
    }
}

void ValidateSources(const Scene& scene, ReceiverNames& names) {
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
        Require(names.Insert(emitter.name), ErrorCode::kAlreadyExists, field + ".name",
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
    if (!InvertibleFrame(node.parentFromLocal())) {
        for (int c = 0; c < 4; ++c) {
            for (int r = 0; r < 3; ++r) {
                if (!std::isfinite(node.parentFromLocal().At(c, r)))
                    throw InputError(ErrorCode::kInvalidArgument, "frame", "is not finite",
                                     node.id);
            }
        }
        throw InputError(ErrorCode::kDegenerate, "frame", "is singular", node.id);
    }
    if (!std::isfinite(node.age()))
        throw InputError(ErrorCode::kInvalidArgument, "age", "is not finite", node.id);
    for (const auto& [key, value] : node.attributes()) {
        if (!std::isfinite(value)) {
            throw InputError(ErrorCode::kInvalidArgument, "attributes[" + key + "]",
                             "is not finite", node.id);
        }
    }
    if (node.organ()) RequireOptics(scene, node.organ()->opticsId, "organ.optics", node.id);
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

std::string WithId(std::string pattern, NodeId id) {
    const std::string digits = std::to_string(id);
    for (std::size_t at = pattern.find("{id}"); at != std::string::npos;
         at = pattern.find("{id}", at + digits.size())) {
        pattern.replace(at, 4, digits);
    }
    return pattern;
}

std::string Node::name() const { return body_->nameHasId ? WithId(body_->name, id) : body_->name; }

std::string Scene::NodeName(const Node& node) const {
    std::string name = node.name();
    return name.empty() ? "node" + std::to_string(node.id) : name;
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
    ReceiverNames names(*this);
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
        Require(names.Insert(surface.name), ErrorCode::kAlreadyExists, field + ".name",
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
