// Linear (order 1) mesh of a CAD model, made by Gmsh in-process.
//
// A model with solids gets tetrahedra, with triangles on its faces and lines on its edges as the
// boundary blocks; a model made only of planar faces in one plane gets triangles (dim 2), with
// lines on its edges. Every node records the CAD entity it lies on and its parameters there
// (see core/mesh.hpp), taken from Gmsh's parametric coordinates, so the high-order stages can
// place new nodes on the CAD. Volume elements have positive Jacobian (2D ones: positive with
// respect to Mesh::planeNormal).
#pragma once

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

struct LinearMeshOptions {
  double size = 0.0;  // target edge length, uniform for now (> 0)
  int threads = 1;    // threads Gmsh may use
  int verbosity = 0;  // 0 silent, 1 Gmsh's warnings, 2 Gmsh's information
};

// Throws ParameterError (bad size), CadError (nothing meshable) or MeshingError.
Mesh generateLinearMesh(const CadModel& cad, const LinearMeshOptions& options);

}  // namespace homesh
