// The one rule every importer applies to geometry that carries no light: a triangle of zero
// area, an organ whose frame is singular (a zero-length internode) or whose file values
// leave it undefined (a NaN diameter). By default such geometry is skipped — the node stays
// in the topology without it — and listed; under ImportOptions::strict the file is refused,
// naming the first one. Coordinates out of range are refused either way: they are errors in
// the file, not geometry that happens to be small.
//
// Internal to solver/io: OBJ, .can and OPF readers each hold one UnlitGeometry per file.
#pragma once

#include <string>
#include <vector>

#include "solver/io/importers.h"

namespace leaflux {

class UnlitGeometry {
  public:
    UnlitGeometry(std::string path, ImportOptions options)
        : path_(std::move(path)), options_(options) {}

    bool Strict() const { return options_.strict; }
    const std::string& Path() const { return path_; }

    // Skips one piece of geometry; under strict, throws kDegenerate naming `skipped.where`,
    // its node and its reason instead.
    void Skip(SkippedGeometry skipped);

    // Appends to `mesh` the fan triangles of `polygon` (indices into mesh->positions, in
    // file coordinates) that carry light; each that does not is skipped, named by
    // `organ` and the file's `line`. Returns how many were appended.
    std::size_t AddPolygon(Mesh& mesh, const std::vector<unsigned>& polygon, int line,
                           const std::string& organ, std::optional<NodeId> node);

    // The last step of every import, in the coordinates the file places its organs in:
    // refuses coordinates beyond kMaxCoordinateM (naming the node), drops the triangles that
    // carry no light once placed (a shared mesh is copied for that organ only), removes the
    // organ of a node left with no triangle and the environment surfaces left empty, and
    // refuses a file of which nothing is left. Then moves the list into `geometry.skipped`
    // and logs it as one warning.
    void Finish(ImportedGeometry& geometry);

  private:
    std::string path_;
    ImportOptions options_;
    std::vector<SkippedGeometry> skipped_;
};

}  // namespace leaflux
