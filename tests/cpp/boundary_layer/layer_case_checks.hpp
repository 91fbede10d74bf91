// Checks the boundary-layer tests share (test_layer_cases_3d.cpp, test_layer_cases_2d.cpp and
// the unit tests beside them): the cases meshed the acceptance's way, and checks on a
// MeshResult with a layer (validity and columns, the first layer's height, the split's nodes on
// the CAD, the files read back, the optimiser's stop, the raise to order 6, the 2D fans).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <set>
#include <string>

#include "core/mesh.hpp"
#include "optimise/optimiser.hpp"
#include "pipeline/mesh_pipeline.hpp"

namespace homesh {

// The .mcf case at `path` (boundary layer included) at `order` with the optimiser (100 sweeps,
// 2 threads): the acceptance's path.
MeshResult meshCase(const std::string& path, int order);

// NekMesh's meshgen case `name`.mcf (peer files: call HOMESH_REQUIRE_PEER_FILES first).
MeshResult meshPeerCase(const std::string& name, int order);

// Node i's position.
inline Eigen::Vector3d point(const Mesh& m, std::int64_t i) {
  return {m.xyz[3 * i], m.xyz[3 * i + 1], m.xyz[3 * i + 2]};
}

// 3D: certified valid, nothing shrunk, and `layers` prisms in the column on every wall triangle
// of `walls` (prisms stacked bottom (0, 1, 2) to top (3, 4, 5)), every prism in one column.
void expectValidWithLayersInEveryWallColumn(const MeshResult& r, const std::set<int>& walls,
                                            int layers);

// 3D: the first layer's height along the wall's normal at the quadrature points (degree 2P) of
// the wall triangles on `walls`: the distance from the wall point to where its normal line meets
// the first prism's top, found by Newton on (a, b, t) together (the report projects onto the
// tangent plane instead). `visit(wall point, height)` for each point.
void forEachFirstLayerHeight(const MeshResult& r, const std::set<int>& walls,
                             const std::function<void(const Eigen::Vector3d&, double)>& visit);

// 3D: the split's new nodes were put on the CAD and the report says so (`input` names the case
// in the JSON report, `layers` the layers asked for). The split's side nodes lie on the curved
// macro quadrilaterals (on the planar side faces), but the first level's shift (onto the wall
// normal, layer_split.hpp) follows the curved wall's interpolated normal, which leans off the
// side plane by the wall's interpolation error; `maxProjection` bounds that move, relative to
// the layer's height. Then every node on a CAD face lies on it: to the precision of the
// projections that put it there (found to 1e-9 of the bounding diagonal, CadModel).
void expectSplitNodesOnTheCad(const MeshResult& r, const std::string& input, int layers,
                              double maxProjection);

// The mesh written as Nektar++ XML and as Gmsh .msh, read back: the same 3D elements by type, the
// same order, still certified valid.
void expectNektarAndGmshFilesReadBack(const MeshResult& r, const std::string& stem);

// The Nektar++ XML of a split 3D layer read back: the same elements, and every node the file
// stores (vertices, edge and face points: all but the interior of each 3D element, which
// Nektar++ rebuilds from the faces itself) bit for bit among the same element's nodes.
// Nektar++'s own reader refused such files until the writer numbered the layer's columns as
// runs (a prism's triangles need their apex vertices to carry their highest ids); NekMesh's
// jac module now reads them and finds no negative Jacobian (bench/boundary_layer with NEKMESH).
void expectNektarXmlStoresEveryNodeExactly(const MeshResult& r, const std::string& stem);

// The optimiser's stop rule: "stalled" also needs the worst element to have stopped rising
// within the window, the pipeline's stall of 1e-3 over 3 sweeps (pipelineOptimiserOptions in
// mesh_pipeline.cpp).
void expectStalledOnlyOnceTheWorstStoppedRising(const OptimiserResult& o);

// A case meshed at order 6 through the continuation (optimised at order 4, raised, optimised
// again): certified valid, the first layer's height within 5 % after the raise, and the
// optimiser's stop rule.
void expectRaisedToOrderSixKeepingTheFirstHeight(const MeshResult& r);

// 2D: `layers` quadrilaterals in the column on every wall line of `walls` (wall (0, 1), top
// (3, 2)), every quadrilateral in one column, and in `worst` the largest relative deviation of
// the first layer's height, the top's component along the wall's normal at the wall's quadrature
// points (degree 2P), from `firstHeight`.
void expectQuadrilateralColumnsOnEveryWallLine(const MeshResult& r, const std::set<int>& walls,
                                               int layers, double firstHeight, double& worst);

// 2D: the fan at the sharp convex corner at CAD vertex `vertex`: its first layer's triangles
// (a vertex at the corner), each at most 40 degrees wide (the fan's step, kFanStep in
// boundary_layer.cpp), and the first layers on either side (quadrilaterals with a wall vertex at
// the corner) with the largest relative deviation of their height along the wall normal (the
// top's component) from `firstHeight`.
struct CornerFan {
  std::size_t pieces = 0, sides = 0;
  double angle = 0.0;  // radians, summed over the pieces
  double worstSideHeight = 0.0;
};
void measureCornerFan(const MeshResult& r, int vertex, double firstHeight, CornerFan& fan);

}  // namespace homesh
