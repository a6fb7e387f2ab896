// The Open Plant Format (OPF) importer of AMAPStudio and ARCHIMED files, on pugixml.
//
// Errors name the file and the line of the element concerned; pugixml gives byte offsets,
// turned into lines only when an error is reported.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <pugixml.hpp>
#include <sstream>

#include "solver/io/importers.h"
#include "solver/io/unlit.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

// OPF lengths are centimetres.
constexpr double kMetresPerOpfUnit = 0.01;

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

class OpfReader {
  public:
    OpfReader(std::string path, const ImportOptions& options)
        : path_(std::move(path)), unlit_(path_, options) {}

    ImportedGeometry Read() {
        std::ifstream in(path_, std::ios::binary);
        if (!in) throw InputError(ErrorCode::kIo, path_, "cannot open the file");
        std::stringstream buffer;
        buffer << in.rdbuf();
        text_ = buffer.str();
        const pugi::xml_parse_result parsed =
            document_.load_buffer(text_.data(), text_.size(), pugi::parse_default);
        if (!parsed) {
            throw InputError(ErrorCode::kParse, At(static_cast<std::size_t>(parsed.offset)),
                             std::string("not well-formed XML: ") + parsed.description());
        }
        const pugi::xml_node root = document_.document_element();
        if (std::string_view(root.name()) != "opf")
            throw InputError(ErrorCode::kParse, At(root), "the root element is not <opf>");
        for (const pugi::xml_node mesh : root.child("meshBDD").children("mesh")) ReadMesh(mesh);
        for (const pugi::xml_node shape : root.child("shapeBDD").children("shape"))
            ReadShape(shape);
        const pugi::xml_node topology = root.child("topology");
        if (!topology) throw InputError(ErrorCode::kParse, At(root), "the OPF has no <topology>");
        ReadNode(topology, kNoParent, glm::dmat4(1.0));
        unlit_.Finish(result_);
        return std::move(result_);
    }

  private:
    // "file:line" of a byte offset, or of an element. The line starts are found once, on
    // the first call: a file with thousands of skipped organs names each line.
    std::string At(std::size_t offset) const {
        if (lineStarts_.empty()) {
            lineStarts_.push_back(0);
            for (std::size_t i = 0; i < text_.size(); ++i) {
                if (text_[i] == '\n') lineStarts_.push_back(i + 1);
            }
        }
        const auto after = std::upper_bound(lineStarts_.begin(), lineStarts_.end(), offset);
        return path_ + ":" + std::to_string(after - lineStarts_.begin());
    }
    std::string At(const pugi::xml_node node) const {
        const std::ptrdiff_t offset = node.offset_debug();
        return offset < 0 ? path_ : At(static_cast<std::size_t>(offset));
    }
    [[noreturn]] void Fail(const pugi::xml_node node, const std::string& message,
                           std::optional<NodeId> id = std::nullopt) const {
        throw InputError(ErrorCode::kParse, At(node), message, id);
    }

    // The numbers of an element's text; NaN and infinities are read as such, for the caller
    // to judge.
    std::vector<double> Numbers(const pugi::xml_node element) const {
        std::vector<double> values;
        const char* at = element.child_value();
        const char* end = at + std::char_traits<char>::length(at);
        for (;;) {
            while (at < end && IsSpace(*at)) ++at;
            if (at == end) return values;
            double value;
            const auto [next, error] = std::from_chars(at, end, value);
            if (error != std::errc() || (next < end && !IsSpace(*next))) {
                const char* token = at;
                while (at < end && !IsSpace(*at)) ++at;
                Fail(element, "<" + std::string(element.name()) + "> holds '" +
                                  std::string(token, at) + "', not a number");
            }
            values.push_back(value);
            at = next;
        }
    }
    std::vector<double> FiniteNumbers(const pugi::xml_node element) const {
        std::vector<double> values = Numbers(element);
        for (double v : values) {
            if (!std::isfinite(v)) {
                Fail(element, "<" + std::string(element.name()) + "> holds " + std::to_string(v) +
                                  ", not a finite number");
            }
        }
        return values;
    }
    // An integer attribute (Id, id) or element text (shapeIndex, meshIndex).
    long long Integer(const pugi::xml_node element, const char* attribute,
                      const std::string& what) const {
        const char* text = attribute ? element.attribute(attribute).value() : element.child_value();
        while (IsSpace(*text)) ++text;
        const char* end = text + std::char_traits<char>::length(text);
        while (end > text && IsSpace(end[-1])) --end;
        long long value = 0;
        const auto [next, error] = std::from_chars(text, end, value);
        if (text == end || error != std::errc() || next != end) {
            Fail(element, what + " is '" + std::string(text, end) + "', not an integer");
        }
        return value;
    }

    // A shared mesh of meshBDD. Faces of zero area are dropped here, once for every organ
    // that uses the mesh, and named by mesh and list position.
    void ReadMesh(const pugi::xml_node element) {
        const long long id = Integer(element, "Id", "<mesh> Id");
        const std::string name = "meshBDD mesh " + std::to_string(id);
        auto mesh = std::make_shared<Mesh>();
        mesh->name = name;
        const pugi::xml_node points = element.child("points");
        const pugi::xml_node faces = element.child("faces");
        if (!points || !faces) Fail(element, name + ": a mesh needs <points> and <faces>");
        const std::vector<double> xyz = FiniteNumbers(points);
        if (xyz.size() % 3 != 0) {
            Fail(points, name + ": <points> holds " + std::to_string(xyz.size()) +
                             " numbers, not x y z triples");
        }
        mesh->positions.reserve(xyz.size() / 3);
        for (std::size_t i = 0; i < xyz.size(); i += 3) {
            mesh->positions.push_back(kMetresPerOpfUnit *
                                      glm::dvec3(xyz[i], xyz[i + 1], xyz[i + 2]));
        }
        std::size_t position = 0;
        for (const pugi::xml_node face : faces.children("face")) {
            const std::string at = name + ", faces[" + std::to_string(position) + "]";
            const std::vector<double> corners = FiniteNumbers(face);
            if (corners.size() != 3) {
                Fail(face,
                     at + ": a face needs 3 vertex indices, got " + std::to_string(corners.size()));
            }
            for (double c : corners) {
                if (c < 0 || c >= static_cast<double>(mesh->positions.size()) ||
                    c != std::floor(c)) {
                    std::ostringstream message;
                    message << at << ": vertex index " << c << " is not one of the "
                            << mesh->positions.size() << " points";
                    Fail(face, message.str());
                }
            }
            const glm::uvec3 tri(corners[0], corners[1], corners[2]);
            if (CarriesLight(mesh->positions[tri.x], mesh->positions[tri.y],
                             mesh->positions[tri.z])) {
                mesh->triangles.push_back(tri);
            } else {
                unlit_.Skip({At(face), std::nullopt, name,
                             "faces[" + std::to_string(position) + "] has zero area", 1});
            }
            ++position;
        }
        if (!meshes_.emplace(id, std::move(mesh)).second)
            Fail(element, name + " is declared twice");
    }

    void ReadShape(const pugi::xml_node element) {
        const long long id = Integer(element, "Id", "<shape> Id");
        const pugi::xml_node mesh = element.child("meshIndex");
        if (!mesh) return;  // a shape without a mesh places nothing
        const pugi::xml_node material = element.child("materialIndex");
        const long long meshIndex = Integer(mesh, nullptr, "<meshIndex>");
        const long long materialIndex =
            material ? Integer(material, nullptr, "<materialIndex>") : 0;
        if (!meshes_.count(meshIndex)) {
            Fail(mesh, "shapeBDD shape " + std::to_string(id) + ": meshIndex " +
                           std::to_string(meshIndex) + " names no mesh of meshBDD");
        }
        shapes_[id] = {meshIndex, materialIndex};
    }

    static NodeType TypeOfClass(std::string_view opfClass) {
        if (opfClass == "Individual" || opfClass == "Plant") return NodeType::kPlant;
        if (opfClass == "Axis" || opfClass == "Branch") return NodeType::kAxis;
        if (opfClass == "Phytomer" || opfClass == "GrowthUnit") return NodeType::kPhytomer;
        if (opfClass == "Leaf" || opfClass == "Leaflet") return NodeType::kLeaf;
        if (opfClass == "Internode") return NodeType::kInternode;
        if (opfClass == "Fruit") return NodeType::kFruit;
        return NodeType::kOther;
    }
    static bool IsTopology(std::string_view name) {
        return name == "decomp" || name == "branch" || name == "follow";
    }

    // Topology elements: decomp, branch and follow all make children of their parent.
    // Frames are global in OPF; leaflux stores parentFromLocal, so a node whose frame is
    // singular is given one that its children can be placed against.
    void ReadNode(const pugi::xml_node element, NodeId parent, const glm::dmat4& worldFromParent) {
        if (!element.attribute("id"))
            Fail(element, "<" + std::string(element.name()) + "> has no id");
        const long long fileId = Integer(element, "id", "<" + std::string(element.name()) + "> id");
        if (fileId <= 0) Fail(element, "node id " + std::to_string(fileId) + " is not positive");
        Node node;
        node.id = static_cast<NodeId>(fileId);
        node.parent = parent;
        const std::string opfClass = element.attribute("class").value();
        node.Edit().type = TypeOfClass(opfClass);
        node.Edit().name = (opfClass.empty() ? "node" : opfClass) + std::to_string(node.id);
        glm::dmat4 worldFromLocal = worldFromParent;
        std::string unusable;  // why the node's geometry carries no light
        pugi::xml_node geometryAt = element;
        for (const pugi::xml_node child : element.children()) {
            if (child.type() != pugi::node_element) continue;
            const std::string_view name = child.name();
            if (name == "geometry") {
                geometryAt = child;
                ReadGeometry(child, node, worldFromLocal, unusable);
            } else if (!IsTopology(name)) {
                // Attributes declared in attributeBDD: <Length>0.1</Length>; text ones skipped.
                const char* text = child.child_value();
                const char* end = text + std::char_traits<char>::length(text);
                while (text < end && IsSpace(*text)) ++text;
                double value;
                const auto [next, error] = std::from_chars(text, end, value);
                if (error == std::errc() && std::all_of(next, end, IsSpace) && std::isfinite(value))
                    node.Edit().attributes[std::string(name)] = value;
            }
        }
        if (!unusable.empty() && (node.organ() || !InvertibleFrame(worldFromLocal))) {
            const bool hadOrgan = node.organ().has_value();
            const std::size_t triangles = hadOrgan ? node.organ()->mesh->triangles.size() : 0;
            unlit_.Skip({At(geometryAt), node.id, node.name(),
                         unusable + (hadOrgan ? "" : " (no mesh; its children keep their frames)"),
                         triangles});
            node.Edit().organ.reset();
            if (!InvertibleFrame(worldFromLocal)) {
                // The parent's axes at the node's own origin, when that origin is known.
                const glm::dvec4 origin = worldFromLocal[3];
                worldFromLocal = worldFromParent;
                if (std::isfinite(origin.x) && std::isfinite(origin.y) && std::isfinite(origin.z))
                    worldFromLocal[3] = glm::dvec4(glm::dvec3(origin), 1.0);
            }
        }
        node.Edit().parentFromLocal = glm::inverse(worldFromParent) * worldFromLocal;
        const NodeId self = node.id;
        result_.nodes.push_back(std::move(node));
        for (const pugi::xml_node child : element.children()) {
            if (child.type() == pugi::node_element && IsTopology(child.name()))
                ReadNode(child, self, worldFromLocal);
        }
    }

    // <geometry>: the shape, the 3×4 global `mat`, the diameters dUp and dDwn.
    void ReadGeometry(const pugi::xml_node geometry, Node& node, glm::dmat4& worldFromLocal,
                      std::string& unusable) {
        if (const pugi::xml_node mat = geometry.child("mat")) {
            const std::vector<double> m = Numbers(mat);
            if (m.size() != 12) {
                Fail(mat, "<mat> holds " + std::to_string(m.size()) + " numbers, not 3 rows of 4",
                     node.id);
            }
            // Rows of [R | t]; glm is column-major. Translations are centimetres.
            worldFromLocal = glm::dmat4(1.0);
            for (int r = 0; r < 3; ++r) {
                for (int c = 0; c < 3; ++c) worldFromLocal[c][r] = m[4 * r + c];
                worldFromLocal[3][r] = kMetresPerOpfUnit * m[4 * r + 3];
            }
            for (int r = 0; r < 3; ++r) {
                if (std::abs(worldFromLocal[3][r]) > kMaxCoordinateM) {  // false for NaN
                    std::ostringstream message;
                    message << "<mat> places the organ at "
                            << "xyz"[r] << " = " << worldFromLocal[3][r]
                            << " m, out of range (at most 1e6 m)";
                    throw InputError(ErrorCode::kInvalidArgument, At(mat), message.str(), node.id);
                }
            }
            if (!std::all_of(m.begin(), m.end(), [](double v) { return std::isfinite(v); })) {
                unusable = "<mat> is not finite";
            } else if (!InvertibleFrame(worldFromLocal)) {
                unusable =
                    "frame is singular: its mesh vanishes (a zero-length or zero-width organ)";
            }
        }
        for (const char* diameter : {"dUp", "dDwn"}) {
            const pugi::xml_node d = geometry.child(diameter);
            if (!d) continue;
            const std::vector<double> value = Numbers(d);
            if (value.size() != 1)
                Fail(d, std::string("<") + diameter + "> needs one number", node.id);
            if (!std::isfinite(value[0]) && unusable.empty()) {
                unusable = std::string(diameter) + " is " +
                           (std::isnan(value[0]) ? "NaN" : std::to_string(value[0]));
            }
        }
        if (const pugi::xml_node shape = geometry.child("shapeIndex")) {
            const long long index = Integer(shape, nullptr, "<shapeIndex>");
            const auto found = shapes_.find(index);
            if (found == shapes_.end()) {
                throw InputError(
                    ErrorCode::kNotFound, At(shape),
                    "shapeIndex " + std::to_string(index) + " names no shape of shapeBDD", node.id);
            }
            node.Edit().organ = Organ{meshes_.at(found->second.first),
                                      "material" + std::to_string(found->second.second)};
        }
    }

    std::string path_;
    std::string text_;
    mutable std::vector<std::size_t> lineStarts_;  // offsets where lines begin, built by At
    pugi::xml_document document_;
    UnlitGeometry unlit_;
    std::map<long long, std::shared_ptr<const Mesh>> meshes_;      // by mesh Id
    std::map<long long, std::pair<long long, long long>> shapes_;  // Id → (mesh, material)
    ImportedGeometry result_;
};

}  // namespace

ImportedGeometry ReadOpf(const std::string& path, const ImportOptions& options) {
    return OpfReader(path, options).Read();
}

}  // namespace leaflux
