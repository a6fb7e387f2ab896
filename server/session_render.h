// A session's picture (RenderRequest): its scene as the last cycle left it, coloured by
// the light that cycle returned, drawn by the renderer `leaflux render` uses.
#pragma once

#include "leaflux.pb.h"
#include "solver/scene/geometry.h"
#include "solver/scene/scene.h"

namespace leaflux {

// The largest picture a daemon draws: a side, and its rays (each held until the scale is
// known, 8 bytes a ray: 512 MiB).
inline constexpr unsigned kMaxPictureSide = 4096;
inline constexpr double kMaxPictureRays = 1 << 26;

// Draws `request` on `scene` (flattened as `flat`) with the organs' light of `last`, the
// session's last cycle (null: none yet). Throws InputError naming the field
// ("render.camera.look", "render.band") or TooLarge (render.width, render.pixel_samples).
v1::Picture RenderSession(const Scene& scene, FlatScene flat, const v1::CycleResult* last,
                          const v1::RenderRequest& request);

}  // namespace leaflux
