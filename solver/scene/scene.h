// The scene as a growth model sees it: bands, optics, a botanical topology whose organs
// carry meshes, a static environment, sources and an optional periodic domain.
//
// Invariant after Validate(): every value is finite and in its domain, every reference
// (parent, optics, band) resolves, the topology is a forest, every triangle has a positive
// area. Meshes are shared (std::shared_ptr<const Mesh>) so that organs built from one
// prototype — an OPF mesh, a leaf shape — keep that sharing: it is instancing data.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "solver/scene/attributes.h"
#include "solver/sources/sources.h"
#include "solver/util/copy_on_write.h"
#include "solver/util/interned_string.h"

namespace leaflux {

using NodeId = std::uint64_t;
inline constexpr NodeId kNoParent = 0;
// A session declares at most this many bands: every solve's work and memory grow with them.
inline constexpr int kMaxBands = 64;
// And at most this many optics: a receiver holds its optics' index in 2 bytes (Receiver).
inline constexpr int kMaxOptics = 32767;

enum class NodeType : std::uint8_t { kPlant, kAxis, kPhytomer, kLeaf, kInternode, kFruit, kOther };
const char* NodeTypeName(NodeType type);

struct Band {
    std::string name;
    double wavelengthMinNm = 0.0;  // 0 when unknown
    double wavelengthMaxNm = 0.0;
    // Photons per joule (µmol J⁻¹) as the scene gives it; 0: not given (PhotonUmolPerJ,
    // solver/scene/light_units.h, says what the band then has).
    double photonUmolPerJ = 0.0;
};

// A triangle mesh in its owner's local frame (metres). The upper side of a triangle is the
// side its normal (right-hand rule on the vertex order) points to.
struct Mesh {
    std::vector<glm::dvec3> positions;
    std::vector<glm::uvec3> triangles;
    // A shared mesh's name where it was declared ("meshes[leaf]", "meshBDD mesh 2"), so that
    // its errors name it; empty for an organ's own mesh.
    std::string name;
};

// World coordinates (m) beyond this are out of range: far past any canopy, and where
// single-precision ray tracing (Embree) can no longer tell leaves apart.
inline constexpr double kMaxCoordinateM = 1e6;

// Irradiances and exitances (W/m²) beyond this are out of range: a million times the sun,
// and far enough below the largest double that every sum of powers over a scene of
// coordinates within kMaxCoordinateM stays finite (a sun of 1e308 W/m² made NaN of it).
inline constexpr double kMaxIrradianceWm2 = 1e12;

// Whether a triangle, in coordinates within kMaxCoordinateM, has an area light can land on:
// its area does not vanish against its longest edge (the sine of its largest angle's
// complement is at least 1e-9, a sliver Embree would lose in float). The one test of
// scene validation and of the importers' skipping (ImportOptions).
bool CarriesLight(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

// Whether a frame's 3×3 part is finite and invertible (|det| > 1e-30): a singular frame
// flattens its mesh (a zero-length internode) and cannot be composed through.
bool InvertibleFrame(const glm::dmat4& frame);

// Diffuse properties of one band (Soler 2003 §4.3). Opaque surfaces have τ = 0.
struct BandOptics {
    double rhoUpper = 0.0;
    double rhoLower = 0.0;
    double tauUpperToLower = 0.0;  // of light arriving on the upper side
    double tauLowerToUpper = 0.0;  // of light arriving on the lower side
};

struct Optics {
    std::string id;
    std::vector<BandOptics> bands;  // one per scene band, in scene band order
};

struct Organ {
    std::shared_ptr<const Mesh> mesh;
    InternedString opticsId;  // one copy of each id for all the organs that name it
};

// A node's organ or none, read as a std::optional<Organ> is, in an organ's 32 bytes where
// the optional takes 40: none is an organ without a mesh, which no scene can hold.
class OptionalOrgan {
  public:
    OptionalOrgan() = default;
    OptionalOrgan(Organ organ) : organ_(std::move(organ)) {}  // NOLINT(google-explicit-constructor)

    bool has_value() const { return organ_.mesh != nullptr; }
    explicit operator bool() const { return has_value(); }
    const Organ& operator*() const { return organ_; }
    Organ& operator*() { return organ_; }
    const Organ* operator->() const { return &organ_; }
    Organ* operator->() { return &organ_; }
    void reset() { organ_ = Organ(); }

  private:
    Organ organ_;
};

// An affine frame (the fourth row 0 0 0 1 implied): its linear part, rotation and scale, in
// single precision, within 1e-7 of a structure's own size, and its translation in double,
// so that a plant far out keeps its place exactly. 64 bytes where a glm::dmat4x3 takes 96
// and a glm::dmat4 128: on a plantation of 233 trees, 17 MB of its half million nodes.
// Written from a glm::dmat4, read as one: composed as glm::dmat4(a) * glm::dmat4(b). An
// entry of the linear part beyond single precision's range (3.4e38) becomes infinite and
// the scene refuses the frame as not finite.
class Frame {
  public:
    Frame() = default;                                 // the identity
    Frame(const glm::dmat4& m) : translation_(m[3]) {  // NOLINT(google-explicit-constructor)
        for (int c = 0; c < 3; ++c) {
            for (int r = 0; r < 3; ++r) linear_[c][r] = static_cast<float>(m[c][r]);
        }
    }
    operator glm::dmat4() const {  // NOLINT(google-explicit-constructor)
        glm::dmat4 m(1.0);
        for (int c = 0; c < 3; ++c) {
            for (int r = 0; r < 3; ++r) m[c][r] = static_cast<double>(linear_[c][r]);
        }
        m[3] = glm::dvec4(translation_, 1.0);
        return m;
    }
    // Column c (0..3) of row r (0..2), as a glm::dmat4's m[c][r].
    double At(int c, int r) const {
        return c < 3 ? static_cast<double>(linear_[c][r]) : translation_[r];
    }
    bool operator==(const Frame&) const = default;

  private:
    glm::mat3 linear_{1.0f};
    glm::dvec3 translation_{0.0};
};

// What the nodes of the placed copies of one structure have in common, held once for all of
// them (Node::Edit).
struct NodeBody {
    // "" for "node<id>". With nameHasId (a placed structure's node), a pattern in which
    // "{id}" stands for the node's id: "leaf{id}" names leaf1042 and its copy leaf2042.
    std::string name;
    Frame parentFromLocal;  // z along the structure's main axis
    double age = 0.0;       // physiological age
    Attributes attributes;
    OptionalOrgan organ;
    // Last, so that the copy-on-write count fits in the padding after them: with the
    // count, 152 bytes, 160 of heap (glibc's chunks grow by 16).
    NodeType type = NodeType::kOther;
    bool nameHasId = false;
};

// A node of the botanical topology: its identity and a body that the copies of a placed
// structure share (copy on write, solver/util/copy_on_write.h). On the paper's plantation,
// 233 copies of 4 trees, a node held in full took 176 bytes, 818 MiB for its 4.3 M nodes; a
// placed copy's node takes 24, and its body is its structure's.
class Node {
  public:
    NodeId id = 0;
    NodeId parent = kNoParent;

    NodeType type() const { return body_->type; }
    // Its name as placed ("{id}" replaced), "" for none (Scene::NodeName says "node<id>").
    std::string name() const;
    const Frame& parentFromLocal() const { return body_->parentFromLocal; }
    double age() const { return body_->age; }
    const Attributes& attributes() const { return body_->attributes; }
    const OptionalOrgan& organ() const { return body_->organ; }
    // The body to change: this node's own, copied from the one it shared, if it did.
    NodeBody& Edit() { return body_.Edit(); }
    // Whether the two share one body: copies of one structure's node, unchanged since.
    bool SharesBodyWith(const Node& other) const { return body_.SharesWith(other.body_); }

  private:
    CopyOnWrite<NodeBody> body_;
};

// `pattern` with every "{id}" replaced by `id`.
std::string WithId(std::string pattern, NodeId id);

// Static environment surface (ground, wall, obstacle), in world coordinates.
struct Surface {
    std::string name;
    std::shared_ptr<const Mesh> mesh;
    std::string opticsId;
};

// The scene is one tile of an infinite canopy, repeated along x and y.
struct PeriodicDomain {
    double xMin = 0.0, yMin = 0.0, xMax = 0.0, yMax = 0.0;
};

struct Scene {
    std::vector<Band> bands;
    std::vector<Optics> optics;
    std::vector<Node> nodes;
    std::vector<Surface> environment;
    Sources sources;
    std::optional<PeriodicDomain> periodic;

    int BandIndex(const std::string& name) const;  // -1 when absent
    int OpticsIndex(const std::string& id) const;  // -1 when absent
    std::string NodeName(const Node& node) const;

    // Checks the invariant above; throws InputError naming the field or node otherwise.
    void Validate() const;
};

// Parts of Validate, for a store that checks only what a change touched (SceneStore).
// One node alone: id, frame, age, attributes, organ optics (not its parent or mesh).
void ValidateNode(const Scene& scene, const Node& node);
// A mesh placed by worldFromLocal: finite positions, triangles of positive area.
void ValidateMesh(const Mesh* mesh, const glm::dmat4& worldFromLocal, const std::string& field,
                  std::optional<NodeId> node);
void ValidateSun(const Scene& scene, const Sun& sun, const std::string& field);

// The scene restricted to some of its bands, in the order given: optics, suns, skies and
// emitters keep only those bands' values. A solver then does no work for the others.
Scene WithBands(const Scene& scene, const std::vector<int>& bands);

// Area (m²) of a triangle mesh after applying worldFromLocal.
double MeshArea(const Mesh& mesh, const glm::dmat4& worldFromLocal);
// The area of one of the mesh's triangles, in the frame worldFromLocal takes it to.
double TriangleArea(const glm::dmat4& worldFromLocal, const Mesh& mesh, const glm::uvec3& tri);

}  // namespace leaflux
