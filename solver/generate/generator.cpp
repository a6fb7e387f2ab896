#include "solver/generate/generator.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>
#include <map>
#include <utility>

#include "solver/scene/geometry.h"
#include "solver/util/check.h"
#include "solver/util/error.h"
#include "solver/util/sampling.h"

namespace leaflux {
namespace {

constexpr double kGoldenAngleDeg = 137.5;

glm::dmat4 FrameOf(const glm::dvec3& origin, const glm::dvec3& x, const glm::dvec3& y,
                   const glm::dvec3& z) {
    glm::dmat4 m(1.0);
    m[0] = glm::dvec4(x, 0.0);
    m[1] = glm::dvec4(y, 0.0);
    m[2] = glm::dvec4(z, 0.0);
    m[3] = glm::dvec4(origin, 1.0);
    return m;
}

glm::dvec3 AnyPerpendicular(const glm::dvec3& a) {
    return glm::normalize(
        glm::cross(a, std::abs(a.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0)));
}

// `v` turned by `angle` around the unit axis `k` (Rodrigues).
glm::dvec3 Rotate(const glm::dvec3& v, const glm::dvec3& k, double angle) {
    return v * std::cos(angle) + glm::cross(k, v) * std::sin(angle) +
           k * glm::dot(k, v) * (1.0 - std::cos(angle));
}

// The frame of an axis starting at the origin of `worldFromParent`, z along `direction`.
glm::dmat4 AxisFrame(const glm::dmat4& worldFromParent, const glm::dvec3& direction) {
    const glm::dvec3 base(worldFromParent[3]);
    const glm::dvec3 side = AnyPerpendicular(direction);
    return FrameOf(base, side, glm::cross(direction, side), direction);
}

// The generated name of a node, "<type><id>".
std::string GeneratedName(NodeType type, NodeId id) {
    return NodeTypeName(type) + std::to_string(id);
}

// Appends a copy of scene.nodes[begin, end): a subtree rooted at nodes[begin] whose ids run
// contiguously from the root's, as the generator makes them. The copy's ids run from
// `firstId`, its root hangs from `parent` at `parentFromLocal`, every other node keeps its
// frame: the copy is exact in its root's frame. Generated names follow the new ids. Returns
// the next free id.
NodeId AppendCopy(Scene& scene, std::size_t begin, std::size_t end, NodeId firstId, NodeId parent,
                  const glm::dmat4& parentFromLocal) {
    const NodeId from = scene.nodes[begin].id;
    for (std::size_t i = begin; i < end; ++i) {
        Node node = scene.nodes[i];
        LEAFLUX_CHECK_EQ(node.id, from + (i - begin));
        const bool generatedName = node.name() == GeneratedName(node.type(), node.id);
        node.id = node.id - from + firstId;
        if (i == begin) {
            node.parent = parent;
            node.Edit().parentFromLocal = parentFromLocal;
        } else {
            node.parent = node.parent - from + firstId;
        }
        if (generatedName) node.Edit().name = GeneratedName(node.type(), node.id);
        scene.nodes.push_back(std::move(node));
    }
    return firstId + (end - begin);
}

std::shared_ptr<const Mesh> LeafPrototype() {
    // A rhombic blade along local x from the petiole (0) to the tip (1), of width 1
    // across y: two triangles, area 1/2 in local units.
    auto mesh = std::make_shared<Mesh>();
    mesh->positions = {{0, 0, 0}, {0.4, -0.5, 0}, {1, 0, 0}, {0.4, 0.5, 0}};
    mesh->triangles = {{0, 1, 2}, {0, 2, 3}};
    return mesh;
}

std::shared_ptr<const Mesh> InternodePrototype() {
    // A triangular prism of unit width around local z, from z = 0 to 1, faces outwards
    // and no caps: six triangles, the least that still casts a shadow from every side.
    auto mesh = std::make_shared<Mesh>();
    for (double z : {0.0, 1.0}) {
        for (int k = 0; k < 3; ++k) {
            const double a = 2.0 * glm::pi<double>() * k / 3.0;
            mesh->positions.push_back({0.5 * std::cos(a), 0.5 * std::sin(a), z});
        }
    }
    for (unsigned i = 0; i < 3; ++i) {
        const unsigned j = (i + 1) % 3;
        mesh->triangles.push_back({i, j, j + 3});
        mesh->triangles.push_back({i, j + 3, i + 3});
    }
    return mesh;
}

class TreeBuilder {
  public:
    TreeBuilder(Scene& scene, const TreeParameters& p, NodeId firstId)
        : scene_(scene),
          p_(p),
          next_(firstId),
          leaf_(LeafPrototype()),
          internode_(InternodePrototype()) {
        const int shoots = (p.leafCount + p.leavesPerShoot - 1) / p.leavesPerShoot;
        depth_ = 0;
        while (std::pow(p.maxBranching, depth_) < shoots) ++depth_;
        branching_ =
            depth_ == 0 ? 1 : static_cast<int>(std::ceil(std::pow(shoots, 1.0 / depth_) - 1e-9));
        trunkLengthM_ = 0.3 * std::cbrt(static_cast<double>(p.leafCount)) * (p.leafLengthM / 0.1);
    }

    NodeId Build(const glm::dvec3& base) {
        Node plant;
        plant.id = next_++;
        plant.Edit().type = NodeType::kPlant;
        plant.Edit().name = "plant" + std::to_string(plant.id);
        const glm::dmat4 world = FrameOf(base, {1, 0, 0}, {0, 1, 0}, {0, 0, 1});
        plant.Edit().parentFromLocal = world;
        const NodeId plantId = plant.id;
        scene_.nodes.push_back(std::move(plant));
        Random random(StreamSeed(p_.seed, 0));
        Axis(plantId, world, glm::dvec3(0, 0, 1), 0, p_.leafCount, random);
        return next_;
    }

  private:
    // Leaves an axis of depth `depth` can carry.
    long Capacity(int depth) const {
        long capacity = p_.leavesPerShoot;
        for (int d = depth; d < depth_; ++d) capacity *= branching_;
        return capacity;
    }

    NodeId Add(Node node, NodeId parent, const glm::dmat4& worldFromParent,
               const glm::dmat4& world) {
        node.id = next_++;
        node.parent = parent;
        node.Edit().parentFromLocal = glm::inverse(worldFromParent) * world;
        if (node.name().empty())
            node.Edit().name = NodeTypeName(node.type()) + std::to_string(node.id);
        scene_.nodes.push_back(std::move(node));
        return scene_.nodes.back().id;
    }

    // A lateral axis in copies mode: a copy of the prototype of its depth and leaf count, the
    // prototype drawn (from a stream of that class) where the first of them grows.
    void CopiedAxis(NodeId parent, const glm::dmat4& worldFromParent, const glm::dvec3& direction,
                    int depth, long leaves) {
        const std::pair<int, long> key(depth, leaves);
        if (const auto it = prototypes_.find(key); it != prototypes_.end()) {
            next_ =
                AppendCopy(scene_, it->second.first, it->second.second, next_, parent,
                           glm::inverse(worldFromParent) * AxisFrame(worldFromParent, direction));
            return;
        }
        const std::size_t begin = scene_.nodes.size();
        Random random(StreamSeed(p_.seed, 0xC0B1E5 + static_cast<std::uint64_t>(depth),
                                 static_cast<std::uint64_t>(leaves)));
        Axis(parent, worldFromParent, direction, depth, leaves, random);
        prototypes_[key] = {begin, scene_.nodes.size()};
    }

    void Axis(NodeId parent, const glm::dmat4& worldFromParent, const glm::dvec3& direction,
              int depth, long leaves, Random& random) {
        const glm::dvec3 base(worldFromParent[3]);
        const glm::dvec3 side = AnyPerpendicular(direction);
        const glm::dmat4 world = AxisFrame(worldFromParent, direction);
        Node axis;
        axis.Edit().type = NodeType::kAxis;
        axis.Edit().age = depth;
        axis.Edit().attributes["order"] = depth;
        const NodeId axisId = Add(std::move(axis), parent, worldFromParent, world);

        const bool shoot = depth >= depth_;
        const long childCapacity = shoot ? 1 : Capacity(depth + 1);
        const int phytomers = static_cast<int>((leaves + childCapacity - 1) / childCapacity);
        const double length =
            std::max(trunkLengthM_ * std::pow(0.55, depth), 0.35 * p_.leafLengthM * phytomers);
        const double width = std::max(0.004, 0.03 * trunkLengthM_ * std::pow(0.5, depth) / 5.0);
        const double firstAt = shoot ? 0.1 : (depth == 0 ? 0.35 : 0.2);
        double previous = 0.0;
        long left = leaves;
        for (int i = 0; i < phytomers; ++i) {
            const double s = length * (firstAt + (1.0 - firstAt) * (i + 1.0) / phytomers);
            const glm::dvec3 at = base + direction * s;
            const glm::dmat4 phytomerWorld =
                FrameOf(at, side, glm::cross(direction, side), direction);
            Node phytomer;
            phytomer.Edit().type = NodeType::kPhytomer;
            phytomer.Edit().age = depth;
            const NodeId phytomerId = Add(std::move(phytomer), axisId, world, phytomerWorld);
            // Twigs of the leafy shoots carry no geometry: thin against the leaves around
            // them, they would multiply the triangles for little light.
            if (p_.internodes && !shoot) {
                Node internode;
                internode.Edit().type = NodeType::kInternode;
                internode.Edit().organ = Organ{internode_, p_.stemOptics};
                const glm::dvec3 from = base + direction * previous;
                Add(std::move(internode), phytomerId, phytomerWorld,
                    FrameOf(from, side * width, glm::cross(direction, side) * width,
                            direction * (s - previous)));
            }
            previous = s;
            const double phyllotaxy =
                glm::radians(kGoldenAngleDeg * i + 20.0 * (random.Uniform() - 0.5));
            const glm::dvec3 around = Rotate(side, direction, phyllotaxy);
            const long here = std::min(left, childCapacity);
            left -= here;
            if (shoot) {
                Leaf(phytomerId, phytomerWorld, at, around, random);
                continue;
            }
            const double angle = glm::radians(p_.branchAngleDeg + 10.0 * (random.Uniform() - 0.5));
            const glm::dvec3 lateral =
                glm::normalize(std::cos(angle) * direction + std::sin(angle) * around);
            if (p_.copies) {
                CopiedAxis(phytomerId, phytomerWorld, lateral, depth + 1, here);
                continue;
            }
            Random childRandom(StreamSeed(p_.seed, next_));
            Axis(phytomerId, FrameOf(at, side, glm::cross(direction, side), direction), lateral,
                 depth + 1, here, childRandom);
        }
    }

    // A blade pointing away from the axis along `around`, inclined and rolled at random.
    void Leaf(NodeId phytomer, const glm::dmat4& phytomerWorld, const glm::dvec3& at,
              const glm::dvec3& around, Random& random) {
        glm::dvec3 horizontal(around.x, around.y, 0.0);
        horizontal =
            glm::length(horizontal) > 1e-6 ? glm::normalize(horizontal) : glm::dvec3(1, 0, 0);
        const glm::dvec3 across = glm::normalize(glm::cross(glm::dvec3(0, 0, 1), horizontal));
        const double inclination =
            glm::radians(p_.leafInclinationDeg + 40.0 * (random.Uniform() - 0.5));
        const double roll = glm::radians(30.0 * (random.Uniform() - 0.5));
        const glm::dvec3 blade = Rotate(horizontal, across, inclination);  // droops down
        const glm::dvec3 width = Rotate(across, blade, roll);
        const glm::dvec3 normal = glm::cross(blade, width);
        const double length = p_.leafLengthM * (0.8 + 0.4 * random.Uniform());
        Node leaf;
        leaf.Edit().type = NodeType::kLeaf;
        leaf.Edit().organ = Organ{leaf_, p_.leafOptics};
        leaf.Edit().attributes["length_m"] = length;
        Add(std::move(leaf), phytomer, phytomerWorld,
            FrameOf(at, blade * length, width * (0.6 * length), normal));
    }

    Scene& scene_;
    const TreeParameters& p_;
    NodeId next_;
    std::shared_ptr<const Mesh> leaf_, internode_;
    int depth_ = 0;
    int branching_ = 1;
    double trunkLengthM_ = 1.0;
    // Copies mode: (depth, leaves) → the prototype's range in scene_.nodes.
    std::map<std::pair<int, long>, std::pair<std::size_t, std::size_t>> prototypes_;
};

}  // namespace

NodeId AddTree(Scene& scene, const TreeParameters& parameters, const glm::dvec3& base,
               NodeId firstId) {
    if (parameters.leafCount < 1 || parameters.leafCount > 10'000'000) {
        throw InputError(ErrorCode::kInvalidArgument, "leaf_count", "must be between 1 and 10^7");
    }
    if (parameters.leavesPerShoot < 1 || parameters.maxBranching < 2) {
        throw InputError(ErrorCode::kInvalidArgument, "leaves_per_shoot",
                         "needs at least 1 leaf per shoot and a branching of 2");
    }
    if (!(parameters.leafLengthM > 0.0) || !std::isfinite(parameters.leafLengthM)) {
        throw InputError(ErrorCode::kInvalidArgument, "leaf_length_m", "must be positive");
    }
    return TreeBuilder(scene, parameters, firstId).Build(base);
}

namespace {

// The plantation's axes and extent: `along` the rows, `across` them; a point (u, v, z) of
// the unit square [−1, 1]² maps to the corners of the ground the trees stand on.
struct PlantationFrame {
    glm::dvec3 along, across;
    double halfAlong, halfAcross;

    explicit PlantationFrame(const PlantationParameters& p) {
        const double azimuth = glm::radians(p.rowAzimuthDeg);
        along = {std::sin(azimuth), std::cos(azimuth), 0.0};
        across = {along.y, -along.x, 0.0};
        halfAlong = 0.5 * p.columns * p.columnSpacingM + p.jitterM;
        halfAcross = 0.5 * p.rows * p.rowSpacingM + p.jitterM;
    }
    glm::dvec3 At(const glm::dvec3& unit) const {
        return unit.x * halfAlong * along + unit.y * halfAcross * across + glm::dvec3(0, 0, unit.z);
    }
};

// The planar quad a b c d (in order round it) with its upper side towards `facing`.
std::shared_ptr<Mesh> QuadFacing(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d,
                                 const glm::dvec3& facing) {
    auto mesh = std::make_shared<Mesh>();
    mesh->positions = {a, b, c, d};
    mesh->triangles = glm::dot(glm::cross(b - a, c - a), facing) > 0.0
                          ? std::vector<glm::uvec3>{{0, 1, 2}, {0, 2, 3}}
                          : std::vector<glm::uvec3>{{0, 2, 1}, {0, 3, 2}};
    return mesh;
}

}  // namespace

void AddPlantation(Scene& scene, const PlantationParameters& parameters,
                   const std::string& groundOptics) {
    if (parameters.rows < 1 || parameters.columns < 1) {
        throw InputError(ErrorCode::kInvalidArgument, "rows", "needs at least one row and column");
    }
    const PlantationFrame frame(parameters);
    NodeId next = 1;
    for (const Node& node : scene.nodes) next = std::max(next, node.id + 1);
    if (parameters.tree.copies && parameters.prototypes < 1) {
        throw InputError(ErrorCode::kInvalidArgument, "prototypes", "needs at least one");
    }
    Random jitter(StreamSeed(parameters.tree.seed, 0xB0A7));
    Random turn(StreamSeed(parameters.tree.seed, 0x7E11));        // copies' azimuths
    std::vector<std::pair<std::size_t, std::size_t>> prototypes;  // ranges in scene.nodes
    const int trees =
        parameters.trees > 0 ? parameters.trees : parameters.rows * parameters.columns;
    for (int r = 0, placed = 0; r < parameters.rows; ++r) {
        for (int c = 0; c < parameters.columns && placed < trees; ++c, ++placed) {
            if (parameters.progress) parameters.progress(static_cast<double>(placed) / trees);
            const double x = (c - 0.5 * (parameters.columns - 1)) * parameters.columnSpacingM +
                             parameters.jitterM * (2.0 * jitter.Uniform() - 1.0);
            const double y = (r - 0.5 * (parameters.rows - 1)) * parameters.rowSpacingM +
                             parameters.jitterM * (2.0 * jitter.Uniform() - 1.0);
            const glm::dvec3 base = x * frame.along + y * frame.across;
            const std::size_t prototype =
                parameters.tree.copies ? placed % parameters.prototypes : prototypes.size();
            if (prototype < prototypes.size()) {
                const double azimuth = 2.0 * glm::pi<double>() * turn.Uniform();
                const glm::dvec3 east(std::cos(azimuth), std::sin(azimuth), 0.0);
                next = AppendCopy(scene, prototypes[prototype].first, prototypes[prototype].second,
                                  next, kNoParent,
                                  FrameOf(base, east, {-east.y, east.x, 0.0}, {0, 0, 1}));
                continue;
            }
            TreeParameters tree = parameters.tree;
            tree.seed = StreamSeed(parameters.tree.seed, r, c);
            const std::size_t begin = scene.nodes.size();
            next = AddTree(scene, tree, base, next);
            if (parameters.tree.copies) prototypes.emplace_back(begin, scene.nodes.size());
        }
    }
    if (parameters.progress) parameters.progress(1.0);
    if (groundOptics.empty()) return;
    const glm::dvec3 a = frame.At({-1, -1, 0}), b = frame.At({1, -1, 0}), c = frame.At({1, 1, 0}),
                     d = frame.At({-1, 1, 0});
    scene.environment.push_back({"ground", QuadFacing(a, b, c, d, {0, 0, 1}), groundOptics});
}

void AddGreenhouse(Scene& scene, const GreenhouseParameters& p) {
    if (!(p.wallHeightM > 0.0) || !(p.lampHeightM > 0.0) || !(p.lampHeightM <= p.wallHeightM) ||
        !(p.lampWidthM > 0.0)) {
        throw InputError(ErrorCode::kInvalidArgument, "greenhouse",
                         "needs 0 < lamp height <= wall height and a positive lamp width");
    }
    if (p.lampExitanceWm2.size() != scene.bands.size()) {
        throw InputError(ErrorCode::kInvalidArgument, "greenhouse.lamp_exitance",
                         "needs one exitance per band");
    }
    AddPlantation(scene, p.plantation, "");
    // The house stands 20 cm clear of the plants, whatever their crowns: a leaf through a
    // wall would be lit by the lamps of a room it is not in.
    const FlatScene plants = Flatten(scene);
    const glm::dvec3 low = plants.origin + plants.boundsMin - glm::dvec3(0.2, 0.2, 0.0);
    const glm::dvec3 high = plants.origin + plants.boundsMax + glm::dvec3(0.2, 0.2, 0.0);
    const glm::dvec3 corners[4] = {
        {low.x, low.y, 0}, {high.x, low.y, 0}, {high.x, high.y, 0}, {low.x, high.y, 0}};
    scene.environment.push_back(
        {"floor", QuadFacing(corners[0], corners[1], corners[2], corners[3], {0, 0, 1}),
         p.floorOptics});
    const glm::dvec3 up(0, 0, p.wallHeightM), middle = 0.5 * (low + high);
    for (int w = 0; w < 4; ++w) {
        const glm::dvec3 a = corners[w], b = corners[(w + 1) % 4];
        const glm::dvec3 inwards = glm::dvec3(middle.x, middle.y, 0) - 0.5 * (a + b);
        scene.environment.push_back(
            {"wall" + std::to_string(w), QuadFacing(a, a + up, b + up, b, inwards), p.wallOptics});
    }
    const PlantationFrame frame(p.plantation);
    // Rows run along `along`, at the plantation's row positions across.
    const PlantationParameters& plantation = p.plantation;
    const double halfLength = 0.4 * plantation.columns * plantation.columnSpacingM;
    for (int r = 0; r < plantation.rows; ++r) {
        const double y = (r - 0.5 * (plantation.rows - 1)) * plantation.rowSpacingM;
        auto corner = [&](double u, double v) {
            return u * halfLength * frame.along + (y + 0.5 * v * p.lampWidthM) * frame.across +
                   glm::dvec3(0, 0, p.lampHeightM);
        };
        auto lamp =
            QuadFacing(corner(-1, -1), corner(-1, 1), corner(1, 1), corner(1, -1), {0, 0, -1});
        scene.sources.emitters.push_back(
            {"lamp" + std::to_string(r), std::move(lamp), p.lampExitanceWm2, ""});
    }
}

void AddRandomCanopy(Scene& scene, const CanopyParameters& p) {
    if (p.leaves < 1 || !(p.leafAreaIndex > 0.0) || !(p.widthM > 0.0) || !(p.topM >= p.bottomM)) {
        throw InputError(ErrorCode::kInvalidArgument, "canopy",
                         "needs leaves >= 1, a positive leaf area index and width, top >= bottom");
    }
    Random random(StreamSeed(p.seed, 0xCA70));
    const double side = std::sqrt(p.leafAreaIndex * p.widthM * p.widthM / p.leaves);
    auto quad = std::make_shared<Mesh>();  // a unit square, shared, scaled by each frame
    quad->positions = {{-0.5, -0.5, 0}, {0.5, -0.5, 0}, {0.5, 0.5, 0}, {-0.5, 0.5, 0}};
    quad->triangles = {{0, 1, 2}, {0, 2, 3}};
    NodeId next = 1;
    for (const Node& node : scene.nodes) next = std::max(next, node.id + 1);
    for (int i = 0; i < p.leaves; ++i) {
        const glm::dvec3 centre((random.Uniform() - 0.5) * p.widthM,
                                (random.Uniform() - 0.5) * p.widthM,
                                p.bottomM + random.Uniform() * (p.topM - p.bottomM));
        const glm::dvec3 normal = UniformSphere(random.Uniform(), random.Uniform());
        const glm::dvec3 u =
            Rotate(AnyPerpendicular(normal), normal, 2.0 * glm::pi<double>() * random.Uniform());
        Node leaf;
        leaf.id = next++;
        leaf.Edit().type = NodeType::kLeaf;
        leaf.Edit().name = "leaf" + std::to_string(i + 1);
        leaf.Edit().organ = Organ{quad, p.leafOptics};
        leaf.Edit().parentFromLocal =
            FrameOf(centre, u * side, glm::cross(normal, u) * side, normal);
        scene.nodes.push_back(std::move(leaf));
    }
}

}  // namespace leaflux
