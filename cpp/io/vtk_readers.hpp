// Reads VTK unstructured grids, as FreeCAD FEM (FemMesh.write), meshio, ParaView and HOMesh
// write them: the legacy format (.vtk: ASCII or BINARY, file versions 2 to 4 with CELLS lists
// and 5.1 with OFFSETS and CONNECTIVITY) and the XML format (.vtu: ascii, base64 binary or
// appended data, raw or base64; UInt32 or UInt64 headers; zlib compression; either byte order;
// several pieces). Points and cells only: point and cell data are not read. The cell types read
// and their node orders are those of vtk_cells.hpp.
//
// Every error is an IoError naming the file and the line (legacy), the data array (XML) or the
// cell.
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

// `notes` (if given) receives what the reading changed (see assembleForeignMesh).
Mesh readLegacyVtk(const std::string& path, std::vector<std::string>* notes = nullptr);
Mesh readVtu(const std::string& path, std::vector<std::string>* notes = nullptr);

}  // namespace homesh
