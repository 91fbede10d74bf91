// The interior nodes of a curved boundary triangle moved on its CAD face so that the triangle's
// polynomial surface follows the face between its nodes: the surface placed for its own
// fidelity (issue 49; the boundary_fit stage, pipeline/boundary_fidelity.hpp, applies it once the
// volume is optimised, and says why then).
//
// Why: nodes on the CAD only say where the surface passes; between them the polynomial follows
// it as closely as the nodes sample one smooth map of the reference triangle. The relaxed
// lattice (face_node_placement.hpp) spreads them evenly, but as the minimum of a discrete spring
// energy, not as samples of such a map. On the unit sphere of examples/sphere_box.step (size 0.8,
// triangles spanning 45 to 90 degrees) its order-5 triangles left the sphere's normal by up to
// 0.22 degrees, where samples of the geodesic barycentric map (the weighted Riemannian centre of
// the corners) leave it by 0.027 (by 0.93 against 0.19 at order 4, 0.029 against 0.003 at
// order 6), with the same edge nodes. That map needs geodesics; the fit gets its result on any
// face by minimising what it buys. With the edge nodes held, the interior nodes minimise, over a
// quadrature rule of degree 2P on the triangle,
//   F = sum_q w_q ( |n_h x n_c|^2 + ((x_h - p) . n_c / h)^2 ),
// x_h and n_h the triangle's point and unit normal, p the point's foot on the face and n_c the
// face's normal there, h the triangle's size (sqrt of its corners' area): the squared sine of the
// angle between the normals and the distance off the tangent plane, the quantities the report's
// geometry measures (quality/geometry_accuracy.hpp). Each step is a Gauss-Newton step in the
// nodes' (u, v) with the feet held (a lagged model, as the optimiser's fidelity term,
// optimise/facet_energy.hpp), kept only where F, with the feet found again, falls; on the
// sphere the fit reaches the geodesic map's figures above.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

#include "core/mesh.hpp"
#include "curving/face_node_placement.hpp"

namespace homesh {

struct TriangleFit {
  std::vector<FaceParameter> uv;  // lattice-indexed (latticeIndex); only the interior changed
  double before = 0.0;            // F at the start and at the end (after <= before)
  double after = 0.0;
  int steps = 0;  // Gauss-Newton steps kept
  // The largest squared sine of the angle between the normals at the points, at the start and
  // at the end.
  double largestBefore = 0.0;
  double largestAfter = 0.0;
};

// The fit of an order-P triangle's interior nodes on `chart`'s face. `uv` holds every lattice
// node's parameters unwrapped into one chart (corners may be poles: their (u, v) is not used) and
// `x` the positions of the boundary nodes (corners and edges). Interior nodes start at their
// entries of `uv`. Orders below 3 have no interior node: returned as given. Points where the
// face's normal is undefined (a pole) are left out of F; a point the face cannot be followed to
// ends the fit with what it has. The result is not checked against the face's trimming or for
// folds: BoundaryFitter checks the trimming, the boundary_fit stage the elements.
TriangleFit fitTriangleInterior(const FaceChart& chart, int order,
                                const std::vector<FaceParameter>& uv,
                                const std::vector<Eigen::Vector3d>& x);

// The fit applied to the boundary triangles of a curved 3D mesh whose interior nodes lie on one
// curved CAD face (nodeCadDim 2; a plane's are left out, they lie in it), corners and nodes on CAD
// curves as they are: rounds over the edges inside a face (the edge's nodes with both triangles'
// interiors) and the triangles' interiors, positions and (u, v) updated in place, each patch only
// where the fit lowers its F by 1 % and keeps every node inside the face's trimming.
class BoundaryFitter {
 public:
  BoundaryFitter(Mesh& mesh, const CadModel& cad);  // holds both; orders below 2: no triangle
  ~BoundaryFitter();
  BoundaryFitter(const BoundaryFitter&) = delete;
  BoundaryFitter& operator=(const BoundaryFitter&) = delete;

  std::size_t triangles() const;
  // Per triangle (those set in `which`, if given; 0 for the others): the largest squared sine of
  // the angle between its normal and the face's at its quadrature points; infinity where it
  // cannot be measured (a node off its face's chart, a degenerate triangle).
  std::vector<double> largestSines(const std::vector<char>* which = nullptr);
  // Per triangle: whether one of its nodes is set in `nodes` (per node).
  std::vector<char> touching(const std::vector<char>& nodes) const;
  // Fits the patches of the triangles set in `active` (per triangle); nodes set in `frozen` (per
  // node, if given) stay.
  void fit(const std::vector<char>& active, const std::vector<char>* frozen = nullptr);

  // The vertices inside a face whose star of triangles (those with a corner there) is closed on
  // it, and a vertex's star (empty for another node).
  std::vector<std::int64_t> starVertices() const;
  std::vector<std::size_t> starOf(std::int64_t vertex) const;
  // Fits the patch of each of `vertices` (of starVertices; no two in one triangle), in turn: the
  // vertex, the nodes of the sides at it and its triangles' interiors move, those set in `frozen`
  // excepted (a frozen vertex: no patch), kept where F falls by 1 %, the patch's largest angle
  // does not rise, neither at the fit's points nor at the report's (a rule of degree 2P + 2 and
  // the nodes), and every node stays inside the face's trimming. The volume's nodes of the
  // tetrahedra around a kept vertex follow it by their barycentric share of it (a node two kept
  // vertices share stays). Returns per vertex the nodes written, dragged ones included (empty
  // where the patch was not kept).
  std::vector<std::vector<std::int64_t>> fitVertices(const std::vector<std::int64_t>& vertices,
                                                     const std::vector<char>* frozen = nullptr);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace homesh
