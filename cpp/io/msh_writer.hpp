// Gmsh MSH 4.1, ASCII or binary: $Entities for the CAD entities the nodes and elements lie on
// (tags are the CAD indices), physical groups "SolidN" / "FaceN" / "EdgeN" named like FreeCAD's
// sub-shapes, high-order element types, one $ElementData section per cell field.
#pragma once

#include <string>
#include <vector>

#include "io/mesh_writers.hpp"

namespace homesh {

// `named` (checked by checkGroups): their entities form one physical group each, named after
// the group, with tags after the largest entity tag of that dimension.
void writeMsh41(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields,
                bool binary, const std::vector<NamedGroup>& named = {});

}  // namespace homesh
