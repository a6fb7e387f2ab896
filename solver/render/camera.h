// A pinhole camera: where it stands, what it looks at, which way is up and how wide it sees,
// and the primary ray through any point of its picture.
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <string>

namespace leaflux {

struct Camera {
    glm::dvec3 eye{0.0, -10.0, 1.5};  // world coordinates (m)
    glm::dvec3 look{0.0, 0.0, 1.5};   // a point the view's centre passes through
    glm::dvec3 up{0.0, 0.0, 1.0};     // towards the picture's top (need not be orthogonal)
    double fovDeg = 45.0;             // the picture's vertical field of view, in (0, 180)
};

// Reads "eye=x,y,z look=x,y,z up=x,y,z fov=deg" (any order; up and fov may be left out)
// and validates it. Errors are InputErrors naming the field ("camera.eye").
Camera ParseCamera(const std::string& text);

// Refuses a camera that sees nothing: a coordinate that is not finite, eye = look, up along
// the view, fov outside (0, 180). The error names the field.
void Validate(const Camera& camera);

// The camera's frame for a picture of width × height pixels.
class View {
  public:
    View(const Camera& camera, int width, int height);

    // The unit direction through picture point (x, y), in pixels from the top-left corner
    // (pixel (i, j) covers [i, i + 1) × [j, j + 1)).
    glm::dvec3 Direction(double x, double y) const;
    const glm::dvec3& Eye() const { return eye_; }
    // Where the world point lands in the picture, in pixels from its top-left corner;
    // nothing for a point on or behind the eye's plane.
    std::optional<glm::dvec2> Project(const glm::dvec3& point) const;
    // Pixels a metre spans at `distance` from the eye along the view (perspective: a length
    // in a plane facing the camera).
    double PixelsPerMetre(double distance) const { return 1.0 / (glm::length(right_) * distance); }
    // Whether a world box may be in view: false only when all its corners lie behind the
    // eye or beyond one side of the picture (conservative: a box near a corner of the view
    // may be kept though unseen).
    bool MaySee(const glm::dvec3& boxMin, const glm::dvec3& boxMax) const;

  private:
    glm::dvec3 eye_, forward_, right_, down_;  // right_ and down_ span one pixel each
    double halfWidth_, halfHeight_;            // in pixels
};

}  // namespace leaflux
