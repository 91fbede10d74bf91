// VTU (VTK XML unstructured grid): the cells of the mesh dimension as VTK Lagrange cells (VTK's
// node order), cell fields plus each element's CAD entity, point fields with each node's CAD
// dimension and index. Data base64 inline, or raw binary appended (smaller, faster to read).
#pragma once

#include <string>
#include <vector>

#include "io/mesh_writers.hpp"

namespace homesh {

void writeVtu(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields,
              bool appended);

}  // namespace homesh
