// Writers of the formats CFD tools read.
//
// - Gmsh MSH 4.1 (ASCII): $Entities for the CAD entities the nodes and elements lie on (tags are
//   the CAD indices), physical groups "SolidN" / "FaceN" / "EdgeN" named like FreeCAD's
//   sub-shapes, high-order element types, and one $ElementData section per cell field.
// - VTU (VTK XML unstructured grid, base64 binary): the cells of the mesh dimension as VTK
//   Lagrange cells, cell fields plus the CAD entity, point fields with each node's CAD dimension
//   and index.
// Files are written to a temporary name and renamed, so a failed write never leaves a truncated
// file behind.
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "io/gmsh_element_types.hpp"

namespace homesh {

// One value per cell of every block: first the cells of dimension mesh.dim (the elements), then
// the lower-dimensional (boundary) cells, each group in block order. This is also the order of
// element tags in MSH files. VTU files, which hold the elements only, use the first part.
struct CellField {
  std::string name;
  std::vector<double> values;
};

void writeMsh41(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields);
void writeVtu(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields);

// Throws IoError unless `path` has a supported extension and its folder exists: lets callers
// reject a bad output path before spending time on meshing.
void checkMeshOutputPath(const std::string& path);

// Chooses the format from the extension (.msh, .vtu); throws IoError for others.
void writeMesh(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields);

}  // namespace homesh
