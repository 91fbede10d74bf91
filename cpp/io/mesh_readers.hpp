// Reads a mesh file, the format chosen by extension: .msh (Gmsh 2.2 / 4.1) or .xml (Nektar++
// XML as HOMesh writes it). Throws IoError naming the file and the problem.
#pragma once

#include <string>

#include "core/mesh.hpp"

namespace homesh {

Mesh readMesh(const std::string& path);

}  // namespace homesh
