// libFuzzer target: arbitrary bytes as a leafluxd request — decoding, dispatch, delta
// application and validation — against a daemon holding one open session. The daemon must
// answer every input with a Reply and never crash. Build and run: see the README.
#include <cstddef>
#include <cstdint>
#include <string>

#include "server/daemon.h"

namespace {

leaflux::Daemon& FuzzedDaemon() {
    static leaflux::Daemon* daemon = [] {
        auto* d = new leaflux::Daemon();
        // Resynced under a fixed id (an opened one is random), so that inputs can name it.
        leaflux::v1::Request open;
        open.set_version(leaflux::v1::PROTOCOL_VERSION_CURRENT);
        open.mutable_resync()->set_session("00000000000000000000000000000001");
        leaflux::v1::Scene* scene = open.mutable_resync()->mutable_scene();
        scene->add_bands()->set_name("PAR");
        leaflux::v1::Optics* optics = scene->add_optics();
        optics->set_id("leaf");
        (*optics->mutable_bands())["PAR"].set_rho_upper(0.1);
        leaflux::v1::Node* plant = scene->add_nodes();
        plant->set_id(1);
        leaflux::v1::Sun* sun = scene->add_suns();
        sun->mutable_direction()->set_z(1.0);
        (*sun->mutable_normal_irradiance())["PAR"] = 1000.0;
        d->Handle(open);
        return d;
    }();
    return *daemon;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string reply =
        FuzzedDaemon().Handle(std::string(reinterpret_cast<const char*>(data), size));
    leaflux::v1::Reply decoded;
    if (!decoded.ParseFromString(reply)) __builtin_trap();  // every input gets a Reply
    return 0;
}
