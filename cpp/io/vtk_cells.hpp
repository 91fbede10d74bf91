// VTK's cell types, as the VTK readers (legacy .vtk, XML .vtu) and the VTU writer need them:
// which HOMesh cell a type code is and how its nodes are numbered.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/cell_type.hpp"
#include "io/foreign_mesh.hpp"

namespace homesh {

// VTK's Lagrange cell code of a shape (VTK_LAGRANGE_CURVE 68 ... VTK_LAGRANGE_WEDGE 73; none for
// a pyramid: VTK 9.1 has no Lagrange pyramid, and a linear one is a VTK_PYRAMID, 14).
std::uint8_t vtkLagrangeType(CellType type);

// perm[i] = index, in Gmsh order, of the i-th node of VTK's Lagrange cell. `hexVersion1`: VTK
// 9 renumbered the Lagrange hexahedron; files older than XML version 2.2 (legacy 5.1) list the
// nodes of edges 10 and 11 (through vertices 2-6 and 3-7) the other way round.
std::vector<int> vtkPermutationFromGmsh(CellType type, int order, bool hexVersion1);

// The cells of an unstructured grid (or of one piece of it, whose points are those from
// `firstPoint` on in `mesh`): cell c has the points connectivity[start .. offsets[c]) (start:
// the previous offset, 0 for the first), numbered from 0 in the piece, and VTK type types[c].
// Each is added to `mesh`
// in Gmsh's order: linear cells (VTK_LINE, _TRIANGLE, _QUAD, _TETRA, _HEXAHEDRON, _PYRAMID,
// _WEDGE, whose handedness is the opposite of Gmsh's prism), quadratic ones that are complete
// Lagrange cells (VTK_QUADRATIC_EDGE, _QUADRATIC_TRIANGLE, _QUADRATIC_TETRA, _BIQUADRATIC_QUAD,
// _TRIQUADRATIC_HEXAHEDRON) and Lagrange cells of orders 1 to 10; vertices are skipped. Throws
// IoError "<where>: cell N ..." for other types (serendipity, curved pyramids, polygons, ...), node
// counts that do not fit the type, offsets out of order or point ids outside the piece.
void addVtkCells(ForeignMesh& mesh, const std::vector<std::int64_t>& connectivity,
                 const std::vector<std::int64_t>& offsets, const std::vector<std::int64_t>& types,
                 bool hexVersion1, std::int64_t firstPoint, const std::string& where);

}  // namespace homesh
