// The rule for geometry that carries no light, shared by the importers (unlit.h).
#include "solver/io/unlit.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <set>

#include "solver/scene/world_frames.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

// False for NaN too.
bool InRange(const glm::dvec3& p) {
    return std::abs(p.x) <= kMaxCoordinateM && std::abs(p.y) <= kMaxCoordinateM &&
           std::abs(p.z) <= kMaxCoordinateM;
}

[[noreturn]] void OutOfRange(const std::string& where, const std::string& name,
                             std::optional<NodeId> node, std::size_t triangle) {
    throw InputError(ErrorCode::kInvalidArgument, where,
                     name + ": triangle " + std::to_string(triangle) +
                         " has a coordinate out of range (|x|, |y|, |z| must be at most 1e6 m, "
                         "or not a number)",
                     node);
}

// The triangles of `mesh` placed by worldFromLocal that carry no light; throws when one is
// out of range.
std::vector<bool> Unlit(const Mesh& mesh, const glm::dmat4& worldFromLocal,
                        const std::string& where, const std::string& name,
                        std::optional<NodeId> node, std::size_t& count) {
    std::vector<bool> unlit(mesh.triangles.size(), false);
    count = 0;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const glm::uvec3& tri = mesh.triangles[t];
        const glm::dvec3 a = glm::dvec3(worldFromLocal * glm::dvec4(mesh.positions[tri.x], 1.0));
        const glm::dvec3 b = glm::dvec3(worldFromLocal * glm::dvec4(mesh.positions[tri.y], 1.0));
        const glm::dvec3 c = glm::dvec3(worldFromLocal * glm::dvec4(mesh.positions[tri.z], 1.0));
        if (!InRange(a) || !InRange(b) || !InRange(c)) OutOfRange(where, name, node, t);
        if (!CarriesLight(a, b, c)) unlit[t] = true, ++count;
    }
    return unlit;
}

std::shared_ptr<const Mesh> Without(const Mesh& mesh, const std::vector<bool>& unlit) {
    auto kept = std::make_shared<Mesh>();
    kept->positions = mesh.positions;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (!unlit[t]) kept->triangles.push_back(mesh.triangles[t]);
    }
    return kept;
}

}  // namespace

void UnlitGeometry::Skip(SkippedGeometry skipped) {
    if (options_.strict) {
        throw InputError(ErrorCode::kDegenerate, skipped.where,
                         skipped.name + ": " + skipped.reason +
                             " (it carries no light; without strict it is skipped)",
                         skipped.node);
    }
    skipped_.push_back(std::move(skipped));
}

std::size_t UnlitGeometry::AddPolygon(Mesh& mesh, const std::vector<unsigned>& polygon, int line,
                                      const std::string& organ, std::optional<NodeId> node) {
    std::size_t added = 0;
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
        const glm::uvec3 tri{polygon[0], polygon[k], polygon[k + 1]};
        if (CarriesLight(mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z])) {
            mesh.triangles.push_back(tri);
            ++added;
        } else {
            Skip({path_ + ":" + std::to_string(line), node, organ,
                  polygon.size() == 3
                      ? "face has zero area"
                      : "triangle " + std::to_string(k) + " of the face has zero area",
                  1});
        }
    }
    return added;
}

void UnlitGeometry::Finish(ImportedGeometry& geometry) {
    // World frames within the file; the importers build trees, so this cannot loop.
    Scene placed;
    placed.nodes = std::move(geometry.nodes);
    const auto worldFromLocal = WorldFromLocal(placed);
    geometry.nodes = std::move(placed.nodes);

    bool hadGeometry = false, hasGeometry = false;
    for (Node& node : geometry.nodes) {
        if (!node.organ()) continue;
        hadGeometry = true;
        const Mesh& mesh = *node.organ()->mesh;
        const std::string name = node.name();  // every importer names its nodes
        std::size_t count = 0;
        const std::vector<bool> unlit =
            Unlit(mesh, worldFromLocal.at(node.id), path_, name, node.id, count);
        if (count == mesh.triangles.size()) {
            Skip({path_, node.id, name,
                  mesh.triangles.empty() ? "no triangle of its mesh carries light"
                                         : "every triangle has zero area where its frame "
                                           "places it",
                  mesh.triangles.size()});
            node.Edit().organ.reset();
            continue;
        }
        if (count > 0) {
            Skip({path_, node.id, name,
                  std::to_string(count) + " of its " + std::to_string(mesh.triangles.size()) +
                      " triangles have zero area where its frame places them",
                  count});
            node.Edit().organ->mesh = Without(mesh, unlit);
        }
        hasGeometry = true;
    }
    std::vector<Surface> kept;
    for (Surface& surface : geometry.environment) {
        hadGeometry = true;
        std::size_t count = 0;
        const std::vector<bool> unlit =
            Unlit(*surface.mesh, glm::dmat4(1.0), path_, surface.name, std::nullopt, count);
        if (count == surface.mesh->triangles.size()) {
            Skip({path_, std::nullopt, surface.name, "no triangle carries light",
                  surface.mesh->triangles.size()});
            continue;
        }
        if (count > 0) surface.mesh = Without(*surface.mesh, unlit);
        kept.push_back(std::move(surface));
        hasGeometry = true;
    }
    geometry.environment = std::move(kept);
    if (hadGeometry && !hasGeometry) {
        throw InputError(ErrorCode::kDegenerate, path_,
                         "no geometry that carries light is left once the " +
                             std::to_string(skipped_.size()) + " pieces without are skipped");
    }
    geometry.skipped = std::move(skipped_);
    skipped_.clear();
    if (!geometry.skipped.empty()) spdlog::warn("{}", SkippedSummary(path_, geometry.skipped));
}

std::string SkippedSummary(const std::string& path, const std::vector<SkippedGeometry>& skipped) {
    std::size_t triangles = 0;
    std::set<std::string> organs;
    for (const SkippedGeometry& s : skipped) {
        triangles += s.triangles;
        organs.insert(s.node ? "node " + std::to_string(*s.node) : s.name);
    }
    std::string text = path + ": skipped " + std::to_string(triangles) +
                       " triangles that carry no light, in " + std::to_string(organs.size()) +
                       " organs or meshes (strict refuses them)";
    constexpr std::size_t kNamed = 10;
    for (std::size_t i = 0; i < skipped.size() && i < kNamed; ++i) {
        const SkippedGeometry& s = skipped[i];
        text += i == 0 ? ": " : "; ";
        if (s.node) text += "node " + std::to_string(*s.node) + " ";
        text += s.name;
        if (s.where.size() > path.size() && s.where.compare(0, path.size(), path) == 0)
            text += " at line " + s.where.substr(path.size() + 1);
        text += ": " + s.reason;
    }
    if (skipped.size() > kNamed)
        text += "; and " + std::to_string(skipped.size() - kNamed) + " more";
    return text;
}

}  // namespace leaflux
