// The light of a radiosity solve as the units hand it to each other, per node of one
// hierarchy and per channel (Channels):
//   Field       what leaves the nodes (radiosity of patches and planes, intensity of
//               clusters): read by links, written by pull-up and the radiosity update;
//   Gathered    what links bring to their receivers (Gather);
//   SourceLight what the directional sources bring to each leaf patch (PushSources);
//   LeafLight   what arrives on each leaf patch, all of it (PushDown), and what it emits;
//   ClosedLight what arrives on each closed instance, from the nodes and from the sources.
// Each is plain data: the units that fill it say how.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "solver/radiosity/channels.h"

namespace leaflux {

struct Field {
    Field(const Channels& channels, int bins)
        : radiosity(channels.Count()),
          intensity(static_cast<std::size_t>(bins) * channels.Count()) {}

    SideTable radiosity;          // per node: W/m² leaving each side (a plane's: its parts' mean)
    std::vector<double> emitted;  // per node: W leaving it, all channels (Channels::Measure)
    Table<double> intensity;      // per cluster slot: [bin][channel], W/sr leaving towards it

    void Resize(std::size_t nodes) {
        radiosity.Resize(nodes);
        emitted.resize(nodes, 0.0);
    }
};

struct Gathered {
    Gathered(const Channels& channels, int binCount)
        : bins(static_cast<std::size_t>(binCount) * channels.Count()),
          sides(channels.Count()),
          integral(channels.Count()),
          moment(channels.Count()) {}

    Table<double> bins;        // per cluster slot: [bin][channel], W/m² normal to the bin
    SideTable sides;           // per plane: W/m² on each side
    Table<double> integral;    // per plane: ∫ L dω (W/m²)
    Table<glm::dvec3> moment;  // per plane: ∫ L ω dω (W/m²)
};

struct SourceLight {
    explicit SourceLight(const Channels& channels)
        : sides(channels.Count()),
          incident(channels.Count()),
          integral(channels.Count()),
          moment(channels.Count()) {}

    SideTable sides;
    SideTable incident;  // of it, what the suns and sky cones bring (DirectionalSource::incident)
    Table<double> integral;
    Table<glm::dvec3> moment;
};

struct LeafLight {
    explicit LeafLight(const Channels& channels)
        : irradiance(channels.Count()),
          direct(channels.Count()),
          change(channels.Count()),
          integral(channels.Count()),
          moment(channels.Count()),
          emission(channels.Count()) {}

    SideTable irradiance;      // W/m² arriving on each side, as the last push left it
    SideTable direct;          // the first sweep's: the light straight from the sources
    SideTable change;          // of the radiosity, in the last update
    Table<double> integral;    // ∫ L dω over the sphere (W/m²)
    Table<glm::dvec3> moment;  // ∫ L ω dω (W/m²)
    Table<double> emission;    // exitance of emitter patches (W/m², upper side)

    void Resize(std::size_t nodes) {
        irradiance.Resize(nodes);
        direct.Resize(nodes);
        change.Resize(nodes);
        integral.Resize(nodes);
        moment.Resize(nodes);
    }
};

struct ClosedLight {
    ClosedLight(const Channels& channels, int binCount, std::size_t closed, std::size_t sourceCount)
        : bins(static_cast<std::size_t>(binCount) * channels.Count(), closed),
          sources(sourceCount, closed) {}

    Table<double> bins;     // per closed instance: [bin][channel], W/m² normal to the bin
    Table<double> sources;  // per closed instance: the visibility of each directional source
};

}  // namespace leaflux
