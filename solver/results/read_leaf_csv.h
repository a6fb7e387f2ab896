// Reads back the per-organ CSV every solver writes (WriteLeafCsv), so that a solution
// already written can be drawn or compared without solving again.
#pragma once

#include <string>

#include "solver/results/light.h"
#include "solver/scene/geometry.h"
#include "solver/scene/scene.h"

namespace leaflux {

// The light of each receiver of `flat` (the scene the file was solved on) found in the
// file at `path`: irradiances and absorbed power by band; receivers the file does not
// list are `unsolved`. Errors (InputError) name path:line and the column or value.
Solution ReadLeafCsv(const std::string& path, const Scene& scene, const FlatScene& flat);

}  // namespace leaflux
