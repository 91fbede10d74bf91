// How closely a mesh made elsewhere (a file Gmsh, NekMesh or an earlier run wrote) follows a CAD
// model: what `homesh quality --cad` reports, so that fidelity is compared between tools on one
// measure (bench/fidelity).
//
// The model is read as `homesh mesh` reads it (setupCase: a CAD file as it is, a .mcf's CAD in
// metres as NekMesh reads it) and healed and imprinted with the default HealingOptions, as it is
// meshed; the mesh's boundary is put on it by its cells' corners (quality/boundary_on_cad.hpp)
// and measured as the pipeline's "geometry" stage measures its own (quality/geometry_accuracy.hpp).
#pragma once

#include <string>

#include "quality/geometry_accuracy.hpp"

namespace homesh {

// `relativeTolerance`: how far a boundary cell's corner may lie from the CAD, relative to the
// model's bounding diagonal (<= 0: the parameter table's classify_tolerance). Throws IoError,
// CadError or ParameterError for the CAD file, and what boundaryOnCad and
// measureGeometryAccuracy throw.
GeometryAccuracy checkGeometryAgainstCad(const Mesh& mesh, const std::string& cadPath, int threads,
                                         double relativeTolerance = 0.0);

}  // namespace homesh
