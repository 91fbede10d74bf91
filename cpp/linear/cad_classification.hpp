// A linear volume (or planar 2D) mesh made elsewhere (tetrahedra, prisms, pyramids and hexahedra
// from FreeCAD FEM's Gmsh or Netgen mesher, Gmsh, any tool whose boundary nodes lie on the CAD) put
// on the CAD, so that the rest of the pipeline can curve it as if the linear mesher had made it.
//
// Boundary faces (triangles and quadrilaterals) are the faces of exactly one cell. Each boundary
// node is classified on the lowest-dimensional CAD entity it lies on within the tolerance: a
// vertex, else an edge (with its parameter t), else a face (with (u, v), inside the face's
// trimming). A boundary face lies on the CAD face its nodes share (the one nearest its centroid
// when several do), a boundary segment on the CAD edge both its nodes lie on. Cells are made
// positive (the volume their faces enclose) and boundary faces point out of their cell, as the
// linear mesher leaves them; nodes no cell uses are dropped.
#pragma once

#include <vector>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

struct CadClassificationStats {
  std::size_t boundaryNodes = 0, onVertices = 0, onEdges = 0, onFaces = 0;
  std::size_t boundaryTriangles = 0, boundaryQuadrilaterals = 0, boundarySegments = 0;
  double maxDistance = 0.0;  // largest node-to-entity distance accepted
};

// `linear`: dim 3, order 1, with blocks of tetrahedra, prisms, pyramids or hexahedra (blocks of
// lower dimension are ignored; node records need not be set); the result has one block per
// non-empty volume block given, in the given order, then its boundary's triangles,
// quadrilaterals and segments. The CAD must have exactly one solid. `tolerance` <= 0: the parameter
// table's classify_tolerance (1e-5) of the CAD's bounding diagonal (above the CAD's own tolerances,
// below any element). Throws ParameterError for a mesh that is not such (and naming a flat cell),
// MeshingError naming two cells that overlap (both on one side of their shared face), and
// MeshingError naming the node, its position and the nearest CAD face when a boundary node lies on
// no CAD face.
//
// A planar 2D mesh (dim 2, triangles and quadrilaterals, in its plane) goes on a CAD of faces
// without solids: every node is classified (interior nodes on their face with (u, v)), cells
// are made counter-clockwise around the plane's normal and put on the face holding their
// centroid, and each boundary side becomes a line on the CAD edge its nodes share (MeshingError
// naming it when there is none), as does each inner side on a curve between two faces. A 2D mesh
// on curved faces is refused.
Mesh classifyOnCad(const Mesh& linear, const CadModel& cad, double tolerance = 0.0,
                   CadClassificationStats* stats = nullptr);

// The faces of a positive linear volume cell of `type` (tetrahedron, prism, pyramid, hexahedron)
// as local corners in Gmsh's order, pointing out. Throws ParameterError for another type.
const std::vector<std::vector<int>>& cellFaceCorners(CellType type);

}  // namespace homesh
