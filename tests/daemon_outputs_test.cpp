// What a cycle's reply holds, by what it asks: only the bands asked for, light vectors only
// when asked, and PAR in photons beside W/m².
#include <gtest/gtest.h>

#include <string>
#include <tuple>

#include "server/daemon.h"
#include "tests/daemon_requests.h"

namespace leaflux {
namespace {

using test::CycleRequest;
using test::Leaf;
using test::OpenRequest;

TEST(DaemonBands, OnlyTheRequestedBandsAreSolvedAndSent) {
    v1::Request open = OpenRequest();
    v1::Scene* scene = open.mutable_open_session()->mutable_scene();
    scene->add_bands()->set_name("NIR");
    v1::BandOptics& nir = (*scene->mutable_optics(0)->mutable_bands())["NIR"];
    nir.set_rho_upper(0.45), nir.set_rho_lower(0.45), nir.set_tau_upper(0.45),
        nir.set_tau_lower(0.45);
    (*scene->mutable_suns(0)->mutable_normal_irradiance())["NIR"] = 800.0;
    *scene->add_nodes() = Leaf(3, 1, 0.02, 0.9);
    Daemon daemon;
    const std::string session = daemon.Handle(open).opened().session();
    v1::Request both = CycleRequest(session, 1);
    const v1::Reply all = daemon.Handle(both);
    ASSERT_TRUE(all.has_cycle()) << all.DebugString();
    v1::Request one = CycleRequest(session, 2);
    one.mutable_cycle()->mutable_outputs()->add_bands("NIR");
    const v1::Reply nirOnly = daemon.Handle(one);
    ASSERT_TRUE(nirOnly.has_cycle()) << nirOnly.DebugString();
    ASSERT_EQ(nirOnly.cycle().organs(0).bands_size(), 1);
    EXPECT_EQ(nirOnly.cycle().organs(0).bands(0).band(), "NIR");
    ASSERT_EQ(nirOnly.cycle().statistics().balance_size(), 1);
    // The shaded leaf's NIR: its refinement now weighs NIR power alone, so close, not equal.
    const double full = all.cycle().organs(1).bands(1).irradiance_upper_wm2();
    EXPECT_NEAR(nirOnly.cycle().organs(1).bands(0).irradiance_upper_wm2(), full, 0.05 * full);
    one.mutable_cycle()->mutable_outputs()->add_bands("NIR");
    one.mutable_cycle()->set_number(3);
    EXPECT_EQ(daemon.Handle(one).error().code(), v1::ERROR_CODE_ALREADY_EXISTS);
}

// A cycle asking no light vectors gets none, and the same irradiance: the solver skips only
// the gathering of the light's directions.
TEST(DaemonOutputs, LightVectorsOnlyWhenAsked) {
    v1::Request open = OpenRequest();
    *open.mutable_open_session()->mutable_scene()->add_nodes() = Leaf(3, 1, 0.02, 0.9);
    Daemon daemon;
    const std::string session = daemon.Handle(open).opened().session();
    const v1::Reply with = daemon.Handle(CycleRequest(session, 1));
    ASSERT_TRUE(with.has_cycle()) << with.DebugString();
    v1::Request request = CycleRequest(session, 2);
    request.mutable_cycle()->mutable_outputs()->set_light_vectors(false);
    const v1::Reply without = daemon.Handle(request);
    ASSERT_TRUE(without.has_cycle()) << without.DebugString();
    EXPECT_FALSE(without.cycle().statistics().reused());
    ASSERT_EQ(without.cycle().organs_size(), with.cycle().organs_size());
    for (int i = 0; i < with.cycle().organs_size(); ++i) {
        const v1::BandLight& a = with.cycle().organs(i).bands(0);
        const v1::BandLight& b = without.cycle().organs(i).bands(0);
        EXPECT_TRUE(a.has_light_vector());
        EXPECT_FALSE(b.has_light_vector());
        EXPECT_EQ(b.irradiance_upper_wm2(), a.irradiance_upper_wm2());
        EXPECT_EQ(b.irradiance_lower_wm2(), a.irradiance_lower_wm2());
        EXPECT_EQ(b.absorbed_w(), a.absorbed_w());
    }
    EXPECT_GT(with.cycle().organs(0).bands(0).light_vector().z(), 0.5);  // the sun is above
}

// PAR comes in photons beside W/m²: 4.57 µmol/J for a PAR band that gives no factor, the
// band's own factor when it gives one, and none for a band without a photon unit.
TEST(DaemonOutputs, PhotonUnitsComeWithEachBandThatHasOne) {
    for (const auto& [name, factor, want] :
         {std::tuple{"PAR", 0.0, 4.57}, {"PAR", 4.2, 4.2}, {"NIR", 0.0, 0.0}}) {
        v1::Request open = OpenRequest();
        v1::Scene* scene = open.mutable_open_session()->mutable_scene();
        scene->mutable_bands(0)->set_name(name);
        scene->mutable_bands(0)->set_photon_umol_per_j(factor);
        v1::Optics* optics = scene->mutable_optics(0);
        (*optics->mutable_bands())[name] = optics->bands().at("PAR");
        if (std::string(name) != "PAR") optics->mutable_bands()->erase("PAR");
        v1::Sun* sun = scene->mutable_suns(0);
        (*sun->mutable_normal_irradiance())[name] = 400.0;
        if (std::string(name) != "PAR") sun->mutable_normal_irradiance()->erase("PAR");
        Daemon daemon;
        const v1::Reply opened = daemon.Handle(open);
        ASSERT_TRUE(opened.has_opened()) << opened.DebugString();
        const v1::Reply reply = daemon.Handle(CycleRequest(opened.opened().session(), 1));
        ASSERT_TRUE(reply.has_cycle()) << reply.DebugString();
        const v1::BandLight& b = reply.cycle().organs(0).bands(0);
        ASSERT_GT(b.irradiance_upper_wm2(), 0.0);
        if (want == 0.0) {
            EXPECT_FALSE(b.has_photon_irradiance_upper_umol_m2_s()) << name;
            EXPECT_FALSE(b.has_absorbed_umol_s());
            continue;
        }
        EXPECT_DOUBLE_EQ(b.photon_irradiance_upper_umol_m2_s(), want * b.irradiance_upper_wm2());
        EXPECT_DOUBLE_EQ(b.photon_irradiance_lower_umol_m2_s(), want * b.irradiance_lower_wm2());
        EXPECT_DOUBLE_EQ(b.absorbed_umol_s(), want * b.absorbed_w());
    }
}

}  // namespace
}  // namespace leaflux
