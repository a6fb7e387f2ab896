// Line-oriented importers: Wavefront OBJ and the Caribu formats (.can, .opt, .light).
// Errors name the file and line; faces that carry no light follow solver/io/unlit.h.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>

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

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// The white-space separated fields of one line, read without streams (files of 10⁶ faces).
class Fields {
  public:
    Fields(std::string_view text, const std::string& path, int line)
        : rest_(text), path_(path), line_(line) {}

    // The next field; empty at the end of the line.
    std::string_view Next() {
        std::size_t start = 0;
        while (start < rest_.size() && IsSpace(rest_[start])) ++start;
        std::size_t end = start;
        while (end < rest_.size() && !IsSpace(rest_[end])) ++end;
        const std::string_view field = rest_.substr(start, end - start);
        rest_.remove_prefix(end);
        return field;
    }
    // The rest of the line without its surrounding white space (OBJ names may hold spaces).
    std::string_view Rest() {
        std::size_t start = 0, end = rest_.size();
        while (start < end && IsSpace(rest_[start])) ++start;
        while (end > start && IsSpace(rest_[end - 1])) --end;
        return rest_.substr(start, end - start);
    }
    double Number(const char* what) {
        const std::string_view field = Next();
        std::string_view digits = field;
        if (digits.size() > 1 && digits[0] == '+') digits.remove_prefix(1);
        double value = 0.0;
        const auto [end, error] =
            std::from_chars(digits.data(), digits.data() + digits.size(), value);
        if (field.empty() || error != std::errc() || end != digits.data() + digits.size()) {
            Fail(std::string("expected a number: ") + what +
                 (field.empty() ? "" : ", got '" + std::string(field) + "'"));
        }
        if (!std::isfinite(value)) Fail(std::string("not finite: ") + what);
        return value;
    }
    long Integer(const char* what) {
        const std::string_view field = Next();
        long value = 0;
        const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
        if (field.empty() || error != std::errc() || end != field.data() + field.size())
            Fail(std::string("expected an integer: ") + what);
        return value;
    }
    // A vertex, each coordinate within kMaxCoordinateM.
    glm::dvec3 Vertex() {
        glm::dvec3 v;
        static const char* const kAxes[] = {"vertex x", "vertex y", "vertex z"};
        for (int k = 0; k < 3; ++k) {
            v[k] = Number(kAxes[k]);
            if (std::abs(v[k]) > kMaxCoordinateM) {
                std::ostringstream text;
                text << kAxes[k] << " = " << v[k] << " is out of range (at most 1e6 in magnitude)";
                Fail(text.str());
            }
        }
        return v;
    }
    [[noreturn]] void Fail(const std::string& message) const { ParseError(path_, line_, message); }

  private:
    std::string_view rest_;
    const std::string& path_;
    int line_;
};

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
    void Start(std::string_view group, std::string_view material) {
        group_ = group;
        material_ = material;
        current_ = -1;
    }
    void Material(std::string_view material) {
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
            node.Edit().name = Unique(name);
            node.Edit().type = TypeFromName(name);
            mesh_ = std::make_shared<Mesh>();
            node.Edit().organ = Organ{mesh_, material_};
            organs_.push_back(std::move(node));
            current_ = static_cast<int>(organs_.size()) - 1;
        }
        if (owner_.size() < vertices.size()) {
            owner_.resize(vertices.size(), -1);
            local_.resize(vertices.size());
        }
        Mesh& mesh = *mesh_;
        polygon_.clear();
        for (int index : indices) {
            if (owner_[index] != current_) {  // first use of this vertex by this organ
                owner_[index] = current_;
                local_[index] = static_cast<unsigned>(mesh.positions.size());
                mesh.positions.push_back(vertices[index]);
            }
            polygon_.push_back(local_[index]);
        }
        const Node& organ = organs_[current_];
        unlit_.AddPolygon(mesh, polygon_, line, organ.name(), organ.id);
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
    // File vertex → its index in the organ that last used it (owner_), to copy each once.
    std::vector<int> owner_;
    std::vector<unsigned> local_;
    std::vector<unsigned> polygon_;
    std::map<std::string, int> names_;
};

}  // namespace

ImportedGeometry ReadObj(const std::string& path, const ImportOptions& options) {
    std::ifstream in = Open(path);
    UnlitGeometry unlit(path, options);
    std::vector<glm::dvec3> vertices;
    ObjOrgans organs(unlit);
    std::string text;
    std::vector<int> indices;
    for (int line = 1; std::getline(in, text); ++line) {
        Fields fields(text, path, line);
        const std::string_view keyword = fields.Next();
        if (keyword.empty() || keyword[0] == '#') continue;
        if (keyword == "v") {
            vertices.push_back(fields.Vertex());
        } else if (keyword == "o" || keyword == "g") {
            organs.Start(fields.Rest(), "");
        } else if (keyword == "usemtl") {
            organs.Material(fields.Next());
        } else if (keyword == "f") {
            indices.clear();
            for (std::string_view corner = fields.Next(); !corner.empty(); corner = fields.Next()) {
                // v, v/vt, v//vn or v/vt/vn; negative indices count back from the end.
                int index = 0;
                const auto [end, error] =
                    std::from_chars(corner.data(), corner.data() + corner.size(), index);
                const bool whole = end == corner.data() + corner.size() || *end == '/';
                const int resolved =
                    index < 0 ? static_cast<int>(vertices.size()) + index : index - 1;
                if (error != std::errc() || !whole || index == 0 || resolved < 0 ||
                    resolved >= static_cast<int>(vertices.size())) {
                    fields.Fail("face refers to vertex " + std::string(corner) +
                                ", not among the " + std::to_string(vertices.size()) + " so far");
                }
                indices.push_back(resolved);
            }
            if (indices.size() < 3) fields.Fail("a face needs at least 3 vertices");
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
    OrganMesh soil{std::make_shared<Mesh>(), 0, "soil"};
    const OrganMesh* last = nullptr;  // polygons of one organ come in runs
    std::pair<long, long> lastKey{-1, -1};
    std::string text;
    std::vector<unsigned> corners;
    NodeId nextId = 1;
    const auto digits = [](std::string_view label, std::size_t from, std::size_t count) {
        long value = 0;
        std::from_chars(label.data() + from, label.data() + from + count, value);
        return value;
    };
    for (int line = 1; std::getline(in, text); ++line) {
        Fields fields(text, path, line);
        const std::string_view keyword = fields.Next();
        if (keyword.empty() || keyword[0] == '#') continue;
        if (keyword != "p")
            fields.Fail("expected 'p' (a polygon), got '" + std::string(keyword) + "'");
        const long attributes = fields.Integer("attribute count");
        const std::string_view label = fields.Next();
        if (attributes < 1 || label.empty()) fields.Fail("expected an attribute count and a label");
        for (long a = 1; a < attributes; ++a) fields.Next();
        if (label.size() < 12 || !std::all_of(label.begin(), label.end(), ::isdigit)) {
            fields.Fail("label '" + std::string(label) + "' is not 12 or more digits");
        }
        const long species = digits(label, 0, label.size() - 11);
        const long plant = digits(label, label.size() - 11, 5);
        const long organ = digits(label, label.size() - 6, 3);
        const long count = fields.Integer("vertex count");
        if (count < 3) fields.Fail("a polygon needs 3 or more vertices");
        const OrganMesh* at = &soil;
        if (species != 0 && std::make_pair(plant, organ) == lastKey) {
            at = last;
        } else if (species != 0) {
            auto [found, added] = organMeshes.emplace(std::make_pair(plant, organ), OrganMesh{});
            if (added) {
                auto [plantAt, newPlant] = plantIds.emplace(plant, 0);
                if (newPlant) {
                    Node plantNode;
                    plantNode.id = plantAt->second = nextId++;
                    plantNode.Edit().type = NodeType::kPlant;
                    plantNode.Edit().name = "plant" + std::to_string(plant);
                    result.nodes.push_back(std::move(plantNode));
                }
                Node node;
                node.id = nextId++;
                node.parent = plantAt->second;
                node.Edit().type = organ == 0 ? NodeType::kInternode : NodeType::kLeaf;
                node.Edit().name =
                    "plant" + std::to_string(plant) + "_organ" + std::to_string(organ);
                const std::string material =
                    "species" + std::to_string(species) + (organ == 0 ? "_stem" : "");
                found->second = {std::make_shared<Mesh>(), node.id, node.name()};
                node.Edit().organ = Organ{found->second.mesh, material};
                result.nodes.push_back(std::move(node));
            }
            at = last = &found->second;
            lastKey = {plant, organ};
        }
        Mesh& mesh = *at->mesh;
        corners.clear();
        for (long k = 0; k < count; ++k) {
            corners.push_back(static_cast<unsigned>(mesh.positions.size()));
            mesh.positions.push_back(fields.Vertex());
        }
        unlit.AddPolygon(mesh, corners, line, at->name,
                         at == &soil ? std::nullopt : std::optional<NodeId>(at->id));
    }
    if (!soil.mesh->positions.empty()) result.environment.push_back({"soil", soil.mesh, "soil"});
    if (result.nodes.empty() && result.environment.empty())
        throw InputError(ErrorCode::kParse, path, "no polygon in the file");
    unlit.Finish(result);
    return result;
}

CanOptics ReadCanOptics(const std::string& path) {
    std::ifstream in = Open(path);
    CanOptics optics;
    std::string text;
    for (int line = 1; std::getline(in, text); ++line) {
        Fields fields(text, path, line);
        // A value is "d <ρ>" for opaque parts and "d <ρ> <τ>" for leaf faces (d: diffuse).
        auto diffuse = [&] {
            if (fields.Next() != "d") fields.Fail("expected 'd' (diffuse)");
        };
        const std::string_view keyword = fields.Next();
        if (keyword.empty() || keyword[0] == '#' || keyword == "n") continue;
        if (keyword == "s") {
            diffuse();
            optics.soilRho = fields.Number("soil reflectance");
        } else if (keyword == "e") {
            CanOptics::Species s;
            diffuse();
            s.stemRho = fields.Number("stem reflectance");
            diffuse();
            s.leaf.rhoUpper = fields.Number("upper reflectance");
            s.leaf.tauUpperToLower = fields.Number("upper transmittance");
            diffuse();
            s.leaf.rhoLower = fields.Number("lower reflectance");
            s.leaf.tauLowerToUpper = fields.Number("lower transmittance");
            optics.species.push_back(s);
        } else {
            fields.Fail("unknown line '" + std::string(keyword) + "'");
        }
    }
    return optics;
}

std::vector<CanLight> ReadCanLights(const std::string& path) {
    std::ifstream in = Open(path);
    std::vector<CanLight> lights;
    std::string text;
    for (int line = 1; std::getline(in, text); ++line) {
        Fields fields(text, path, line);
        if (text.find_first_not_of(" \t\r") == std::string::npos || text[0] == '#') continue;
        CanLight light;
        light.horizontalIrradiance = fields.Number("energy");
        glm::dvec3 travel;
        travel.x = fields.Number("vx");
        travel.y = fields.Number("vy");
        travel.z = fields.Number("vz");
        if (glm::length(travel) == 0.0) fields.Fail("zero direction");
        light.towardSource = -glm::normalize(travel);
        lights.push_back(light);
    }
    return lights;
}

}  // namespace leaflux
