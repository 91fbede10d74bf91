// Reads a mesh file, the format chosen by extension: .msh (Gmsh 2.2 / 4.1), .xml (Nektar++
// XML as HOMesh writes it), .unv (I-DEAS universal file, as FreeCAD FEM writes it), .vtk (legacy
// VTK), .vtu (VTK XML) or .cgns (CGNS, io/cgns_reader.hpp). Throws IoError naming the file and
// the problem.
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "io/named_group.hpp"

namespace homesh {

// `notes` (if given) receives a line for each thing the reading did to the file's cells
// (a UNV or VTK file's mirrored solids read with their orientation reversed). `groups` (if
// given) receives the file's named boundary groups (CGNS boundary conditions; none for the
// other formats), for writing them back.
Mesh readMesh(const std::string& path, std::vector<std::string>* notes = nullptr,
              std::vector<NamedGroup>* groups = nullptr);

}  // namespace homesh
