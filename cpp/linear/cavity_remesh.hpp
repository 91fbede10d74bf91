// Local remeshing of a linear tetrahedral mesh around cells that no split or flip mends.
//
// Remeshing the whole model with a finer size field around such cells (a refinement round)
// changes nearly every cell: on real models each such round brought back tens to hundreds of
// invalid elements far from the ones it was for. Here only a cavity changes: the cells that
// share a vertex with a requested cell (in its solid) are taken out, the cavity grown until its
// surface is a closed 2-manifold, and Gmsh fills that surface again (linear_mesher.hpp's
// fillTetrahedra: the surface, and so every boundary triangle on the CAD, stays as it is), with
// interior nodes of its own choosing, sized from the surface. Every other cell, and its curved
// nodes in the next round (curved_reuse.hpp), stays.
//
// (Asking for smaller cells does not pay: Gmsh 4.8's Delaunay fill of a discrete volume ignores
// its maximum size, and with points of our own inside, half the offenders' mean edge apart,
// MSOP_10.stp's cavities went from 17 to 25 invalid elements and MODERN_Cooker_1.brep's from 5
// to 13, where the plain fill took the Cooker's 6 to 1. HXT, which does refine, crashed on a
// cavity.)
#pragma once

#include <cstddef>
#include <vector>

#include "core/mesh.hpp"
#include "linear/linear_mesher.hpp"

namespace homesh {

struct CavityOutcome {
  std::size_t cavities = 0;      // connected cavities filled again
  std::size_t cellsRemoved = 0;  // cells taken out
  std::size_t cellsAdded = 0;    // cells Gmsh filled them with
};

// Remeshes the cavities around `cells` (indices among the mesh's tetrahedra, in element order).
// Gmsh runs under `options` (its time limit, isolation, verbosity; the sizes there are ignored).
// Cells that stay keep their order, new cells follow them; nodes of removed cells that no cell
// uses any more stay in the mesh, unused. Throws ParameterError when the mesh is not a linear
// tetrahedral mesh with its tetrahedra in one block or an index is out of range, and
// MeshingError when a cavity's surface cannot be made a closed 2-manifold, Gmsh
// cannot fill it, or the fill does not have the cavity's volume (the mesh is then unchanged).
CavityOutcome remeshCavities(Mesh& mesh, const std::vector<std::size_t>& cells,
                             const LinearMeshOptions& options);

}  // namespace homesh
