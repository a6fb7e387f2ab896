#include "server/scene_proto.h"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/text_format.h>
#include <google/protobuf/wire_format_lite.h>
#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <unordered_set>

#include "server/scene_structures.h"
#include "server/text_format.h"
#include "solver/io/importers.h"
#include "solver/scene/light_units.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

[[noreturn]] void Fail(ErrorCode code, const std::string& field, const std::string& message,
                       std::optional<NodeId> node = std::nullopt) {
    throw InputError(code, field, message, node);
}

// A band → value map as a vector in scene band order; every band must be present.
std::vector<double> PerBand(const Scene& scene,
                            const google::protobuf::Map<std::string, double>& values,
                            const std::string& field) {
    std::vector<double> result(scene.bands.size(), 0.0);
    std::vector<bool> seen(scene.bands.size(), false);
    for (const auto& [band, value] : values) {
        const int b = scene.BandIndex(band);
        if (b < 0) Fail(ErrorCode::kNotFound, field + "[" + band + "]", "names no declared band");
        result[b] = value;
        seen[b] = true;
    }
    for (std::size_t b = 0; b < seen.size(); ++b) {
        if (!seen[b])
            Fail(ErrorCode::kNotFound, field, "has no value for band " + scene.bands[b].name);
    }
    return result;
}

std::shared_ptr<Mesh> MeshFromProto(const v1::Mesh& message, const std::string& field,
                                    std::optional<NodeId> node = std::nullopt) {
    if (message.positions_size() % 3 != 0) {
        Fail(ErrorCode::kInvalidArgument, field + ".positions",
             "holds " + std::to_string(message.positions_size()) + " numbers, not x, y, z triples",
             node);
    }
    if (message.triangles_size() % 3 != 0) {
        Fail(ErrorCode::kInvalidArgument, field + ".triangles",
             "holds " + std::to_string(message.triangles_size()) + " indices, not triples", node);
    }
    auto mesh = std::make_shared<Mesh>();
    for (int i = 0; i < message.positions_size(); i += 3) {
        mesh->positions.push_back(
            {message.positions(i), message.positions(i + 1), message.positions(i + 2)});
    }
    for (int i = 0; i < message.triangles_size(); i += 3) {
        mesh->triangles.push_back(
            {message.triangles(i), message.triangles(i + 1), message.triangles(i + 2)});
    }
    return mesh;
}

NodeType TypeFromProto(v1::NodeType type) {
    switch (type) {
        case v1::NODE_TYPE_PLANT:
            return NodeType::kPlant;
        case v1::NODE_TYPE_AXIS:
            return NodeType::kAxis;
        case v1::NODE_TYPE_PHYTOMER:
            return NodeType::kPhytomer;
        case v1::NODE_TYPE_LEAF:
            return NodeType::kLeaf;
        case v1::NODE_TYPE_INTERNODE:
            return NodeType::kInternode;
        case v1::NODE_TYPE_FRUIT:
            return NodeType::kFruit;
        default:
            return NodeType::kOther;
    }
}

SkyDiscretization DiscretizationFromProto(v1::SkyDiscretization d) {
    switch (d) {
        case v1::SKY_DISCRETIZATION_TURTLE_46:
            return SkyDiscretization::kTurtle46;
        case v1::SKY_DISCRETIZATION_TETRA_34:
            return SkyDiscretization::kTetra34;
        case v1::SKY_DISCRETIZATION_TETRA_130:
            return SkyDiscretization::kTetra130;
        case v1::SKY_DISCRETIZATION_TETRA_514:
            return SkyDiscretization::kTetra514;
        default:
            return SkyDiscretization::kContinuous;
    }
}

v1::SkyDiscretization DiscretizationToProto(SkyDiscretization d) {
    switch (d) {
        case SkyDiscretization::kTurtle46:
            return v1::SKY_DISCRETIZATION_TURTLE_46;
        case SkyDiscretization::kTetra34:
            return v1::SKY_DISCRETIZATION_TETRA_34;
        case SkyDiscretization::kTetra130:
            return v1::SKY_DISCRETIZATION_TETRA_130;
        case SkyDiscretization::kTetra514:
            return v1::SKY_DISCRETIZATION_TETRA_514;
        case SkyDiscretization::kContinuous:
            return v1::SKY_DISCRETIZATION_CONTINUOUS;
    }
    return v1::SKY_DISCRETIZATION_CONTINUOUS;
}

}  // namespace

glm::dmat4 FrameFromProto(const v1::Frame& frame, const std::string& field,
                          std::optional<NodeId> node) {
    if (frame.m_size() == 0) return glm::dmat4(1.0);
    if (frame.m_size() != 12) {
        Fail(ErrorCode::kInvalidArgument, field,
             "needs 12 numbers (3×4 row-major), got " + std::to_string(frame.m_size()), node);
    }
    glm::dmat4 m(1.0);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) m[c][r] = frame.m(4 * r + c);
    }
    return m;
}

void FrameToProto(const glm::dmat4& m, v1::Frame* frame) {
    if (m == glm::dmat4(1.0)) return;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) frame->add_m(m[c][r]);
    }
}

void MeshToProto(const Mesh& mesh, v1::Mesh* message) {
    for (const glm::dvec3& p : mesh.positions) {
        message->add_positions(p.x);
        message->add_positions(p.y);
        message->add_positions(p.z);
    }
    for (const glm::uvec3& t : mesh.triangles) {
        message->add_triangles(t.x);
        message->add_triangles(t.y);
        message->add_triangles(t.z);
    }
}

v1::NodeType TypeToProto(NodeType type) {
    switch (type) {
        case NodeType::kPlant:
            return v1::NODE_TYPE_PLANT;
        case NodeType::kAxis:
            return v1::NODE_TYPE_AXIS;
        case NodeType::kPhytomer:
            return v1::NODE_TYPE_PHYTOMER;
        case NodeType::kLeaf:
            return v1::NODE_TYPE_LEAF;
        case NodeType::kInternode:
            return v1::NODE_TYPE_INTERNODE;
        case NodeType::kFruit:
            return v1::NODE_TYPE_FRUIT;
        case NodeType::kOther:
            return v1::NODE_TYPE_OTHER;
    }
    return v1::NODE_TYPE_OTHER;
}

namespace {

// Source values that are valid but look mistaken (solver/scene/light_units.h): the log's.
void LogWarnings(const std::vector<std::string>& warnings) {
    for (const std::string& warning : warnings) spdlog::warn("{}", warning);
}

}  // namespace

Sun SunFromProto(const Scene& scene, const v1::Sun& in, const std::string& field) {
    Sun sun;
    if (in.has_solar()) {
        const v1::SolarPosition& p = in.solar();
        if (!std::isfinite(p.latitude_deg()) || std::abs(p.latitude_deg()) > 90.0) {
            Fail(ErrorCode::kInvalidArgument, field + ".solar.latitude_deg",
                 "must be in [-90, 90]");
        }
        if (p.day_of_year() < 1 || p.day_of_year() > 366) {
            Fail(ErrorCode::kInvalidArgument, field + ".solar.day_of_year", "must be in [1, 366]");
        }
        if (!std::isfinite(p.solar_time_h()) || p.solar_time_h() < 0.0 || p.solar_time_h() > 24.0) {
            Fail(ErrorCode::kInvalidArgument, field + ".solar.solar_time_h", "must be in [0, 24]");
        }
        sun.towardSun =
            DirectionFromAngles(SolarPosition(p.latitude_deg(), p.day_of_year(), p.solar_time_h()));
    } else {
        const glm::dvec3 d(in.direction().x(), in.direction().y(), in.direction().z());
        const double length = glm::length(d);
        if (!std::isfinite(length) || length == 0.0) {
            Fail(ErrorCode::kInvalidArgument, field + ".direction",
                 "must be a finite non-zero vector");
        }
        sun.towardSun = d / length;
    }
    sun.normalIrradianceWm2 = PerBand(scene, in.normal_irradiance(), field + ".normal_irradiance");
    sun.angularRadiusRad = glm::radians(in.angular_radius_deg());
    LogWarnings(SunWarnings(scene, sun, field));
    return sun;
}

namespace {

void ReadSources(const v1::Scene& message, Scene& scene, const std::filesystem::path& base,
                 const SceneLimits& limits) {
    if (static_cast<std::size_t>(message.suns_size()) > limits.maxSuns) {
        throw TooLarge("suns", "at most " + std::to_string(limits.maxSuns) + " suns, got " +
                                   std::to_string(message.suns_size()));
    }
    // Sun periods' steps, counted before any is expanded; suns given one by one count too.
    double sunCount = message.suns_size();
    for (int i = 0; i < message.sun_periods_size(); ++i) {
        const v1::SunPeriod& p = message.sun_periods(i);
        const std::string field = "sun_periods[" + std::to_string(i) + "]";
        if (!(p.step_h() > 0.0) || !(p.end_h() > p.start_h()) || !(p.start_h() >= 0.0) ||
            !(p.end_h() <= 24.0)) {
            Fail(ErrorCode::kInvalidArgument, field,
                 "needs 0 <= start_h < end_h <= 24 and step_h > 0");
        }
        if (p.day_of_year() < 1 || p.day_of_year() > 366 || !(std::abs(p.latitude_deg()) <= 90.0)) {
            Fail(ErrorCode::kInvalidArgument, field,
                 "needs a day of year in [1, 366] and a latitude in [-90, 90]");
        }
        const double steps = std::ceil((p.end_h() - p.start_h()) / p.step_h());
        if (!(steps <= static_cast<double>(limits.maxSuns))) {
            throw TooLarge(field + ".step_h", "makes " + fmt::format("{:g}", steps) +
                                                  " sun positions; at most " +
                                                  std::to_string(limits.maxSuns) + " suns");
        }
        sunCount += steps;
        if (sunCount > static_cast<double>(limits.maxSuns)) {
            throw TooLarge("sun_periods", "the suns and sun period steps make more than " +
                                              std::to_string(limits.maxSuns) + " suns");
        }
    }
    for (int i = 0; i < message.suns_size(); ++i) {
        scene.sources.suns.push_back(
            SunFromProto(scene, message.suns(i), "suns[" + std::to_string(i) + "]"));
    }
    for (int i = 0; i < message.sun_periods_size(); ++i) {
        const v1::SunPeriod& p = message.sun_periods(i);
        const std::string field = "sun_periods[" + std::to_string(i) + "]";
        const std::vector<double> normalIrradianceWm2 =
            PerBand(scene, p.normal_irradiance(), field + ".normal_irradiance");
        LogWarnings(IrradianceWarnings(scene, normalIrradianceWm2, field + ".normal_irradiance"));
        const auto suns = SunPositionsOverPeriod(p.latitude_deg(), p.day_of_year(), p.start_h(),
                                                 p.end_h(), p.step_h(), normalIrradianceWm2);
        scene.sources.suns.insert(scene.sources.suns.end(), suns.begin(), suns.end());
    }
    if (message.has_sky()) {
        Sky sky;
        sky.model = message.sky().model() == v1::SKY_MODEL_CIE_OVERCAST ? SkyModel::kCieOvercast
                                                                        : SkyModel::kUniform;
        sky.horizontalIrradianceWm2 =
            PerBand(scene, message.sky().horizontal_irradiance(), "sky.horizontal_irradiance");
        sky.discretization = DiscretizationFromProto(message.sky().discretization());
        LogWarnings(
            IrradianceWarnings(scene, sky.horizontalIrradianceWm2, "sky.horizontal_irradiance"));
        scene.sources.skies.push_back(std::move(sky));
    }
    for (int i = 0; i < message.emitters_size(); ++i) {
        const v1::Emitter& in = message.emitters(i);
        const std::string field =
            "emitters[" + (in.name().empty() ? std::to_string(i) : in.name()) + "]";
        scene.sources.emitters.push_back({in.name(), MeshFromProto(in.mesh(), field + ".mesh"),
                                          PerBand(scene, in.exitance(), field + ".exitance"),
                                          in.optics()});
    }
    for (int i = 0; i < message.can_lights_size(); ++i) {
        const v1::CanLights& in = message.can_lights(i);
        const std::string field = "can_lights[" + std::to_string(i) + "]";
        const std::vector<double> scale = PerBand(scene, in.scale(), field + ".scale");
        for (const CanLight& light : ReadCanLights((base / in.path()).string())) {
            if (light.towardSource.z <= 0.0)
                continue;  // below the horizon: lights nothing from the sky
            Sun sun;
            sun.towardSun = light.towardSource;
            for (double s : scale)
                sun.normalIrradianceWm2.push_back(s * light.horizontalIrradiance /
                                                  light.towardSource.z);
            scene.sources.suns.push_back(std::move(sun));
        }
    }
}

}  // namespace

Node NodeFromProto(const v1::Node& in, const MeshLibrary& meshes) {
    Node node;
    node.id = in.id();
    node.parent = in.parent();
    node.Edit().type = TypeFromProto(in.type());
    node.Edit().name = in.name();
    node.Edit().parentFromLocal = FrameFromProto(in.frame(), "frame", in.id());
    node.Edit().age = in.age();
    node.Edit().attributes.insert(in.attributes().begin(), in.attributes().end());
    if (in.has_organ()) {
        const v1::Organ& organ = in.organ();
        std::shared_ptr<const Mesh> mesh;
        if (organ.has_mesh_ref()) {
            const auto it = meshes.find(organ.mesh_ref());
            if (it == meshes.end()) {
                Fail(ErrorCode::kNotFound, "organ.mesh_ref",
                     "names no mesh '" + organ.mesh_ref() + "'", in.id());
            }
            mesh = it->second;
        } else {
            mesh = MeshFromProto(organ.mesh(), "organ.mesh", in.id());
        }
        node.Edit().organ = Organ{mesh, organ.optics()};
    }
    return node;
}

MeshLibrary MeshesFromProto(const v1::Scene& message) {
    MeshLibrary meshes;
    for (const auto& [name, mesh] : message.meshes()) {
        auto shared = MeshFromProto(mesh, "meshes[" + name + "]");
        shared->name = "meshes[" + name + "]";  // its errors name it, not the organ using it
        meshes[name] = std::move(shared);
    }
    return meshes;
}

// Imports are in scene_import.cpp.
void ReadImports(const v1::Scene& message, Scene& scene, const std::filesystem::path& base,
                 const ImportOptions& options);

void CheckPeriodicTile(const Scene& scene, const FlatScene& flat, const SceneLimits& limits) {
    if (!scene.periodic || flat.triangles.empty()) return;
    const glm::dvec3 extent = flat.boundsMax - flat.boundsMin;
    const double width = scene.periodic->xMax - scene.periodic->xMin;
    const double depth = scene.periodic->yMax - scene.periodic->yMin;
    if (extent.x > limits.maxTilesSpanned * width || extent.y > limits.maxTilesSpanned * depth) {
        throw TooLarge("periodic",
                       fmt::format("a tile of {:g} m × {:g} m under geometry {:g} m × {:g} m "
                                   "wide: the geometry may span at most {:g} tiles each way",
                                   width, depth, extent.x, extent.y, limits.maxTilesSpanned));
    }
}

namespace {

// A scene's nodes as its reader has them: how many, and each in order (visit(node)).
struct NodeSource {
    std::size_t count = 0;
    std::function<void(const std::function<void(const v1::Node&)>& visit)> forEach;
};

NodeSource NodesOf(const v1::Scene& message) {
    return {static_cast<std::size_t>(message.nodes_size()), [&message](const auto& visit) {
                for (const v1::Node& node : message.nodes()) visit(node);
            }};
}

// FromProto but for the check of the whole (Scene::Validate), which a caller that owns the
// message does once the message is gone; the nodes from `nodes`, not the message's.
Scene UncheckedFromProto(const v1::Scene& message, const NodeSource& nodes,
                         const std::string& baseDirectory, const SceneLimits& limits,
                         const ImportOptions& options) {
    if (message.version() > v1::PROTOCOL_VERSION_CURRENT) {
        Fail(ErrorCode::kUnsupported, "version", "is newer than this leaflux understands");
    }
    if (message.version() < 0) {
        Fail(ErrorCode::kInvalidArgument, "version",
             "must be PROTOCOL_VERSION_CURRENT (1) or unset, got " +
                 std::to_string(message.version()));
    }
    // Counts first, before any work they would multiply.
    if (message.bands_size() > kMaxBands) {
        throw TooLarge("bands", "at most " + std::to_string(kMaxBands) + " bands, got " +
                                    std::to_string(message.bands_size()));
    }
    if (nodes.count > limits.maxNodes) {
        throw TooLarge("nodes", "at most " + std::to_string(limits.maxNodes) +
                                    " nodes a scene (--max-nodes), got " +
                                    std::to_string(nodes.count));
    }
    const std::size_t placedNodes = CountPlacedNodes(message, nodes.count, limits);
    const std::filesystem::path base(baseDirectory);
    Scene scene;
    std::unordered_set<std::string> bandNames;
    for (const v1::Band& band : message.bands()) {
        // Bands first: every per-band map below is read against them.
        if (!bandNames.insert(band.name()).second) {
            Fail(ErrorCode::kAlreadyExists, "bands[" + band.name() + "]", "is declared twice");
        }
        scene.bands.push_back({band.name(), band.wavelength_min_nm(), band.wavelength_max_nm(),
                               band.photon_umol_per_j()});
    }
    for (const v1::Optics& optics : message.optics()) {
        Optics o;
        o.id = optics.id();
        o.bands.resize(scene.bands.size());
        const std::string field = "optics[" + optics.id() + "]";
        std::vector<bool> seen(scene.bands.size(), false);
        for (const auto& [band, values] : optics.bands()) {
            const int b = scene.BandIndex(band);
            if (b < 0)
                Fail(ErrorCode::kNotFound, field + ".bands[" + band + "]",
                     "names no declared band");
            o.bands[b] = {values.rho_upper(), values.rho_lower(), values.tau_upper(),
                          values.tau_lower()};
            seen[b] = true;
        }
        for (std::size_t b = 0; b < seen.size(); ++b) {
            if (!seen[b])
                Fail(ErrorCode::kNotFound, field + ".bands",
                     "has no properties for band " + scene.bands[b].name);
        }
        scene.optics.push_back(std::move(o));
    }
    const MeshLibrary meshes = MeshesFromProto(message);
    // Exactly as many as there will be: grown by doubling, the nodes of a plantation of 233
    // trees took 310 MB for 160.
    scene.nodes.reserve(nodes.count + placedNodes);
    nodes.forEach([&](const v1::Node& in) { scene.nodes.push_back(NodeFromProto(in, meshes)); });
    ExpandPlacements(message, meshes, scene.nodes);
    for (const v1::Surface& surface : message.environment()) {
        scene.environment.push_back(
            {surface.name(),
             MeshFromProto(surface.mesh(), "environment[" + surface.name() + "].mesh"),
             surface.optics()});
    }
    ReadSources(message, scene, base, limits);
    if (message.has_periodic()) {
        const v1::PeriodicDomain& p = message.periodic();
        scene.periodic = PeriodicDomain{p.x_min(), p.y_min(), p.x_max(), p.y_max()};
    }
    ReadImports(message, scene, base, options);
    return scene;
}

}  // namespace

Scene FromProto(const v1::Scene& message, const std::string& baseDirectory,
                const SceneLimits& limits, const ImportOptions& options) {
    Scene scene = UncheckedFromProto(message, NodesOf(message), baseDirectory, limits, options);
    scene.Validate();
    return scene;
}

v1::Scene ToProto(const Scene& scene, SceneWriting writing) {
    v1::Scene message;
    message.set_version(v1::PROTOCOL_VERSION_CURRENT);
    for (const Band& band : scene.bands) {
        v1::Band* b = message.add_bands();
        b->set_name(band.name);
        b->set_wavelength_min_nm(band.wavelengthMinNm);
        b->set_wavelength_max_nm(band.wavelengthMaxNm);
        b->set_photon_umol_per_j(band.photonUmolPerJ);
    }
    for (const Optics& optics : scene.optics) {
        v1::Optics* o = message.add_optics();
        o->set_id(optics.id);
        for (std::size_t b = 0; b < optics.bands.size(); ++b) {
            v1::BandOptics& values = (*o->mutable_bands())[scene.bands[b].name];
            values.set_rho_upper(optics.bands[b].rhoUpper);
            values.set_rho_lower(optics.bands[b].rhoLower);
            values.set_tau_upper(optics.bands[b].tauUpperToLower);
            values.set_tau_lower(optics.bands[b].tauLowerToUpper);
        }
    }
    if (writing == SceneWriting::kInstanced) {
        WriteInstancedNodes(scene, message);
    } else {
        WriteFlatNodes(scene, message);
    }
    for (const Surface& surface : scene.environment) {
        v1::Surface* s = message.add_environment();
        s->set_name(surface.name);
        s->set_optics(surface.opticsId);
        MeshToProto(*surface.mesh, s->mutable_mesh());
    }
    auto perBand = [&](const std::vector<double>& values,
                       google::protobuf::Map<std::string, double>* map) {
        for (std::size_t b = 0; b < values.size(); ++b) (*map)[scene.bands[b].name] = values[b];
    };
    for (const Sun& sun : scene.sources.suns) {
        v1::Sun* s = message.add_suns();
        s->mutable_direction()->set_x(sun.towardSun.x);
        s->mutable_direction()->set_y(sun.towardSun.y);
        s->mutable_direction()->set_z(sun.towardSun.z);
        perBand(sun.normalIrradianceWm2, s->mutable_normal_irradiance());
        s->set_angular_radius_deg(glm::degrees(sun.angularRadiusRad));
    }
    if (!scene.sources.skies.empty()) {
        const Sky& sky = scene.sources.skies.front();
        v1::Sky* s = message.mutable_sky();
        s->set_model(sky.model == SkyModel::kCieOvercast ? v1::SKY_MODEL_CIE_OVERCAST
                                                         : v1::SKY_MODEL_UNIFORM);
        perBand(sky.horizontalIrradianceWm2, s->mutable_horizontal_irradiance());
        s->set_discretization(DiscretizationToProto(sky.discretization));
    }
    for (const Emitter& emitter : scene.sources.emitters) {
        v1::Emitter* e = message.add_emitters();
        e->set_name(emitter.name);
        e->set_optics(emitter.opticsId);
        MeshToProto(*emitter.mesh, e->mutable_mesh());
        perBand(emitter.exitanceWm2, e->mutable_exitance());
    }
    if (scene.periodic) {
        v1::PeriodicDomain* p = message.mutable_periodic();
        p->set_x_min(scene.periodic->xMin);
        p->set_y_min(scene.periodic->yMin);
        p->set_x_max(scene.periodic->xMax);
        p->set_y_max(scene.periodic->yMax);
    }
    return message;
}

namespace {

using google::protobuf::internal::WireFormatLite;

// A binary scene file read as a stream of fields, `onField(tag, stream)` reading or skipping
// each (false: it does not parse). Throws when the file cannot be opened or read whole.
template <class OnField>
void ReadFields(const std::string& path, const OnField& onField) {
    std::ifstream file(path, std::ios::binary);
    if (!file) Fail(ErrorCode::kIo, path, "cannot open the scene file");
    google::protobuf::io::IstreamInputStream raw(&file);
    google::protobuf::io::CodedInputStream in(&raw);
    while (const std::uint32_t tag = in.ReadTag()) {
        if (!onField(tag, in)) break;
    }
    if (!in.ConsumedEntireMessage() || file.bad())
        Fail(ErrorCode::kParse, path, "is not a binary leaflux.v1.Scene");
}

bool IsNodesField(std::uint32_t tag) {
    return WireFormatLite::GetTagFieldNumber(tag) == v1::Scene::kNodesFieldNumber &&
           WireFormatLite::GetTagWireType(tag) == WireFormatLite::WIRETYPE_LENGTH_DELIMITED;
}

// Every field of the file's Scene but its nodes, which `nodes` then reads from the file one
// at a time (a second pass), having counted them.
v1::Scene BinaryWithoutNodes(const std::string& path, NodeSource& nodes) {
    std::string rest;
    nodes.count = 0;
    {
        google::protobuf::io::StringOutputStream raw(&rest);
        google::protobuf::io::CodedOutputStream out(&raw);
        ReadFields(path, [&](std::uint32_t tag, google::protobuf::io::CodedInputStream& in) {
            if (!IsNodesField(tag)) return WireFormatLite::SkipField(&in, tag, &out);
            ++nodes.count;
            return WireFormatLite::SkipField(&in, tag);
        });
    }
    v1::Scene message;
    if (!message.ParseFromString(rest))
        Fail(ErrorCode::kParse, path, "is not a binary leaflux.v1.Scene");
    nodes.forEach = [path](const std::function<void(const v1::Node&)>& visit) {
        v1::Node node;
        ReadFields(path, [&](std::uint32_t tag, google::protobuf::io::CodedInputStream& in) {
            if (!IsNodesField(tag)) return WireFormatLite::SkipField(&in, tag);
            std::uint32_t length = 0;
            if (!in.ReadVarint32(&length)) return false;
            const auto limit = in.PushLimit(static_cast<int>(length));
            node.Clear();
            const bool parsed = node.MergeFromCodedStream(&in) && in.ConsumedEntireMessage();
            in.PopLimit(limit);
            if (parsed) visit(node);
            return parsed;
        });
    };
    return message;
}

}  // namespace

bool IsBinarySceneFile(const std::string& path) {
    return std::filesystem::path(path).extension() == kBinarySceneExtension;
}

Scene LoadSceneFile(const std::string& path, const ImportOptions& options,
                    const SceneLimits& limits) {
    Scene scene;
    const std::string base = std::filesystem::path(path).parent_path().string();
    if (IsBinarySceneFile(path)) {
        // The nodes, most of a large scene, a node at a time (BinaryWithoutNodes): the whole
        // message beside the scene it becomes made the reading's peak (445 MB of heap for a
        // plantation of 233 trees from 81 MB of binary, 264 MB of it the message); now the
        // solve makes the peak.
        NodeSource nodes;
        const v1::Scene message = BinaryWithoutNodes(path, nodes);
        scene = UncheckedFromProto(message, nodes, base, limits, options);
    } else {
        // So too from text, where each node starts a line and its closing brace ends one
        // (as leaflux writes them): the rest first, then the nodes a run at a time
        // (SplitTextFile). The 233-tree plantation's 240 MB were read into 543 MiB at the
        // peak, 221 once loaded; now 186 once loaded, and the solve makes the peak.
        const auto fail = [](const TextFormatError& error) {
            Fail(error.unreadable ? ErrorCode::kIo : ErrorCode::kParse, error.where,
                 error.unreadable ? "cannot open the scene file" : error.what);
        };
        SplitTextFile file(path, "nodes");
        v1::Scene message;
        std::size_t taken = 0;
        if (const auto error = file.ReadRest(message, taken)) fail(*error);
        if (message.nodes_size() > 0) {  // nodes laid out otherwise: the file read whole
            message.Clear();
            if (const auto error = ReadTextFormat(path, message)) fail(*error);
            scene = UncheckedFromProto(message, NodesOf(message), base, limits, options);
        } else {
            const NodeSource nodes{taken, [&](const auto& visit) {
                                       v1::Scene run;
                                       const auto error = file.ForEachRun(run, [&] {
                                           for (const v1::Node& node : run.nodes()) visit(node);
                                       });
                                       if (error) fail(*error);
                                   }};
            scene = UncheckedFromProto(message, nodes, base, limits, options);
        }
    }
    // Checked once the file's message is freed: the check's tables of every node's frame
    // and name, beside the message and the scene, made the reading's peak (627 MiB for a
    // plantation of 233 trees read from 81 MB of binary).
    scene.Validate();
    return scene;
}

void SaveSceneFile(const Scene& scene, const std::string& path, SceneWriting writing) {
    const v1::Scene message = ToProto(scene, writing);
    std::ofstream out(path, std::ios::binary);
    bool written = static_cast<bool>(out);
    if (written && IsBinarySceneFile(path)) {
        written = message.SerializeToOstream(&out);
    } else if (written) {
        std::string text;
        google::protobuf::TextFormat::PrintToString(message, &text);
        written = static_cast<bool>(out << text);
    }
    if (!written || !out.flush()) Fail(ErrorCode::kIo, path, "cannot write the scene file");
}

}  // namespace leaflux
