#include "growth_stub/model.h"

#include <google/protobuf/util/message_differencer.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <stdexcept>
#include <string>

namespace leaflux::grow {
namespace {

constexpr double kMinOrganSizeM = 1e-3;  // organs start at a millimetre, never at zero

void Require(bool ok, const std::string& field, const std::string& what) {
    if (!ok) throw std::invalid_argument("scenario." + field + ": " + what);
}

void CheckSpecies(const SpeciesTraits& s) {
    Require(s.rue_g_per_mj() >= 0.0, "species.rue_g_per_mj", "must be ≥ 0");
    Require(s.light_hours_per_cycle() > 0.0, "species.light_hours_per_cycle", "must be > 0");
    Require(s.seed_biomass_g() > 0.0, "species.seed_biomass_g", "must be > 0");
    Require(s.leaf_sink() >= 0.0 && s.internode_sink() >= 0.0, "species.leaf_sink",
            "sinks must be ≥ 0");
    Require(s.leaf_sink() + s.internode_sink() > 0.0, "species.leaf_sink",
            "leaf_sink + internode_sink must be > 0");
    Require(s.expansion_cycles() >= 1, "species.expansion_cycles", "must be ≥ 1");
    Require(s.specific_leaf_area_m2_per_g() > 0.0, "species.specific_leaf_area_m2_per_g",
            "must be > 0");
    Require(s.leaf_length_to_width() > 0.0, "species.leaf_length_to_width", "must be > 0");
    Require(s.internode_density_g_per_m3() > 0.0, "species.internode_density_g_per_m3",
            "must be > 0");
    Require(s.internode_length_to_radius() > 0.0, "species.internode_length_to_radius",
            "must be > 0");
    Require(s.max_phytomers_main() >= 1, "species.max_phytomers_main", "must be ≥ 1");
    Require(s.max_order() >= 0, "species.max_order", "must be ≥ 0");
    Require(s.stiffness() >= 0.0, "species.stiffness", "must be ≥ 0");
    Require(s.max_bend_deg() >= 0.0 && s.max_bend_deg() <= 90.0, "species.max_bend_deg",
            "must be in [0, 90]");
    Require(!s.shed_shaded_leaves() || s.shade_cycles() >= 1, "species.shade_cycles",
            "must be ≥ 1 when leaves are shed");
}

std::vector<Placement> Placements(const Scenario& scenario) {
    std::vector<Placement> out(scenario.plants().begin(), scenario.plants().end());
    const Stand& stand = scenario.stand();
    if (stand.rows() > 0 || stand.per_row() > 0) {
        Require(stand.rows() > 0 && stand.per_row() > 0, "stand", "needs rows and per_row ≥ 1");
        Require(stand.spacing() > 0.0 && (stand.rows() == 1 || stand.row_spacing() > 0.0),
                "stand.spacing", "must be > 0");
        const double a = glm::radians(stand.row_azimuth_deg());
        const glm::dvec2 along(std::sin(a), std::cos(a)), across(std::cos(a), -std::sin(a));
        for (int r = 0; r < stand.rows(); ++r) {
            for (int i = 0; i < stand.per_row(); ++i) {
                const glm::dvec2 p = (r - 0.5 * (stand.rows() - 1)) * stand.row_spacing() * across +
                                     (i - 0.5 * (stand.per_row() - 1)) * stand.spacing() * along;
                Placement placement;
                placement.set_x(p.x);
                placement.set_y(p.y);
                placement.set_azimuth_deg(37.0 * (r * stand.per_row() + i));  // not all alike
                out.push_back(placement);
            }
        }
    }
    Require(!out.empty(), "plants", "no plant: give plants or a stand");
    return out;
}

glm::dmat3 RotateZ(double deg) {
    return glm::dmat3(glm::rotate(glm::dmat4(1.0), glm::radians(deg), glm::dvec3(0, 0, 1)));
}
glm::dmat4 RotateY(double deg) {
    return glm::rotate(glm::dmat4(1.0), glm::radians(deg), glm::dvec3(0, 1, 0));
}
glm::dmat4 Translate(double x, double y, double z) {
    return glm::translate(glm::dmat4(1.0), glm::dvec3(x, y, z));
}
glm::dmat4 Scale(double x, double y, double z) {
    return glm::scale(glm::dmat4(1.0), glm::dvec3(x, y, z));
}

void SetFrame(const glm::dmat4& m, v1::Frame* frame) {
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) frame->add_m(m[c][r]);
    }
}

glm::dmat4 FrameOf(const v1::Node& node) {
    glm::dmat4 m(1.0);
    if (node.frame().m_size() != 12) return m;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) m[c][r] = node.frame().m(4 * r + c);
    }
    return m;
}

v1::Mesh MakeMesh(const std::vector<glm::dvec3>& positions,
                  const std::vector<glm::uvec3>& triangles) {
    v1::Mesh mesh;
    for (const glm::dvec3& p : positions) {
        mesh.add_positions(p.x);
        mesh.add_positions(p.y);
        mesh.add_positions(p.z);
    }
    for (const glm::uvec3& t : triangles) {
        mesh.add_triangles(t.x);
        mesh.add_triangles(t.y);
        mesh.add_triangles(t.z);
    }
    return mesh;
}

// The unit leaf: a blade from its petiole at the origin to its tip at x = 1, width 1,
// in the plane z = 0 with its upper side facing +z.
const std::vector<glm::dvec3> kLeafOutline = {{0, 0, 0}, {0.3, -0.5, 0}, {0.7, -0.4, 0},
                                              {1, 0, 0}, {0.7, 0.4, 0},  {0.3, 0.5, 0}};

// Area and centroid of the unit leaf (a fan of triangles from the petiole).
std::pair<double, glm::dvec3> UnitLeafAreaCentroid() {
    double area = 0.0;
    glm::dvec3 centroid(0.0);
    for (std::size_t i = 1; i + 1 < kLeafOutline.size(); ++i) {
        const glm::dvec3 &a = kLeafOutline[0], &b = kLeafOutline[i], &c = kLeafOutline[i + 1];
        const double t = 0.5 * glm::length(glm::cross(b - a, c - a));
        area += t;
        centroid += t * (a + b + c) / 3.0;
    }
    return {area, centroid / area};
}

// A rectangle o, o + u, o + u + v, o + v whose upper side faces u × v.
v1::Surface Rectangle(const std::string& name, glm::dvec3 o, glm::dvec3 u, glm::dvec3 v,
                      const std::string& optics) {
    v1::Surface surface;
    surface.set_name(name);
    surface.set_optics(optics);
    *surface.mutable_mesh() = MakeMesh({o, o + u, o + u + v, o + v}, {{0, 1, 2}, {0, 2, 3}});
    return surface;
}

}  // namespace

GrowthModel::GrowthModel(const Scenario& scenario) : scenario_(scenario) {
    CheckSpecies(Species());
    Require(!scenario_.par_band().empty(), "par_band", "is empty");
    Require(!scenario_.leaf_optics().empty(), "leaf_optics", "is empty");
    Require(!scenario_.stem_optics().empty(), "stem_optics", "is empty");
    if (scenario_.has_room()) {
        const Room& room = scenario_.room();
        Require(room.max().x() > room.min().x() && room.max().y() > room.min().y() &&
                    room.max().z() > room.min().z(),
                "room", "max must exceed min on every axis");
        Require(
            room.min().y() <= room.opening_y_min() && room.opening_y_min() < room.opening_y_max() &&
                room.opening_y_max() <= room.max().y() && room.min().z() <= room.opening_z_min() &&
                room.opening_z_min() < room.opening_z_max() &&
                room.opening_z_max() <= room.max().z(),
            "room.opening_y_min", "the opening must lie within the wall");
        Require(!room.optics().empty(), "room.optics", "is empty");
    }
    for (const Placement& placement : Placements(scenario_)) {
        Plant plant;
        plant.id = nextId_++;
        plant.placement = placement;
        plant.axes.push_back({nextId_++, 0, -1, {}, true});
        AddPhytomer(plant, 0, RotateZ(0.0));
        Allocate(plant, Species().seed_biomass_g());
        plants_.push_back(std::move(plant));
    }
}

void GrowthModel::AddPhytomer(Plant& plant, int axis, const glm::dmat3& turn) {
    Phytomer p;
    p.id = nextId_++;
    p.internode = nextId_++;
    p.leaf = nextId_++;
    p.axis = axis;
    p.turn = turn;
    plant.axes[axis].phytomers.push_back(static_cast<int>(plant.phytomers.size()));
    plant.phytomers.push_back(p);
}

void GrowthModel::Allocate(Plant& plant, double supplyG) {
    const SpeciesTraits& s = Species();
    const double available = plant.poolG + supplyG;
    double demand = 0.0;
    for (const Phytomer& p : plant.phytomers) {
        if (p.age < s.expansion_cycles()) {
            demand += s.internode_sink() + (p.leaf != 0 ? s.leaf_sink() : 0.0);
        }
    }
    plant.builtG += supplyG;
    if (demand <= 0.0) {  // nothing grows: keep the pool for later
        plant.poolG = available;
        plant.supplyDemand = std::numeric_limits<double>::infinity();
        return;
    }
    plant.supplyDemand = available / demand;
    for (Phytomer& p : plant.phytomers) {
        if (p.age >= s.expansion_cycles()) continue;
        p.internodeG += plant.supplyDemand * s.internode_sink();
        if (p.leaf != 0) p.leafG += plant.supplyDemand * s.leaf_sink();
    }
    plant.poolG = 0.0;
}

double GrowthModel::InternodeLength(const Phytomer& p) const {
    // A cylinder of length L and radius L / λ: volume π L³ / λ², so L = (λ² V / π)^⅓.
    const double lambda = Species().internode_length_to_radius();
    const double volume = p.internodeG / Species().internode_density_g_per_m3();
    return std::max(kMinOrganSizeM, std::cbrt(lambda * lambda * volume / glm::pi<double>()));
}

glm::dmat4 GrowthModel::LeafFrame(const Phytomer& p) const {
    static const double unitArea = UnitLeafAreaCentroid().first;
    const double area = Species().specific_leaf_area_m2_per_g() * p.leafG;
    const double ratio = Species().leaf_length_to_width();
    const double length = std::max(kMinOrganSizeM, std::sqrt(area * ratio / unitArea));
    // The blade leaves the axis at leaf_insertion_deg, pointing along the phytomer's +x.
    return Translate(0, 0, InternodeLength(p)) * RotateY(Species().leaf_insertion_deg() - 90.0) *
           Scale(length, length / ratio, 1.0);
}

std::map<NodeId, leaflux::v1::Node> GrowthModel::Nodes() const {
    std::map<NodeId, v1::Node> nodes;
    const auto add = [&](NodeId id, NodeId parent, v1::NodeType type, const std::string& name,
                         const glm::dmat4& frame) -> v1::Node& {
        v1::Node& node = nodes[id];
        node.set_id(id);
        node.set_parent(parent);
        node.set_type(type);
        node.set_name(name);
        SetFrame(frame, node.mutable_frame());
        return node;
    };
    const auto organ = [&](v1::Node& node, const char* mesh, const std::string& optics) {
        node.mutable_organ()->set_mesh_ref(mesh);
        node.mutable_organ()->set_optics(optics);
    };
    for (std::size_t k = 0; k < plants_.size(); ++k) {
        const Plant& plant = plants_[k];
        const Placement& at = plant.placement;
        add(plant.id, 0, v1::NODE_TYPE_PLANT, "plant" + std::to_string(k + 1),
            Translate(at.x(), at.y(), 0.0) *
                glm::dmat4(RotateZ(at.azimuth_deg() + plant.turnedDeg)));
        for (const Axis& axis : plant.axes) {
            if (axis.bearer < 0) {
                add(axis.id, plant.id, v1::NODE_TYPE_AXIS, "axis" + std::to_string(axis.id),
                    glm::dmat4(1.0));
            } else {
                // A branch leaves from the top of its bearer's internode, on the leaf's side.
                const Phytomer& bearer = plant.phytomers[axis.bearer];
                add(axis.id, bearer.id, v1::NODE_TYPE_AXIS, "axis" + std::to_string(axis.id),
                    Translate(0, 0, InternodeLength(bearer)) *
                        RotateY(Species().branch_insertion_deg()));
            }
            NodeId below = axis.id;
            double lengthBelow = 0.0;
            for (int index : axis.phytomers) {
                const Phytomer& p = plant.phytomers[index];
                add(p.id, below, v1::NODE_TYPE_PHYTOMER, "phytomer" + std::to_string(p.id),
                    Translate(0, 0, lengthBelow) * glm::dmat4(p.turn));
                const double length = InternodeLength(p);
                const double radius = length / Species().internode_length_to_radius();
                organ(add(p.internode, p.id, v1::NODE_TYPE_INTERNODE,
                          "internode" + std::to_string(p.internode), Scale(radius, radius, length)),
                      "internode", scenario_.stem_optics());
                if (p.leaf != 0) {
                    organ(add(p.leaf, p.id, v1::NODE_TYPE_LEAF, "leaf" + std::to_string(p.leaf),
                              LeafFrame(p)),
                          "leaf", scenario_.leaf_optics());
                }
                below = p.id;
                lengthBelow = length;
            }
        }
    }
    return nodes;
}

std::map<std::string, leaflux::v1::Mesh> GrowthModel::Meshes() {
    // The unit internode: a square tube of half-width 1 from z = 0 to 1, upper sides out.
    std::vector<glm::dvec3> tube;
    const glm::dvec2 corners[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (double z : {0.0, 1.0}) {
        for (const glm::dvec2& c : corners) tube.emplace_back(c.x, c.y, z);
    }
    std::vector<glm::uvec3> sides;
    for (unsigned i = 0; i < 4; ++i) {
        const unsigned j = (i + 1) % 4;
        sides.emplace_back(i, j, 4 + j);
        sides.emplace_back(i, 4 + j, 4 + i);
    }
    std::vector<glm::uvec3> fan;
    for (unsigned i = 1; i + 1 < kLeafOutline.size(); ++i) fan.emplace_back(0, i, i + 1);
    return {{"leaf", MakeMesh(kLeafOutline, fan)}, {"internode", MakeMesh(tube, sides)}};
}

std::vector<leaflux::v1::Surface> GrowthModel::Environment() const {
    std::vector<v1::Surface> out;
    if (!scenario_.has_room()) return out;
    const Room& room = scenario_.room();
    const glm::dvec3 lo(room.min().x(), room.min().y(), room.min().z());
    const glm::dvec3 hi(room.max().x(), room.max().y(), room.max().z());
    const glm::dvec3 d = hi - lo;
    const std::string& optics = room.optics();
    // Upper sides face into the room.
    out.push_back(Rectangle("room.floor", lo, {d.x, 0, 0}, {0, d.y, 0}, optics));
    out.push_back(Rectangle("room.ceiling", {lo.x, lo.y, hi.z}, {0, d.y, 0}, {d.x, 0, 0}, optics));
    out.push_back(Rectangle("room.wall_x_min", lo, {0, d.y, 0}, {0, 0, d.z}, optics));
    out.push_back(Rectangle("room.wall_y_min", lo, {0, 0, d.z}, {d.x, 0, 0}, optics));
    out.push_back(
        Rectangle("room.wall_y_max", {lo.x, hi.y, lo.z}, {d.x, 0, 0}, {0, 0, d.z}, optics));
    // The wall at x = max, in four pieces around its opening.
    const auto piece = [&](const char* name, double y0, double y1, double z0, double z1) {
        if (y1 - y0 <= 0.0 || z1 - z0 <= 0.0) return;
        out.push_back(Rectangle(name, {hi.x, y0, z0}, {0, 0, z1 - z0}, {0, y1 - y0, 0}, optics));
    };
    const double oy0 = room.opening_y_min(), oy1 = room.opening_y_max();
    const double oz0 = room.opening_z_min(), oz1 = room.opening_z_max();
    piece("room.wall_x_max.below", lo.y, hi.y, lo.z, oz0);
    piece("room.wall_x_max.above", lo.y, hi.y, oz1, hi.z);
    piece("room.wall_x_max.left", lo.y, oy0, oz0, oz1);
    piece("room.wall_x_max.right", oy1, hi.y, oz0, oz1);
    return out;
}

std::map<NodeId, glm::dmat4> GrowthModel::WorldFrames() const {
    std::map<NodeId, glm::dmat4> world;
    // Ids grow with age, so a parent comes before its children.
    for (const auto& [id, node] : Nodes()) {
        const auto parent = world.find(node.parent());
        world[id] = (parent == world.end() ? glm::dmat4(1.0) : parent->second) * FrameOf(node);
    }
    return world;
}

glm::dmat3 GrowthModel::TurnTowardsLight(const Plant& plant, const Axis& axis,
                                         const std::map<NodeId, glm::dmat4>& world) const {
    const SpeciesTraits& s = Species();
    const glm::dmat3 phyllotaxy = RotateZ(s.phyllotaxy_deg());
    // The light of the axis's youngest leaves (three at most, weighted by their mass, so by
    // their area), or of its bearer's leaf.
    glm::dvec3 light(0.0);
    double mass = 0.0;
    int counted = 0;
    for (auto it = axis.phytomers.rbegin(); it != axis.phytomers.rend() && counted < 3; ++it) {
        const Phytomer& p = plant.phytomers[*it];
        if (p.leaf == 0) continue;
        light += p.leafG * p.light.vector;
        mass += p.leafG;
        ++counted;
    }
    if (mass > 0.0) light /= mass;
    if (counted == 0 && axis.bearer >= 0) light = plant.phytomers[axis.bearer].light.vector;
    const double strength = glm::length(light);
    if (strength < 1e-9) return phyllotaxy;
    light /= strength;
    // Where the apex points now: the z axis of the last phytomer (or of the axis).
    const NodeId apex =
        axis.phytomers.empty() ? axis.id : plant.phytomers[axis.phytomers.back()].id;
    const glm::dmat3 r(world.at(apex));
    const glm::dvec3 direction = glm::normalize(r[2]);
    const glm::dvec3 across = glm::cross(direction, light);
    if (glm::length(across) < 1e-9) return phyllotaxy;
    const double angle = std::acos(std::clamp(glm::dot(direction, light), -1.0, 1.0));
    const double bend = std::min(glm::radians(s.max_bend_deg()),
                                 angle * std::min(1.0, strength) / (1.0 + s.stiffness()));
    const glm::dmat3 turnWorld(glm::rotate(glm::dmat4(1.0), bend, glm::normalize(across)));
    return glm::transpose(r) * turnWorld * r * phyllotaxy;
}

void GrowthModel::Grow(const std::map<NodeId, LeafLight>& light) {
    const SpeciesTraits& s = Species();
    const std::map<NodeId, glm::dmat4> world = WorldFrames();
    ++cycle_;
    for (Plant& plant : plants_) {
        double absorbedW = 0.0;
        for (Phytomer& p : plant.phytomers) {
            if (p.leaf == 0) continue;
            const auto it = light.find(p.leaf);
            p.light = it == light.end() ? LeafLight{} : it->second;
            absorbedW += p.light.absorbedW;
        }
        const double productionG =
            s.rue_g_per_mj() * absorbedW * s.light_hours_per_cycle() * 3600.0 * 1e-6;

        if (s.shed_shaded_leaves()) {
            for (Phytomer& p : plant.phytomers) {
                if (p.leaf == 0) continue;
                p.shadedCycles = p.light.irradianceWm2 < s.shade_par_wm2() ? p.shadedCycles + 1 : 0;
                if (p.shadedCycles >= s.shade_cycles() && p.age >= s.expansion_cycles()) {
                    p.leaf = 0;
                    if (p.bud == Bud::kDormant) p.bud = Bud::kDead;
                }
            }
        }

        if (plant.supplyDemand >= s.min_supply_demand()) {
            const std::size_t axes = plant.axes.size(), phytomers = plant.phytomers.size();
            for (std::size_t a = 0; a < axes; ++a) {
                Axis& axis = plant.axes[a];
                const int most =
                    axis.order == 0 ? s.max_phytomers_main() : s.max_phytomers_branch();
                if (axis.growing && static_cast<int>(axis.phytomers.size()) >= most) {
                    axis.growing = false;
                }
                if (axis.growing) {
                    AddPhytomer(plant, static_cast<int>(a), TurnTowardsLight(plant, axis, world));
                }
            }
            for (std::size_t i = 0; i < phytomers; ++i) {
                Phytomer& p = plant.phytomers[i];
                const int order = plant.axes[p.axis].order;
                if (p.bud != Bud::kDormant || p.leaf == 0 || p.age < s.bud_delay_cycles() ||
                    order >= s.max_order() || p.light.irradianceWm2 < s.bud_break_par_wm2()) {
                    continue;
                }
                p.bud = Bud::kBroken;
                plant.axes.push_back({nextId_++, order + 1, static_cast<int>(i), {}, true});
                AddPhytomer(plant, static_cast<int>(plant.axes.size()) - 1,
                            RotateZ(s.phyllotaxy_deg()));
            }
        }
        Allocate(plant, productionG);
        for (Phytomer& p : plant.phytomers) ++p.age;
    }
    const Turning& turning = scenario_.turning();
    if (turning.every_cycles() > 0 && cycle_ % turning.every_cycles() == 0) {
        for (Plant& plant : plants_) plant.turnedDeg += turning.degrees();
    }
}

std::vector<PlantSummary> GrowthModel::Summaries() const {
    static const glm::dvec3 unitCentroid = UnitLeafAreaCentroid().second;
    const std::map<NodeId, glm::dmat4> world = WorldFrames();
    std::vector<PlantSummary> out;
    for (const Plant& plant : plants_) {
        PlantSummary summary;
        summary.id = plant.id;
        summary.biomassG = plant.builtG;
        for (const Phytomer& p : plant.phytomers) {
            if (p.leaf == 0) continue;
            const double area = Species().specific_leaf_area_m2_per_g() * p.leafG;
            ++summary.leaves;
            summary.leafAreaM2 += area;
            summary.leafCentroid +=
                area * glm::dvec3(world.at(p.leaf) * glm::dvec4(unitCentroid, 1.0));
        }
        if (summary.leafAreaM2 > 0.0) summary.leafCentroid /= summary.leafAreaM2;
        out.push_back(summary);
    }
    return out;
}

std::vector<GrowthModel::PhytomerSize> GrowthModel::Phytomers() const {
    std::vector<PhytomerSize> out;
    for (const Plant& plant : plants_) {
        // Axes are made after their bearer's, so a bearer's address is known first.
        std::vector<std::string> axisAddress(plant.axes.size());
        std::vector<int> rank(plant.phytomers.size());
        for (std::size_t a = 0; a < plant.axes.size(); ++a) {
            const Axis& axis = plant.axes[a];
            axisAddress[a] = axis.bearer < 0 ? "0"
                                             : axisAddress[plant.phytomers[axis.bearer].axis] +
                                                   "." + std::to_string(rank[axis.bearer]);
            for (std::size_t r = 0; r < axis.phytomers.size(); ++r) {
                rank[axis.phytomers[r]] = static_cast<int>(r);
            }
        }
        for (std::size_t i = 0; i < plant.phytomers.size(); ++i) {
            const Phytomer& p = plant.phytomers[i];
            out.push_back({std::to_string(plant.id) + ":" + axisAddress[p.axis] + "/" +
                               std::to_string(rank[i]),
                           p.internodeG, p.leaf != 0 ? p.leafG : 0.0});
        }
    }
    return out;
}

std::vector<GrowthModel::LeafInfo> GrowthModel::Leaves() const {
    std::vector<LeafInfo> out;
    for (const Plant& plant : plants_) {
        for (const Phytomer& p : plant.phytomers) {
            if (p.leaf == 0) continue;
            std::vector<NodeId> axes;
            for (int a = p.axis; a >= 0;) {
                axes.push_back(plant.axes[a].id);
                const int bearer = plant.axes[a].bearer;
                a = bearer < 0 ? -1 : plant.phytomers[bearer].axis;
            }
            out.push_back({p.leaf, plant.axes[p.axis].id, plant.id,
                           Species().specific_leaf_area_m2_per_g() * p.leafG, std::move(axes)});
        }
    }
    return out;
}

std::vector<WorldTriangle> GrowthModel::Triangles() const {
    const std::map<std::string, v1::Mesh> meshes = Meshes();
    const std::map<NodeId, glm::dmat4> world = WorldFrames();
    std::vector<WorldTriangle> out;
    for (const auto& [id, node] : Nodes()) {
        if (!node.has_organ()) continue;
        const v1::Mesh& mesh = meshes.at(node.organ().mesh_ref());
        const glm::dmat4& m = world.at(id);
        const auto vertex = [&](std::uint32_t i) {
            return glm::dvec3(m * glm::dvec4(mesh.positions(3 * i), mesh.positions(3 * i + 1),
                                             mesh.positions(3 * i + 2), 1.0));
        };
        for (int t = 0; t + 2 < mesh.triangles_size(); t += 3) {
            out.push_back({vertex(mesh.triangles(t)), vertex(mesh.triangles(t + 1)),
                           vertex(mesh.triangles(t + 2)), id});
        }
    }
    return out;
}

leaflux::v1::TopologyDelta Diff(const std::map<NodeId, leaflux::v1::Node>& before,
                                const std::map<NodeId, leaflux::v1::Node>& after) {
    using google::protobuf::util::MessageDifferencer;
    v1::TopologyDelta delta;
    for (const auto& [id, node] : after) {
        const auto old = before.find(id);
        if (old == before.end()) {
            *delta.add_added() = node;
        } else if (!MessageDifferencer::Equals(old->second, node)) {
            *delta.add_updated() = node;
        }
    }
    for (const auto& [id, node] : before) {
        // Removing a node removes what is below it: name only the topmost.
        if (!after.count(id) && (node.parent() == 0 || after.count(node.parent()))) {
            delta.add_removed(id);
        }
    }
    return delta;
}

}  // namespace leaflux::grow
