// The Open Plant Format (OPF) importer, with the small XML reader it needs: elements,
// attributes and text; no DTD, no namespaces, which OPF files do not use.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "solver/io/importers.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

// OPF lengths are centimetres.
constexpr double kMetresPerOpfUnit = 0.01;

struct XmlElement {
    std::string name;
    std::map<std::string, std::string> attributes;
    std::string text;
    std::vector<std::unique_ptr<XmlElement>> children;
    int line = 0;

    const XmlElement* Child(const std::string& childName) const {
        for (const auto& c : children) {
            if (c->name == childName) return c.get();
        }
        return nullptr;
    }
};

class XmlReader {
  public:
    XmlReader(std::string text, std::string path)
        : text_(std::move(text)), path_(std::move(path)) {}

    std::unique_ptr<XmlElement> Document() {
        SkipMisc();
        auto root = Element();
        SkipMisc();
        return root;
    }

  private:
    [[noreturn]] void Fail(const std::string& message) const {
        throw InputError(ErrorCode::kParse, path_ + ":" + std::to_string(Line()), message);
    }
    int Line() const {
        return 1 + static_cast<int>(std::count(text_.begin(), text_.begin() + at_, '\n'));
    }
    bool Starts(const char* s) const { return text_.compare(at_, std::strlen(s), s) == 0; }
    void SkipSpace() {
        while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
    }
    void SkipPast(const char* end) {
        const std::size_t found = text_.find(end, at_);
        if (found == std::string::npos) Fail(std::string("unterminated, expected ") + end);
        at_ = found + std::strlen(end);
    }
    // Declarations, comments and white space between elements.
    void SkipMisc() {
        for (;;) {
            SkipSpace();
            if (Starts("<?"))
                SkipPast("?>");
            else if (Starts("<!--"))
                SkipPast("-->");
            else if (Starts("<!"))
                SkipPast(">");
            else
                return;
        }
    }
    std::string Name() {
        const std::size_t start = at_;
        while (at_ < text_.size() &&
               (std::isalnum(static_cast<unsigned char>(text_[at_])) || text_[at_] == '_' ||
                text_[at_] == '-' || text_[at_] == ':' || text_[at_] == '.')) {
            ++at_;
        }
        if (at_ == start) Fail("expected a name");
        return text_.substr(start, at_ - start);
    }
    std::unique_ptr<XmlElement> Element() {
        if (!Starts("<")) Fail("expected an element");
        ++at_;
        auto element = std::make_unique<XmlElement>();
        element->line = Line();
        element->name = Name();
        for (;;) {
            SkipSpace();
            if (Starts("/>")) {
                at_ += 2;
                return element;
            }
            if (Starts(">")) {
                ++at_;
                break;
            }
            const std::string key = Name();
            SkipSpace();
            if (!Starts("=")) Fail("expected '=' after attribute " + key);
            ++at_;
            SkipSpace();
            const char quote = at_ < text_.size() ? text_[at_] : '\0';
            if (quote != '"' && quote != '\'') Fail("expected a quoted value for " + key);
            const std::size_t end = text_.find(quote, at_ + 1);
            if (end == std::string::npos) Fail("unterminated attribute " + key);
            element->attributes[key] = text_.substr(at_ + 1, end - at_ - 1);
            at_ = end + 1;
        }
        for (;;) {
            if (at_ >= text_.size()) Fail("element <" + element->name + "> is not closed");
            if (Starts("</")) {
                at_ += 2;
                if (Name() != element->name)
                    Fail("mismatched closing tag for <" + element->name + ">");
                SkipSpace();
                if (!Starts(">")) Fail("expected '>'");
                ++at_;
                return element;
            }
            if (Starts("<!--")) {
                SkipPast("-->");
            } else if (Starts("<")) {
                element->children.push_back(Element());
            } else {
                element->text += text_[at_++];
            }
        }
    }

    std::string text_;
    std::string path_;
    std::size_t at_ = 0;
};

std::vector<double> Numbers(const XmlElement& element, const std::string& path) {
    std::istringstream in(element.text);
    std::vector<double> values;
    std::string token;
    while (in >> token) {
        char* end = nullptr;
        const double value = std::strtod(token.c_str(), &end);
        if (*end != '\0' || !std::isfinite(value)) {
            throw InputError(ErrorCode::kParse, path + ":" + std::to_string(element.line),
                             "<" + element.name + "> holds '" + token + "', not a finite number");
        }
        values.push_back(value);
    }
    return values;
}

std::shared_ptr<Mesh> ReadMesh(const XmlElement& element, const std::string& path) {
    auto mesh = std::make_shared<Mesh>();
    const std::string at = path + ":" + std::to_string(element.line);
    const XmlElement* points = element.Child("points");
    const XmlElement* faces = element.Child("faces");
    if (!points || !faces)
        throw InputError(ErrorCode::kParse, at, "a mesh needs <points> and <faces>");
    const std::vector<double> xyz = Numbers(*points, path);
    if (xyz.size() % 3 != 0)
        throw InputError(ErrorCode::kParse, at, "<points> is not x y z triples");
    for (std::size_t i = 0; i < xyz.size(); i += 3) {
        mesh->positions.push_back(kMetresPerOpfUnit * glm::dvec3(xyz[i], xyz[i + 1], xyz[i + 2]));
    }
    for (const auto& face : faces->children) {
        const std::vector<double> corners = Numbers(*face, path);
        if (corners.size() != 3) {
            throw InputError(ErrorCode::kParse, path + ":" + std::to_string(face->line),
                             "a face needs 3 vertex indices");
        }
        for (double c : corners) {
            if (c < 0 || c >= static_cast<double>(mesh->positions.size()) || c != std::floor(c)) {
                throw InputError(ErrorCode::kParse, path + ":" + std::to_string(face->line),
                                 "face vertex index out of range");
            }
        }
        mesh->triangles.push_back(glm::uvec3(corners[0], corners[1], corners[2]));
    }
    return mesh;
}

NodeType TypeOfClass(const std::string& opfClass) {
    if (opfClass == "Individual" || opfClass == "Plant") return NodeType::kPlant;
    if (opfClass == "Axis" || opfClass == "Branch") return NodeType::kAxis;
    if (opfClass == "Phytomer" || opfClass == "GrowthUnit") return NodeType::kPhytomer;
    if (opfClass == "Leaf" || opfClass == "Leaflet") return NodeType::kLeaf;
    if (opfClass == "Internode") return NodeType::kInternode;
    if (opfClass == "Fruit") return NodeType::kFruit;
    return NodeType::kOther;
}

struct OpfContext {
    std::string path;
    std::map<int, std::shared_ptr<const Mesh>> meshes;  // by mesh Id
    std::map<int, std::pair<int, int>> shapes;          // shape Id → (mesh, material)
    ImportedGeometry result;
};

// Topology elements: decomp, branch and follow all make children of their parent.
void ReadNode(const XmlElement& element, NodeId parent, const glm::dmat4& worldFromParent,
              OpfContext& context) {
    Node node;
    const auto id = element.attributes.find("id");
    if (id == element.attributes.end()) {
        throw InputError(ErrorCode::kParse, context.path + ":" + std::to_string(element.line),
                         "<" + element.name + "> has no id");
    }
    node.id = std::stoull(id->second);
    node.parent = parent;
    const std::string opfClass =
        element.attributes.count("class") ? element.attributes.at("class") : "";
    node.type = TypeOfClass(opfClass);
    node.name = (opfClass.empty() ? "node" : opfClass) + std::to_string(node.id);
    glm::dmat4 worldFromLocal = worldFromParent;
    for (const auto& child : element.children) {
        if (child->name == "geometry") {
            if (const XmlElement* mat = child->Child("mat")) {
                const std::vector<double> m = Numbers(*mat, context.path);
                if (m.size() == 12) {
                    // Rows of [R | t]; glm is column-major. Translations are centimetres.
                    worldFromLocal = glm::dmat4(1.0);
                    for (int r = 0; r < 3; ++r) {
                        for (int c = 0; c < 3; ++c) worldFromLocal[c][r] = m[4 * r + c];
                        worldFromLocal[3][r] = kMetresPerOpfUnit * m[4 * r + 3];
                    }
                }
            }
            if (const XmlElement* shape = child->Child("shapeIndex")) {
                const std::vector<double> index = Numbers(*shape, context.path);
                const auto found = index.size() == 1
                                       ? context.shapes.find(static_cast<int>(index[0]))
                                       : context.shapes.end();
                if (found == context.shapes.end() || !context.meshes.count(found->second.first)) {
                    throw InputError(ErrorCode::kNotFound,
                                     context.path + ":" + std::to_string(shape->line),
                                     "shapeIndex names no shape with a mesh");
                }
                node.organ = Organ{context.meshes.at(found->second.first),
                                   "material" + std::to_string(found->second.second)};
            }
        } else if (child->name != "decomp" && child->name != "branch" && child->name != "follow" &&
                   child->text.find_first_not_of(" \t\r\n") != std::string::npos) {
            // Attributes declared in attributeBDD: <Length>0.1</Length>.
            std::istringstream in(child->text);
            double value;
            if (in >> value && std::isfinite(value)) node.attributes[child->name] = value;
        }
    }
    // Frames are global in OPF; leaflux stores parentFromLocal.
    node.parentFromLocal = glm::inverse(worldFromParent) * worldFromLocal;
    const NodeId self = node.id;
    context.result.nodes.push_back(std::move(node));
    for (const auto& child : element.children) {
        if (child->name == "decomp" || child->name == "branch" || child->name == "follow") {
            ReadNode(*child, self, worldFromLocal, context);
        }
    }
}

ImportedGeometry ReadOpfFile(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError(ErrorCode::kIo, path, "cannot open the file");
    std::stringstream buffer;
    buffer << in.rdbuf();
    const auto root = XmlReader(buffer.str(), path).Document();
    if (root->name != "opf")
        throw InputError(ErrorCode::kParse, path, "the root element is not <opf>");

    OpfContext context;
    context.path = path;
    if (const XmlElement* meshes = root->Child("meshBDD")) {
        for (const auto& mesh : meshes->children) {
            context.meshes[std::stoi(mesh->attributes.at("Id"))] = ReadMesh(*mesh, path);
        }
    }
    if (const XmlElement* shapes = root->Child("shapeBDD")) {
        for (const auto& shape : shapes->children) {
            const XmlElement* mesh = shape->Child("meshIndex");
            const XmlElement* material = shape->Child("materialIndex");
            if (!mesh) continue;
            const auto meshIndex = Numbers(*mesh, path);
            const auto materialIndex = material ? Numbers(*material, path) : std::vector<double>{0};
            if (meshIndex.size() != 1 || materialIndex.size() != 1) continue;
            context.shapes[std::stoi(shape->attributes.at("Id"))] = {
                static_cast<int>(meshIndex[0]), static_cast<int>(materialIndex[0])};
        }
    }
    const XmlElement* topology = root->Child("topology");
    if (!topology) throw InputError(ErrorCode::kParse, path, "no <topology>");
    ReadNode(*topology, kNoParent, glm::dmat4(1.0), context);
    return std::move(context.result);
}

}  // namespace

ImportedGeometry ReadOpf(const std::string& path) {
    try {
        return ReadOpfFile(path);
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {  // a missing Id, an id that is not a number
        throw InputError(ErrorCode::kParse, path, std::string("malformed OPF: ") + e.what());
    }
}

}  // namespace leaflux
