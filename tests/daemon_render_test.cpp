// RenderRequest: the daemon draws a session's scene in the light its last cycle returned,
// and refuses a bad request naming the field, the session left as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "server/daemon.h"
#include "server/session_render.h"
#include "solver/render/image.h"
#include "tests/daemon_requests.h"

namespace leaflux {
namespace {

using test::CycleRequest;
using test::OpenRequest;

v1::Vec3 Vec(double x, double y, double z) {
    v1::Vec3 v;
    v.set_x(x), v.set_y(y), v.set_z(z);
    return v;
}

// The leaf of OpenRequest() (10 cm square at z = 1 m, its corner at the origin) seen from
// 2 m above, filling the view, on the grey scale from 0 to 2000 W/m².
v1::Request RenderRequest(const std::string& session) {
    v1::Request request;
    request.set_version(v1::PROTOCOL_VERSION_CURRENT);
    v1::RenderRequest* render = request.mutable_render();
    render->set_session(session);
    *render->mutable_camera()->mutable_eye() = Vec(0.05, 0.05, 3.0);
    *render->mutable_camera()->mutable_look() = Vec(0.05, 0.05, 1.0);
    *render->mutable_camera()->mutable_up() = Vec(0.0, 1.0, 0.0);
    render->mutable_camera()->set_fov_deg(2.0);
    render->set_width(64), render->set_height(48);
    render->set_palette(v1::RENDER_PALETTE_GREY);
    render->mutable_range()->set_min(0.0);
    render->mutable_range()->set_max(2000.0);
    return request;
}

Image Decoded(const std::string& png) {
    const std::string path =
        (std::filesystem::temp_directory_path() / "leaflux_daemon_render.png").string();
    std::ofstream(path, std::ios::binary) << png;
    Image image = ReadPng(path);
    std::filesystem::remove(path);
    return image;
}

TEST(DaemonRender, APictureShowsTheLightTheLastCycleReturned) {
    Daemon daemon;
    const std::string session = daemon.Handle(OpenRequest()).opened().session();
    const v1::Reply lit = daemon.Handle(CycleRequest(session, 1));
    ASSERT_TRUE(lit.has_cycle()) << lit.DebugString();
    const double irradiance = lit.cycle().organs(0).bands(0).irradiance_upper_wm2();
    EXPECT_NEAR(irradiance, 1000.0 / std::sqrt(1.04), 1e-6);  // the sun at atan 0.2 from zenith

    const v1::Reply reply = daemon.Handle(RenderRequest(session));
    ASSERT_TRUE(reply.has_picture()) << reply.DebugString();
    const v1::Picture& picture = reply.picture();
    EXPECT_EQ(picture.width(), 64u);
    EXPECT_GT(picture.height(), 48u);  // the colour bar's panel
    EXPECT_EQ(picture.scale_max(), 2000.0);
    EXPECT_EQ(picture.caption(), "PAR irradiance, side facing the camera (W/m²)");
    const Image image = Decoded(picture.png());
    ASSERT_EQ(image.Width(), 64);
    const auto grey = static_cast<std::uint8_t>(std::lround(255.0 * irradiance / 2000.0));
    EXPECT_EQ(image.At(32, 24), (Rgb{grey, grey, grey}));

    // Nothing changed: the next cycle asking the same gets the same light unsolved.
    const v1::Reply again = daemon.Handle(CycleRequest(session, 2));
    EXPECT_TRUE(again.cycle().statistics().reused());
}

TEST(DaemonRender, ABadPictureRequestIsRefusedNamingItsFieldAndChangesNothing) {
    Daemon daemon;
    const std::string session = daemon.Handle(OpenRequest()).opened().session();
    const auto refused = [&](const v1::Request& request, v1::ErrorCode code,
                             const std::string& field) {
        const v1::Reply reply = daemon.Handle(request);
        ASSERT_TRUE(reply.has_error()) << field;
        EXPECT_EQ(reply.error().code(), code) << reply.error().message();
        EXPECT_EQ(reply.error().field(), field) << reply.error().message();
    };
    refused(RenderRequest(session), v1::ERROR_CODE_NOT_FOUND, "render.session");  // no cycle yet
    refused(RenderRequest("0123456789abcdef0123456789abcdef"), v1::ERROR_CODE_UNKNOWN_SESSION,
            "session");
    ASSERT_TRUE(daemon.Handle(CycleRequest(session, 1)).has_cycle());

    v1::Request request = RenderRequest(session);
    *request.mutable_render()->mutable_camera()->mutable_look() = Vec(0.05, 0.05, 3.0);
    refused(request, v1::ERROR_CODE_INVALID_ARGUMENT, "render.camera.look");  // eye = look
    request = RenderRequest(session);
    request.mutable_render()->mutable_camera()->clear_eye();
    refused(request, v1::ERROR_CODE_INVALID_ARGUMENT, "render.camera.eye");
    request = RenderRequest(session);
    request.mutable_render()->mutable_camera()->set_fov_deg(180.0);
    refused(request, v1::ERROR_CODE_INVALID_ARGUMENT, "render.camera.fov");
    request = RenderRequest(session);
    request.mutable_render()->set_band("NIR");
    refused(request, v1::ERROR_CODE_NOT_FOUND, "render.band");
    request = RenderRequest(session);
    request.mutable_render()->set_quantity(v1::RENDER_QUANTITY_TRUE_COLOUR);
    refused(request, v1::ERROR_CODE_NOT_FOUND, "render.rgb[0]");  // no band R
    request = RenderRequest(session);
    request.mutable_render()->mutable_range()->set_max(0.0);
    refused(request, v1::ERROR_CODE_INVALID_ARGUMENT, "render.range");
    request = RenderRequest(session);
    request.mutable_render()->set_width(kMaxPictureSide + 1);
    refused(request, v1::ERROR_CODE_TOO_LARGE, "render.width");
    request = RenderRequest(session);
    request.mutable_render()->set_width(4096), request.mutable_render()->set_height(4096);
    request.mutable_render()->set_pixel_samples(16);
    refused(request, v1::ERROR_CODE_TOO_LARGE, "render.pixel_samples");

    // A cycle that returned no organ light leaves nothing to draw.
    v1::Request dark = CycleRequest(session, 2);
    dark.mutable_cycle()->mutable_outputs()->set_leaves(false);
    ASSERT_TRUE(daemon.Handle(dark).has_cycle());
    refused(RenderRequest(session), v1::ERROR_CODE_NOT_FOUND, "render.session");
    dark.mutable_cycle()->set_number(3);
    EXPECT_TRUE(daemon.Handle(dark).cycle().statistics().reused());  // as it was
}

}  // namespace
}  // namespace leaflux
