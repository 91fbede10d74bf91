// Repair of the elements that curving left not proven valid: where they come from in the linear
// mesh, and what to change there.
//
// The classic offender is a linear cell with an interior edge whose two ends lie on one curved
// CAD face (in 2D: curve), for example a tetrahedron with two faces on a sphere: curving moves
// the boundary around the edge but not the edge, and no placement of interior nodes can make
// the element valid. Splitting that edge (a new interior node, every cell around the edge
// halved) removes the configuration. A cell without such an edge is refined instead: a
// refinement sphere around it asks the linear mesher for smaller elements there.
//
// The curved mesh's elements come from the linear cells with the same index (elevation keeps
// the cell order), so a verdict per curved element points at its linear cell.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "cad/face_cusps.hpp"
#include "core/mesh.hpp"
#include "linear/edge_split.hpp"
#include "linear/linear_mesher.hpp"
#include "quality/bezier_jacobian.hpp"
#include "quality/mesh_quality.hpp"
#include "sizing/refinement_source.hpp"

namespace homesh {

// One repair round, as the report records it.
struct RepairRound {
  std::size_t invalid = 0, undecided = 0;  // elements not proven valid that the round found
  double worst = 0.0, worstAfter = 0.0;    // certified scaled Jacobian before and after
  // "split", "flip", "remesh" (cavities around the flagged cells filled again), "refine" (the
  // whole model meshed again, finer around them), or "split poor", "flip poor", "remesh poor"
  // (every element was valid; the round split, flipped or remeshed around the cells of those
  // below the pipeline's poor-element threshold)
  std::string action;
  std::size_t elements = 0;                          // linear cells it acted on
  std::size_t edgesSplit = 0;                        // edges bisected ("split")
  std::size_t flips = 0;                             // flips made ("flip")
  std::size_t sources = 0;                           // refinement spheres added ("refine")
  std::size_t cavities = 0;                          // cavities filled again ("remesh")
  std::size_t invalidAfter = 0, undecidedAfter = 0;  // of the mesh the round made
  std::size_t meshElements = 0;                      // elements of the mesh the round made
  std::size_t reused = 0;  // of those, elements whose curved nodes came from the round before
  bool kept = false;       // the round's mesh is no worse than the best before it and was kept
  double seconds = 0.0;
  // The round's optimiser run (the last one, at the final order): its region, sweeps, why it
  // stopped and its time; where a round's seconds go.
  std::size_t optimiserRegion = 0;
  int optimiserSweeps = 0;
  std::string optimiserStopped;
  double optimiserSeconds = 0.0;
  std::string failure;  // why the round's mesh could not be made (the rounds then stop)
  // The job's time budget stopped a stage of the round early or left it out (its Gmsh run,
  // then `failure` says so, or its optimiser run).
  bool budgetStopped = false;
};

struct CurvedFaceEdge {
  MeshEdge edge;
  // The curved CAD face (curve in 2D) both ends lie on; 0 for a chord between boundary nodes
  // of different entities (CurvedFaceEdges::longestBoundaryChord).
  int entity = 0;
  bool boundary = false;  // the edge lies on that face (else it is an interior chord)
};

// The edges of linear cells whose two ends lie on one curved CAD face (3D: a face that is not
// planar; 2D: any curve), found from the boundary cells: a node lies on a CAD face when a
// boundary triangle of that face (line, in 2D) has it.
class CurvedFaceEdges {
 public:
  CurvedFaceEdges(const Mesh& linear, const CadModel& cad);
  // The interior edges (on no boundary cell) of cell `cell` (index among the cells of dimension
  // mesh.dim) with both ends on one curved face: chords that curving cannot follow.
  std::vector<CurvedFaceEdge> interior(std::size_t cell) const;
  // The longest edge of cell `cell` that lies on a curved face (3D: an edge of that face's
  // boundary triangles and of no CAD curve; 2D: a boundary line), if any: where curving moves
  // the cell's boundary most.
  std::optional<CurvedFaceEdge> longestOnFace(std::size_t cell) const;
  // When every vertex of cell `cell` lies on the boundary (on any CAD face, curve or vertex),
  // its longest interior edge (on no boundary cell), if it has one (entity 0). Such a cell has
  // no node the optimiser can move off the CAD: its Jacobian at a vertex is fixed by the curved
  // boundary edges there, which only slide on the CAD. A cell with two faces on the boundary
  // (an ear over a boundary edge whose faces are nearly flat against each other, across a CAD
  // curve or on one face) has exactly one interior edge; splitting it gives the cell an
  // interior vertex.
  std::optional<CurvedFaceEdge> longestBoundaryChord(std::size_t cell) const;

 private:
  const Mesh& mesh_;
  std::vector<std::vector<int>> nodeFaces_;  // curved CAD faces per node, sorted
  std::vector<char> onBoundary_;             // per node: a vertex of a boundary cell
  std::set<MeshEdge> boundary_;
  std::map<MeshEdge, int> faceEdges_;  // edges on a curved face (not on a CAD curve in 3D)
  std::vector<const std::int64_t*> cells_;
};

// What a round does on the linear mesh.
struct RepairPlan {
  std::vector<CurvedFaceEdge> splits;        // distinct edges to bisect
  std::vector<RefinementSource> sources;     // spheres around the flagged cells without such edges
  std::vector<RefinementSource> allSources;  // spheres around every flagged cell
  std::size_t splitCells = 0, refineCells = 0;
  std::vector<std::size_t> unsplit;  // the flagged cells without an edge to split (`sources`)
  std::vector<std::size_t> flagged;  // every flagged cell
};

// Locates the elements whose verdict is not Valid (`validity` per element of the curved mesh,
// in element order) in `linear`. A flagged cell with interior edges on one curved face gets
// those split; else, when `optimised` (the optimiser runs on the new mesh: the new node at the
// edge's midpoint helps only once something moves it) and in 3D, a tetrahedron whose vertices
// all lie on the boundary gets its longest interior edge split (longestBoundaryChord); else one
// with an edge on a curved face gets its longest such edge split (the face's triangles there
// are halved, which halves the sagitta curving has to follow); else it gets a sphere of radius
// its longest edge, centred at its centroid, of size half its mean edge length. A mesh with
// other cells than simplices (a boundary layer's prisms) gets spheres only. Throws
// ParameterError when `validity` does not match the linear mesh's cell count.
RepairPlan planRepair(const Mesh& linear, const std::vector<Validity>& validity,
                      const CadModel& cad, bool optimised);

// Tangent ears of a linear simplex mesh: cells with two boundary facets (3D: triangles, 2D:
// lines) on one curved CAD face (2D: curve). Curving puts both facets on that face, so at each
// end of the edge they share (2D: at the vertex) every edge of the cell is tangent to the face
// and the Jacobian vanishes there, whatever the interior nodes do: such a cell is never proven
// valid (on OpenCASCADE's Motor-c, 80 of the 94 elements left invalid after the optimiser). The
// edge joining the two facets' far vertices, to split before curving (applySplits: a new
// interior vertex, its node off the face); none where that edge is on the boundary itself.
std::vector<CurvedFaceEdge> tangentEarSplits(const Mesh& linear, const CadModel& cad);

// The elements not proven valid that have a corner at a cusp of the CAD (cad/face_cusps.hpp: a
// node at the cusp's vertex, and nodes on both its edges or on one of them and on its face): their
// Jacobian is zero at that vertex whatever the mesh, so no repair round mends them. `perCusp[c]`:
// how many touch cusps[c].
struct CuspElements {
  std::vector<std::size_t> elements;  // indices among the cells of dimension mesh.dim
  std::vector<std::size_t> perCusp;
};
CuspElements elementsAtCusps(const Mesh& mesh, const QualitySummary& quality,
                             const std::vector<FaceCusp>& cusps);

// Splits the plan's edges in turn (linear/edge_split.hpp) and returns how many it split. A
// chord between different entities (entity 0) is split at its midpoint. An interior edge's new
// node goes at its midpoint when that lies on the solid's side of the curved face (the side of the
// cells around the edge, from the signed distances of their other vertices to the face); where the
// chord crosses to the other side (a tetrahedron outside a convex face), it goes to the mirror
// image of the midpoint in the face, and back to the midpoint if that would make a cell of
// non-positive volume. A boundary edge's new node is the midpoint projected onto its face (curve),
// with its parameters; such an edge is skipped when that would make a cell of non-positive volume.
std::size_t applySplits(Mesh& linear, const std::vector<CurvedFaceEdge>& splits,
                        const CadModel& cad);

// The linear mesh's node coordinates with every cell's vertices where the curved mesh made from
// it (elements in the same order, as elevation keeps them) has them: where the optimiser moved
// them. Throws ParameterError when the two meshes do not have the same elements.
std::vector<double> curvedVertexPositions(const Mesh& linear, const Mesh& curved);

// `base` capped by the refinement spheres, each growing by `growth` per unit distance outside
// its sphere (size(x) = min(base(x), min over sources (delta + growth * distance))).
inline constexpr double kRepairSizeGrowth = 1.0;
SizeField cappedSizeField(SizeField base, std::vector<RefinementSource> sources,
                          double growth = kRepairSizeGrowth);

}  // namespace homesh
