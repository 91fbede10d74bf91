// Writers of the formats CFD tools read, chosen by file extension.
//
// - Gmsh MSH 4.1 (msh_writer.hpp), ASCII or binary.
// - VTU, VTK's XML unstructured grid with Lagrange cells (vtu_writer.hpp), base64 inline or raw
//   appended binary.
// - Nektar++ XML (nektar_writer.hpp), plain or compressed (B64Z-LittleEndian).
// - CGNS (cgns_writer.hpp), HDF5, orders 1 to 4.
// Files are written to a temporary name and renamed, so a failed write never leaves a truncated
// file behind.
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "io/gmsh_element_types.hpp"
#include "io/named_group.hpp"

namespace homesh {

// One value per cell of every block: first the cells of dimension mesh.dim (the elements), then
// the lower-dimensional (boundary) cells, each group in block order. This is also the order of
// element tags in MSH files. VTU files, which hold the elements only, use the first part.
struct CellField {
  std::string name;
  std::vector<double> values;
};

struct WriteOptions {
  bool binary = false;      // MSH: binary; VTU: raw appended data (else base64 inline)
  bool compressed = false;  // Nektar++ XML: B64Z-LittleEndian sections
  std::vector<NamedGroup> groups;
};

// Throws ParameterError for an empty name or one with a quote, '<', '>' or '&' (it goes into
// MSH and XML text), a name used twice, an entity in two groups, or an entity no boundary cell
// of `mesh` lies on (naming the group and the entity).
void checkGroups(const Mesh& mesh, const std::vector<NamedGroup>& groups);

// Throws IoError unless `path` has a supported extension (.msh, .vtu, .xml) and its folder
// exists: lets callers reject a bad output path before spending time on meshing.
void checkMeshOutputPath(const std::string& path);

// Chooses the format from the extension; throws IoError for others.
void writeMesh(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields,
               const WriteOptions& options = {});

// Throws Error unless every field has one value per cell.
void checkCellFields(const Mesh& mesh, const std::vector<CellField>& fields);

}  // namespace homesh
