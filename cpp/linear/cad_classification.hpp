// A linear tetrahedral mesh made elsewhere (FreeCAD FEM's Gmsh or Netgen mesher, any tool whose
// boundary nodes lie on the CAD) put on the CAD, so that the rest of the pipeline can curve it
// as if the linear mesher had made it.
//
// Boundary triangles are the faces of exactly one tetrahedron. Each boundary node is classified
// on the lowest-dimensional CAD entity it lies on within the tolerance: a vertex, else an edge
// (with its parameter t), else a face (with (u, v), inside the face's trimming). A boundary
// triangle lies on the CAD face its nodes share (the one nearest its centroid when several do),
// a boundary segment on the CAD edge both its nodes lie on. Tetrahedra are made positive and
// boundary triangles point out of their tetrahedron, as the linear mesher leaves them; nodes no
// tetrahedron uses are dropped.
#pragma once

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

struct CadClassificationStats {
  std::size_t boundaryNodes = 0, onVertices = 0, onEdges = 0, onFaces = 0;
  std::size_t boundaryTriangles = 0, boundarySegments = 0;
  double maxDistance = 0.0;  // largest node-to-entity distance accepted
};

// `linear`: dim 3, order 1, one tetrahedron block (other blocks are ignored; node records need
// not be set). The CAD must have exactly one solid. `tolerance` <= 0: the parameter table's
// classify_tolerance (1e-5) of the CAD's bounding
// diagonal (above the CAD's own tolerances, below any element). Throws ParameterError for a mesh
// that is not such, and MeshingError naming the node, its position and the nearest CAD face when
// a boundary node lies on no CAD face.
Mesh classifyOnCad(const Mesh& linear, const CadModel& cad, double tolerance = 0.0,
                   CadClassificationStats* stats = nullptr);

}  // namespace homesh
