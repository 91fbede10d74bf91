// Reads a mesh file, the format chosen by extension: .msh (Gmsh 2.2 / 4.1), .xml (Nektar++
// XML as HOMesh writes it), .unv (I-DEAS universal file, as FreeCAD FEM writes it), .vtk (legacy
// VTK) or .vtu (VTK XML). Throws IoError naming the file and the problem.
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"

namespace homesh {

// `notes` (if given) receives a line for each thing the reading did to the file's cells
// (a UNV or VTK file's mirrored solids read with their orientation reversed).
Mesh readMesh(const std::string& path, std::vector<std::string>* notes = nullptr);

}  // namespace homesh
