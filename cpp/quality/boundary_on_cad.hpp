// A curved mesh made elsewhere (Gmsh, NekMesh, an earlier HOMesh run, read from its file) put on
// the CAD model it was made from, so that its boundary's distance and normal angle to the CAD can
// be measured (geometry_accuracy.hpp) as for a mesh the pipeline made: `homesh quality --cad`.
//
// Each boundary cell (3D: the triangles, quadrilaterals and lines the file holds besides its
// volume cells; a surface mesh: its triangles and quadrilaterals and lines; a planar 2D mesh: its
// lines) is put on a CAD entity of its own dimension by its corners alone: every corner is
// classified on the lowest-dimensional CAD entity within the tolerance of it (every mesher puts
// the vertices of its boundary on the CAD; a curved cell's other nodes and its surface between
// them are what is measured), and the cell lies on the face (curve) its corners share, the one
// nearest its nodes' centroid when several do. The file's own entity tags (Gmsh's, NekMesh's
// composites) are not used: their numbering is not the CAD's.
//
// The result is the mesh with its boundary cells' entities set and its nodes' CAD records
// rewritten: corners where they were classified, the other nodes of a cell on its entity with
// their parameters (projected), nodes of no boundary cell unclassified. Positions are unchanged.
#pragma once

#include <cstddef>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

struct BoundaryOnCadStats {
  std::size_t faceCells = 0, curveCells = 0;  // cells put on faces, on curves
  double maxCornerDistance = 0.0;             // the largest corner-to-entity distance accepted
};

// `tolerance` <= 0: the parameter table's classify_tolerance of the CAD's bounding diagonal.
// Throws ParameterError when the mesh has no boundary cells (naming what it has), MeshingError
// naming the node, its position and the nearest CAD face when a corner lies on no CAD entity, and
// naming the cell (its block's type, its index and its corner nodes, 1-based) when its corners
// share no face (curve).
Mesh boundaryOnCad(const Mesh& mesh, const CadModel& cad, double tolerance = 0.0,
                   BoundaryOnCadStats* stats = nullptr);

}  // namespace homesh
