// A named boundary group (wall, inlet, farfield ...): CAD entities of dimension mesh.dim - 1
// (faces in 3D, curves in 2D) written as one physical group (MSH), composite (Nektar++) or
// boundary condition (CGNS) called `name`, instead of one per entity ("FaceN"). VTU holds the
// elements only: no groups.
#pragma once

#include <string>
#include <vector>

namespace homesh {

struct NamedGroup {
  std::string name;
  std::vector<int> entities;  // 1-based, FreeCAD's FaceN / EdgeN
};

}  // namespace homesh
