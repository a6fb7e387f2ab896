#include "solver/render/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <sstream>

#include "solver/util/box.h"
#include "solver/util/error.h"

namespace leaflux {
namespace {

// "x,y,z" as three finite numbers, else an error naming the field.
glm::dvec3 ParseVector(const std::string& text, const std::string& field) {
    glm::dvec3 v;
    std::size_t at = 0;
    for (int k = 0; k < 3; ++k) {
        const std::size_t comma = k < 2 ? text.find(',', at) : text.size();
        if (comma == std::string::npos) {
            throw InputError(ErrorCode::kParse, field,
                             "expects three numbers x,y,z, got '" + text + "'");
        }
        const std::string part = text.substr(at, comma - at);
        char* end = nullptr;
        v[k] = std::strtod(part.c_str(), &end);
        if (part.empty() || end != part.c_str() + part.size()) {
            throw InputError(ErrorCode::kParse, field,
                             "expects three numbers x,y,z, got '" + text + "'");
        }
        at = comma + 1;
    }
    return v;
}

bool Finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

Camera ParseCamera(const std::string& text) {
    Camera camera;
    bool eye = false, look = false;
    std::istringstream words(text);
    std::string word;
    while (words >> word) {
        const std::size_t equals = word.find('=');
        const std::string key = word.substr(0, equals);
        if (equals == std::string::npos) {
            throw InputError(ErrorCode::kParse, "camera",
                             "expects key=value words (eye, look, up, fov), got '" + word + "'");
        }
        const std::string value = word.substr(equals + 1);
        if (key == "eye") {
            camera.eye = ParseVector(value, "camera.eye");
            eye = true;
        } else if (key == "look") {
            camera.look = ParseVector(value, "camera.look");
            look = true;
        } else if (key == "up") {
            camera.up = ParseVector(value, "camera.up");
        } else if (key == "fov") {
            char* end = nullptr;
            camera.fovDeg = std::strtod(value.c_str(), &end);
            if (value.empty() || end != value.c_str() + value.size()) {
                throw InputError(ErrorCode::kParse, "camera.fov",
                                 "expects degrees, got '" + value + "'");
            }
        } else {
            throw InputError(ErrorCode::kParse, "camera." + key,
                             "unknown; the camera has eye, look, up and fov");
        }
    }
    if (!eye) throw InputError(ErrorCode::kInvalidArgument, "camera.eye", "missing");
    if (!look) throw InputError(ErrorCode::kInvalidArgument, "camera.look", "missing");
    Validate(camera);
    return camera;
}

void Validate(const Camera& camera) {
    if (!Finite(camera.eye))
        throw InputError(ErrorCode::kInvalidArgument, "camera.eye", "not finite");
    if (!Finite(camera.look))
        throw InputError(ErrorCode::kInvalidArgument, "camera.look", "not finite");
    if (!Finite(camera.up))
        throw InputError(ErrorCode::kInvalidArgument, "camera.up", "not finite");
    const glm::dvec3 view = camera.look - camera.eye;
    const double scale = std::max(glm::length(camera.eye), glm::length(camera.look));
    if (glm::length(view) <= 1e-12 * std::max(scale, 1.0)) {
        throw InputError(ErrorCode::kInvalidArgument, "camera.look",
                         "equals camera.eye: the camera looks nowhere");
    }
    if (glm::length(glm::cross(glm::normalize(view), camera.up)) <= 1e-9 * glm::length(camera.up)) {
        throw InputError(ErrorCode::kInvalidArgument, "camera.up",
                         "zero or along the view: it gives the picture no top");
    }
    if (!(camera.fovDeg > 0.0 && camera.fovDeg < 180.0)) {
        throw InputError(ErrorCode::kInvalidArgument, "camera.fov", "must lie in (0, 180) degrees");
    }
}

View::View(const Camera& camera, int width, int height)
    : eye_(camera.eye),
      forward_(glm::normalize(camera.look - camera.eye)),
      halfWidth_(0.5 * width),
      halfHeight_(0.5 * height) {
    const glm::dvec3 right = glm::normalize(glm::cross(forward_, camera.up));
    const glm::dvec3 up = glm::cross(right, forward_);
    // The picture plane at distance 1: its half height is tan(fov / 2), over halfHeight_ pixels.
    const double pixel = std::tan(0.5 * glm::radians(camera.fovDeg)) / halfHeight_;
    right_ = right * pixel;
    down_ = -up * pixel;
}

bool View::MaySee(const glm::dvec3& boxMin, const glm::dvec3& boxMax) const {
    // Each corner against the eye's plane and the four planes through the eye and the
    // picture's edges; the box is out when one plane has every corner outside it.
    const double tanX = glm::length(right_) * halfWidth_, tanY = glm::length(down_) * halfHeight_;
    const glm::dvec3 right = glm::normalize(right_), down = glm::normalize(down_);
    int outside[5] = {0, 0, 0, 0, 0};
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 d = BoxCorner(boxMin, boxMax, corner) - eye_;
        const double z = glm::dot(d, forward_), x = glm::dot(d, right), y = glm::dot(d, down);
        outside[0] += z <= 0.0;
        outside[1] += x > z * tanX;
        outside[2] += x < -z * tanX;
        outside[3] += y > z * tanY;
        outside[4] += y < -z * tanY;
    }
    return std::none_of(std::begin(outside), std::end(outside), [](int n) { return n == 8; });
}

std::optional<glm::dvec2> View::Project(const glm::dvec3& point) const {
    const glm::dvec3 d = point - eye_;
    const double z = glm::dot(d, forward_);
    if (!(z > 0.0)) return std::nullopt;
    // Direction(x, y) ∝ forward + (x − w/2) right_ + (y − h/2) down_, right_ ⊥ down_.
    const double r2 = glm::dot(right_, right_), d2 = glm::dot(down_, down_);
    return glm::dvec2(halfWidth_ + glm::dot(d, right_) / (z * r2),
                      halfHeight_ + glm::dot(d, down_) / (z * d2));
}

glm::dvec3 View::Direction(double x, double y) const {
    return glm::normalize(forward_ + (x - halfWidth_) * right_ + (y - halfHeight_) * down_);
}

}  // namespace leaflux
