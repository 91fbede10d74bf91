// The sizing octree as a mesh, so that a user can see in ParaView why the mesh is fine where it
// is: one hexahedron per leaf (a quadrilateral in 2D) that is at least partly inside, with the
// cell fields "delta" (the leaf's graded size), "inside_fraction", "level" and "location"
// (2 inside, 1 boundary).
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "io/mesh_writers.hpp"

namespace homesh {

class SizingOctree;

struct OctreeMesh {
  Mesh mesh;
  std::vector<CellField> fields;
};

OctreeMesh octreeLeavesMesh(const SizingOctree& octree);

// Writes octreeLeavesMesh to a .vtu (or any format writeMesh knows). Throws IoError.
void writeOctree(const SizingOctree& octree, const std::string& path);

}  // namespace homesh
