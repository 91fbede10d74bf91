// The common end of the readers of formats that carry no CAD (I-DEAS UNV, VTK): nodes and cells
// as a file lists them, turned into a Mesh with the checks and normalisations these formats need
// and MSH does not (its writers follow Gmsh's conventions).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

struct ForeignMesh {
  std::vector<double> xyz;           // 3 per node, finite (the reader checks)
  std::vector<std::int64_t> labels;  // the file's name of each node (UNV labels); empty: index
  std::vector<ElementBlock> blocks;  // Gmsh node order, 0-based node ids in range

  // Appends a cell to the block of its type and order (made when first met).
  void addCell(CellType type, int order, const std::int64_t* nodes, std::int32_t entity);
};

// The mesh of `raw`: elements are the cells of the highest dimension (2 or 3), the others its
// boundary. Throws IoError naming `path` when it has no 2D or 3D cell, mixes orders, or its 2D
// elements do not lie in one plane (HOMesh checks volume meshes and planar 2D meshes; a shell's
// validity is not defined by a plane's normal). Writers differ in the handedness of their
// solids (FreeCAD FEM's VTK export lists tetrahedra in SMESH's order, which VTK reads as
// inverted): a block of 3D cells whose every cell has a negative volume is read mirrored, and a
// line saying so is appended to `notes` (if given). A block with cells of both signs is kept as
// it is: there the cells against the majority are folded, and the verdicts say so.
Mesh assembleForeignMesh(ForeignMesh raw, const std::string& path, std::vector<std::string>* notes);

// `text` quoted for a one-line error message: at most `limit` characters, anything not
// printable ASCII (binary garbage, line breaks) shown as '?'.
std::string quoteExcerpt(std::string_view text, std::size_t limit = 40);

}  // namespace homesh
