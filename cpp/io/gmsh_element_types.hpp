// Gmsh's element type codes (MSH files) for complete Lagrange elements: shape and order.
#pragma once

#include <optional>
#include <utility>

#include "core/cell_type.hpp"

namespace homesh {

// The code of a shape and order; throws ParameterError when Gmsh has none (Gmsh 4.8 stops at
// order 10 for lines, triangles, quadrilaterals and tetrahedra, at 9 for prisms and hexahedra).
int gmshElementType(CellType type, int order);

// Shape and order of a code, or nothing for codes HOMesh does not read (points, serendipity
// and incomplete elements, pyramids).
std::optional<std::pair<CellType, int>> cellFromGmshType(int code);

}  // namespace homesh
