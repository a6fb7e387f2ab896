// Geometry files named by a scene's `imports`, placed into the scene. What the importers
// skip (geometry that carries no light) they log; ImportOptions::strict refuses it.
#include <algorithm>
#include <filesystem>
#include <set>

#include "server/scene_proto.h"
#include "solver/io/importers.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

v1::GeometryFormat FormatOf(const v1::Import& import, const std::string& field) {
    if (import.format() != v1::GEOMETRY_FORMAT_UNSPECIFIED) return import.format();
    std::string extension = std::filesystem::path(import.path()).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
    if (extension == ".obj") return v1::GEOMETRY_FORMAT_OBJ;
    if (extension == ".can") return v1::GEOMETRY_FORMAT_CAN;
    if (extension == ".opf") return v1::GEOMETRY_FORMAT_OPF;
    throw InputError(ErrorCode::kUnsupported, field + ".path",
                     "cannot tell the format of '" + import.path() + "': set format");
}

// Optics "species<S>", "species<S>_stem" and "soil" from one .opt file per band.
std::set<std::string> AddCanOptics(const v1::Import& import, const std::string& field,
                                   const std::filesystem::path& base, Scene& scene) {
    std::vector<CanOptics> perBand(scene.bands.size());
    std::vector<bool> seen(scene.bands.size(), false);
    for (const auto& [band, path] : import.can_optics()) {
        const int b = scene.BandIndex(band);
        if (b < 0)
            throw InputError(ErrorCode::kNotFound, field + ".can_optics[" + band + "]",
                             "names no declared band");
        perBand[b] = ReadCanOptics((base / path).string());
        seen[b] = true;
    }
    for (std::size_t b = 0; b < seen.size(); ++b) {
        if (!seen[b])
            throw InputError(ErrorCode::kNotFound, field + ".can_optics",
                             "has no .opt file for band " + scene.bands[b].name);
    }
    const std::size_t species = perBand.front().species.size();
    for (const CanOptics& o : perBand) {
        if (o.species.size() != species) {
            throw InputError(ErrorCode::kInvalidArgument, field + ".can_optics",
                             "the .opt files declare different numbers of species");
        }
    }
    std::set<std::string> created;
    auto add = [&](const std::string& id, auto valueOf) {
        Optics optics{id, {}};
        for (const CanOptics& o : perBand) optics.bands.push_back(valueOf(o));
        scene.optics.push_back(std::move(optics));
        created.insert(id);
    };
    add("soil", [](const CanOptics& o) { return BandOptics{o.soilRho, o.soilRho, 0.0, 0.0}; });
    for (std::size_t s = 0; s < species; ++s) {
        const std::string name = "species" + std::to_string(s + 1);
        add(name, [s](const CanOptics& o) { return o.species[s].leaf; });
        add(name + "_stem", [s](const CanOptics& o) {
            return BandOptics{o.species[s].stemRho, o.species[s].stemRho, 0.0, 0.0};
        });
    }
    return created;
}

std::string OpticsFor(const std::string& material, const v1::Import& import,
                      const std::set<std::string>& created, const std::string& field) {
    if (const auto it = import.material_optics().find(material);
        it != import.material_optics().end()) {
        return it->second;
    }
    if (created.count(material)) return material;
    if (!import.default_optics().empty()) return import.default_optics();
    throw InputError(ErrorCode::kNotFound, field + ".material_optics",
                     "material '" + material + "' of " + import.path() +
                         " has no optics: map it or set default_optics");
}

glm::dmat4 ImportFrame(const v1::Frame& frame, const std::string& field) {
    if (frame.m_size() == 0) return glm::dmat4(1.0);
    if (frame.m_size() != 12)
        throw InputError(ErrorCode::kInvalidArgument, field, "needs 12 numbers");
    glm::dmat4 m(1.0);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) m[c][r] = frame.m(4 * r + c);
    }
    return m;
}

}  // namespace

void ReadImports(const v1::Scene& message, Scene& scene, const std::filesystem::path& base,
                 const ImportOptions& options) {
    for (int i = 0; i < message.imports_size(); ++i) {
        const v1::Import& import = message.imports(i);
        const std::string field = "imports[" + std::to_string(i) + "]";
        const std::string path = (base / import.path()).string();
        ImportedGeometry geometry;
        std::set<std::string> created;
        switch (FormatOf(import, field)) {
            case v1::GEOMETRY_FORMAT_OBJ:
                geometry = ReadObj(path, options);
                break;
            case v1::GEOMETRY_FORMAT_OPF:
                geometry = ReadOpf(path, options);
                break;
            default:
                geometry = ReadCan(path, options);
                if (import.can_optics_size() > 0)
                    created = AddCanOptics(import, field, base, scene);
                break;
        }
        const glm::dmat4 frame = ImportFrame(import.frame(), field + ".frame");
        for (Node& node : geometry.nodes) {
            node.id += import.id_offset();
            if (node.parent == kNoParent) {
                node.parent = import.parent();
                node.Edit().parentFromLocal = frame * glm::dmat4(node.parentFromLocal());
            } else {
                node.parent += import.id_offset();
            }
            if (node.organ())
                node.Edit().organ->opticsId =
                    OpticsFor(node.organ()->opticsId, import, created, field);
            scene.nodes.push_back(std::move(node));
        }
        for (Surface& surface : geometry.environment) {
            auto mesh = std::make_shared<Mesh>(*surface.mesh);
            for (glm::dvec3& p : mesh->positions) p = glm::dvec3(frame * glm::dvec4(p, 1.0));
            surface.mesh = mesh;
            surface.opticsId = OpticsFor(surface.opticsId, import, created, field);
            if (message.imports_size() > 1) surface.name += "#" + std::to_string(i);
            scene.environment.push_back(std::move(surface));
        }
    }
}

}  // namespace leaflux
