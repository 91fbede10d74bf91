// Gmsh MSH 4.1, ASCII or binary: $Entities for the CAD entities the nodes and elements lie on
// (tags are the CAD indices), physical groups "SolidN" / "FaceN" / "EdgeN" named like FreeCAD's
// sub-shapes, high-order element types, one $ElementData section per cell field.
#pragma once

#include <string>
#include <vector>

#include "io/mesh_writers.hpp"

namespace homesh {

void writeMsh41(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields,
                bool binary);

}  // namespace homesh
