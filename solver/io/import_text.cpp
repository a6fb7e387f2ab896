// Line-oriented importers: Wavefront OBJ and the Caribu formats (.can, .opt, .light).
// Errors name the file and line; faces that carry no light follow solver/io/unlit.h.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "solver/io/importers.h"
#include "solver/io/unlit.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

std::ifstream Open(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError(ErrorCode::kIo, path, "cannot open the file");
    return in;
}

[[noreturn]] void ParseError(const std::string& path, int line, const std::string& message) {
    throw InputError(ErrorCode::kParse, path + ":" + std::to_string(line), message);
}

double ReadNumber(std::istringstream& in, const std::string& path, int line, const char* what) {
    double value;
    if (!(in >> value)) ParseError(path, line, std::string("expected a number: ") + what);
    if (!std::isfinite(value)) ParseError(path, line, std::string("not finite: ") + what);
    return value;
}

// A vertex, each coordinate within kMaxCoordinateM.
glm::dvec3 ReadVertex(std::istringstream& in, const std::string& path, int line, const char* what) {
    glm::dvec3 v;
    const char* axes[] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
        const std::string name = std::string(what) + " " + axes[k];
        v[k] = ReadNumber(in, path, line, name.c_str());
        if (std::abs(v[k]) > kMaxCoordinateM) {
            std::ostringstream text;
            text << name << " = " << v[k] << " is out of range (at most 1e6 in magnitude)";
            ParseError(path, line, text.str());
        }
    }
    return v;
}

NodeType TypeFromName(std::string name) {
    std::transform(name.begin(), name.end(), name.begin(), ::tolower);
    if (name.find("leaf") != std::string::npos) return NodeType::kLeaf;
    if (name.find("internode") != std::string::npos || name.find("stem") != std::string::npos) {
        return NodeType::kInternode;
    }
    if (name.find("fruit") != std::string::npos) return NodeType::kFruit;
    return NodeType::kOther;
}

// Builds organs as faces arrive; vertices are shared file-wide, copied per organ.
class ObjOrgans {
  public:
    explicit ObjOrgans(UnlitGeometry& unlit) : unlit_(unlit) {}
    void Start(const std::string& group, const std::string& material) {
        group_ = group;
        material_ = material;
        current_ = -1;
    }
    void Material(const std::string& material) {
        if (material == material_) return;
        material_ = material;
        // A second material in a group starts a new organ.
        if (current_ >= 0) current_ = -1, split_ = true;
    }
    void Face(const std::vector<glm::dvec3>& vertices, const std::vector<int>& indices, int line) {
        if (current_ < 0) {
            std::string name = group_.empty() ? "object" : group_;
            if (split_) name += "/" + material_;
            split_ = false;
            Node node;
            node.id = static_cast<NodeId>(organs_.size() + 1);
            node.name = Unique(name);
            node.type = TypeFromName(name);
            mesh_ = std::make_shared<Mesh>();
            node.organ = Organ{mesh_, material_};
            organs_.push_back(std::move(node));
            remap_.clear();
            current_ = static_cast<int>(organs_.size()) - 1;
        }
        Mesh& mesh = *mesh_;
        std::vector<unsigned> local;
        for (int index : indices) {
            auto [it, added] = remap_.emplace(index, static_cast<unsigned>(mesh.positions.size()));
            if (added) mesh.positions.push_back(vertices[index]);
            local.push_back(it->second);
        }
        const Node& organ = organs_[current_];
        unlit_.AddPolygon(mesh, local, line, organ.name, organ.id);
    }
    std::vector<Node> Take() { return std::move(organs_); }

  private:
    std::string Unique(const std::string& name) {
        const int seen = names_[name]++;
        return seen == 0 ? name : name + "#" + std::to_string(seen + 1);
    }
    UnlitGeometry& unlit_;
    std::string group_, material_;
    int current_ = -1;
    std::shared_ptr<Mesh> mesh_;  // the current organ's, still being filled
    bool split_ = false;
    std::vector<Node> organs_;
    std::map<int, unsigned> remap_;
    std::map<std::string, int> names_;
};

}  // namespace

ImportedGeometry ReadObj(const std::string& path, const ImportOptions& options) {
    std::ifstream in = Open(path);
    UnlitGeometry unlit(path, options);
    std::vector<glm::dvec3> vertices;
    ObjOrgans organs(unlit);
    std::string text;
    for (int line = 1; std::getline(in, text); ++line) {
        std::istringstream fields(text);
        std::string keyword;
        if (!(fields >> keyword) || keyword[0] == '#') continue;
        if (keyword == "v") {
            vertices.push_back(ReadVertex(fields, path, line, "vertex"));
        } else if (keyword == "o" || keyword == "g") {
            std::string name;
            std::getline(fields >> std::ws, name);
            organs.Start(name, "");
        } else if (keyword == "usemtl") {
            std::string material;
            fields >> material;
            organs.Material(material);
        } else if (keyword == "f") {
            std::vector<int> indices;
            std::string corner;
            while (fields >> corner) {
                // v, v/vt, v//vn or v/vt/vn; negative indices count back from the end.
                const int index = std::atoi(corner.c_str());
                const int resolved =
                    index < 0 ? static_cast<int>(vertices.size()) + index : index - 1;
                if (index == 0 || resolved < 0 || resolved >= static_cast<int>(vertices.size())) {
                    ParseError(path, line,
                               "face refers to vertex " + corner + ", not among the " +
                                   std::to_string(vertices.size()) + " so far");
                }
                indices.push_back(resolved);
            }
            if (indices.size() < 3) ParseError(path, line, "a face needs at least 3 vertices");
            organs.Face(vertices, indices, line);
        }
        // vt, vn, s, mtllib and the rest carry nothing leaflux uses.
    }
    ImportedGeometry result;
    result.nodes = organs.Take();
    if (result.nodes.empty()) throw InputError(ErrorCode::kParse, path, "no face in the file");
    unlit.Finish(result);
    return result;
}

ImportedGeometry ReadCan(const std::string& path, const ImportOptions& options) {
    std::ifstream in = Open(path);
    UnlitGeometry unlit(path, options);
    ImportedGeometry result;
    // (plant, organ) → its mesh, node id and name; plant → its node id.
    struct OrganMesh {
        std::shared_ptr<Mesh> mesh;
        NodeId id = 0;
        std::string name;
    };
    std::map<std::pair<long, long>, OrganMesh> organMeshes;
    std::map<long, NodeId> plantIds;
    auto soil = std::make_shared<Mesh>();
    std::string text;
    NodeId nextId = 1;
    for (int line = 1; std::getline(in, text); ++line) {
        std::istringstream fields(text);
        std::string keyword;
        if (!(fields >> keyword) || keyword[0] == '#') continue;
        if (keyword != "p")
            ParseError(path, line, "expected 'p' (a polygon), got '" + keyword + "'");
        int attributes = 0;
        std::string label;
        if (!(fields >> attributes) || attributes < 1 || !(fields >> label)) {
            ParseError(path, line, "expected an attribute count and a label");
        }
        for (int a = 1; a < attributes; ++a) {
            std::string ignored;
            fields >> ignored;
        }
        if (label.size() < 12 || !std::all_of(label.begin(), label.end(), ::isdigit)) {
            ParseError(path, line, "label '" + label + "' is not 12 or more digits");
        }
        const long species = std::stol(label.substr(0, label.size() - 11));
        const long plant = std::stol(label.substr(label.size() - 11, 5));
        const long organ = std::stol(label.substr(label.size() - 6, 3));
        int count = 0;
        if (!(fields >> count) || count < 3)
            ParseError(path, line, "a polygon needs 3 or more vertices");
        std::vector<glm::dvec3> polygon(count);
        for (glm::dvec3& v : polygon) v = ReadVertex(fields, path, line, "vertex");
        Mesh* mesh = soil.get();
        std::string organName = "soil";
        std::optional<NodeId> organId;
        if (species != 0) {
            auto [at, added] = organMeshes.emplace(std::make_pair(plant, organ), OrganMesh{});
            if (added) {
                auto [plantAt, newPlant] = plantIds.emplace(plant, 0);
                if (newPlant) {
                    Node plantNode;
                    plantNode.id = plantAt->second = nextId++;
                    plantNode.type = NodeType::kPlant;
                    plantNode.name = "plant" + std::to_string(plant);
                    result.nodes.push_back(std::move(plantNode));
                }
                Node node;
                node.id = nextId++;
                node.parent = plantAt->second;
                node.type = organ == 0 ? NodeType::kInternode : NodeType::kLeaf;
                node.name = "plant" + std::to_string(plant) + "_organ" + std::to_string(organ);
                const std::string material =
                    "species" + std::to_string(species) + (organ == 0 ? "_stem" : "");
                at->second.mesh = std::make_shared<Mesh>();
                at->second.id = node.id;
                at->second.name = node.name;
                node.organ = Organ{at->second.mesh, material};
                result.nodes.push_back(std::move(node));
            }
            mesh = at->second.mesh.get();
            organName = at->second.name;
            organId = at->second.id;
        }
        const auto first = static_cast<unsigned>(mesh->positions.size());
        mesh->positions.insert(mesh->positions.end(), polygon.begin(), polygon.end());
        std::vector<unsigned> corners(count);
        for (int k = 0; k < count; ++k) corners[k] = first + k;
        unlit.AddPolygon(*mesh, corners, line, organName, organId);
    }
    if (!soil->positions.empty()) result.environment.push_back({"soil", soil, "soil"});
    if (result.nodes.empty() && result.environment.empty())
        throw InputError(ErrorCode::kParse, path, "no polygon in the file");
    unlit.Finish(result);
    return result;
}

CanOptics ReadCanOptics(const std::string& path) {
    std::ifstream in = Open(path);
    CanOptics optics;
    std::string text;
    // A value is "d <ρ>" for opaque parts and "d <ρ> <τ>" for leaf faces (d: diffuse).
    auto expectDiffuse = [&](std::istringstream& fields, int line) {
        std::string kind;
        if (!(fields >> kind) || kind != "d") ParseError(path, line, "expected 'd' (diffuse)");
    };
    for (int line = 1; std::getline(in, text); ++line) {
        std::istringstream fields(text);
        std::string keyword;
        if (!(fields >> keyword) || keyword[0] == '#' || keyword == "n") continue;
        if (keyword == "s") {
            expectDiffuse(fields, line);
            optics.soilRho = ReadNumber(fields, path, line, "soil reflectance");
        } else if (keyword == "e") {
            CanOptics::Species s;
            expectDiffuse(fields, line);
            s.stemRho = ReadNumber(fields, path, line, "stem reflectance");
            expectDiffuse(fields, line);
            s.leaf.rhoUpper = ReadNumber(fields, path, line, "upper reflectance");
            s.leaf.tauUpperToLower = ReadNumber(fields, path, line, "upper transmittance");
            expectDiffuse(fields, line);
            s.leaf.rhoLower = ReadNumber(fields, path, line, "lower reflectance");
            s.leaf.tauLowerToUpper = ReadNumber(fields, path, line, "lower transmittance");
            optics.species.push_back(s);
        } else {
            ParseError(path, line, "unknown line '" + keyword + "'");
        }
    }
    return optics;
}

std::vector<CanLight> ReadCanLights(const std::string& path) {
    std::ifstream in = Open(path);
    std::vector<CanLight> lights;
    std::string text;
    for (int line = 1; std::getline(in, text); ++line) {
        std::istringstream fields(text);
        if (text.find_first_not_of(" \t\r") == std::string::npos || text[0] == '#') continue;
        CanLight light;
        light.horizontalIrradiance = ReadNumber(fields, path, line, "energy");
        glm::dvec3 travel;
        travel.x = ReadNumber(fields, path, line, "vx");
        travel.y = ReadNumber(fields, path, line, "vy");
        travel.z = ReadNumber(fields, path, line, "vz");
        if (glm::length(travel) == 0.0) ParseError(path, line, "zero direction");
        light.towardSource = -glm::normalize(travel);
        lights.push_back(light);
    }
    return lights;
}

}  // namespace leaflux
