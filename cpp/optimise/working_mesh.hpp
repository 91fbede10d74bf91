// The optimiser's working copy of a mesh (optimiser.hpp): the node coordinates in its frame (of
// the well-conditioned node set where it converts), and per block of elements of the mesh's
// dimension the energy's sample points, the basis gradients at them and, per element, the ideal
// (straight-sided) inverse Jacobian, the weights and the cached deformation gradient F and
// J = det F; the node-to-element incidence and each node's element size. Every other part of
// the optimiser reads this; the node steps (node_step.hpp) update F, J and the coordinates.
//
// Where the mesh was renumbered for locality (SpatialOrder), the choices made in sequence follow
// the caller's numbers: a node's elements are listed (and its patch summed) in the caller's
// element order, and a node shared by elements takes its working position from the caller's last
// one. So the renumbering changes where data lies, never a result, to the last bit.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/mesh.hpp"
#include "core/spatial_order.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"

namespace homesh::optimiser {

template <int D>
class NodeColouring;

// The optimiser moves the nodes of this set, converting from and to the mesh's equispaced nodes
// (the same polynomial map either way). Nodal Gauss-Seidel converges faster through the
// well-conditioned set (GLL, warp & blend): 0.716 against 0.693 worst scaled Jacobian after five
// sweeps on NekMesh's cube-sphere at order 4.
constexpr NodeSet kWorkingSet = NodeSet::Optimal;

// The energy's quadrature: exact to degree 2P - 1 (per variable on boxes), enough for the
// polynomial part of W on a straight-sided ideal element. (Higher degrees changed the worst
// value after five sweeps by less than 0.004; degree P + 1 halves the time but lost 0.18 of it
// on NekMesh's cube-sphere and left the sphere in a box tangled.)
//
// The energy also samples W at the element's own (equispaced) nodes, together weighted
// kNodeShare of the element's measure. A curved element's J is often lowest at its vertices and
// edges, where no interior quadrature point is: without these samples, sweeps at order 6 made
// the worst element of Gmsh's sphere in a box (MeshSizeMax 0.5, 2 907 tetrahedra) worse while
// the energy fell (0.436 -> 0.307 after two sweeps, 0.418 after five without focused passes,
// 0.542 with them) and left one element tangled at its nodes on the order-4 sphere in a box
// re-interpolated at order 6 (-0.437 after 20 sweeps); with them, 0.704 after five sweeps
// (NekMesh's varopti: 0.654) and the re-interpolated mesh valid (0.531). A larger share (0.03,
// 0.1: 0.800, 0.863) helps those meshes more but, with boundary nodes sliding on the CAD, left
// more coarse sphere-in-box meshes invalid after the repair rounds (2 and 3 of 9 test cases
// against 1).
constexpr double kNodeShare = 0.01;

// Which samples the energy takes. Both rules are exact to degree 2P - 1; W is not a
// polynomial, and the larger set's extra points see more of a fold:
// - Collapsed: the collapsed Gauss-Jacobi product (quadrature.hpp), n^3 points on a
//   tetrahedron, and every node of the element;
// - Symmetric: on tetrahedra of orders 3 and 4, the fully symmetric rule of that degree
//   (symmetric_quadrature.hpp: 14 and 35 points against 27 and 64) and the vertices and edge
//   nodes only (16 and 22 of 20 and 35); the collapsed set elsewhere.
// The optimiser takes Symmetric for an input certified valid, whose kept sweep is never worse
// than the input; an input with elements not proven valid keeps Collapsed (optimiser.cpp says
// what the smaller set lost there).
enum class EnergyRule { Collapsed, Symmetric };

// The energy's sample points of a cell type and order by `choice`: the quadrature rule of
// degree 2P - 1 and the element's equispaced nodes (or some, above), weighted kNodeShare of the
// measure together.
QuadratureRule energySamples(CellType type, int order, const ReferenceElement& equispaced,
                             EnergyRule choice = EnergyRule::Collapsed);

// Whether EnergyRule::Symmetric changes the samples of (type, order) (tetrahedra of orders 3
// and 4).
bool takesSymmetricSamples(CellType type, int order);

template <int D>
struct Block {
  using Mat = Eigen::Matrix<double, D, D>;
  using Vec = Eigen::Matrix<double, D, 1>;
  const ElementBlock* cells = nullptr;
  int nodes = 0, points = 0;
  bool affine = true;             // the ideal element's Jacobian is constant (simplices)
  std::vector<double> gradients;  // reference basis gradients, [node][direction][point]
  Eigen::MatrixXd gradientTable;  // the same as one matrix: [node][point x D + direction]
  std::vector<Mat> idealInvT;     // (dx_I/dxi)^-T per element (affine) or per element x point
  std::vector<double> weights;    // quadrature weight x |det dx_I/dxi|, per element x point
  // The deformation gradient, [element][component][point] (component k is F(k % D, k / D)): a
  // node's patch reads and updates an element's points one contiguous run per component.
  std::vector<double> F;
  std::vector<double> J;         // det F, per element x point (updated with F)
  Eigen::MatrixXd toWorking;     // equispaced node values -> working node values
  Eigen::MatrixXd toEquispaced;  // and back

  const Mat& invT(std::size_t e, int q) const {
    return idealInvT[affine ? e : e * points + static_cast<std::size_t>(q)];
  }
  double* componentF(std::size_t e, int k) {
    return &F[(e * D * D + static_cast<std::size_t>(k)) * static_cast<std::size_t>(points)];
  }
  const double* componentF(std::size_t e, int k) const {
    return &F[(e * D * D + static_cast<std::size_t>(k)) * static_cast<std::size_t>(points)];
  }
  Mat matrixF(std::size_t e, int q) const {
    Mat m;
    for (int k = 0; k < D * D; ++k) m(k % D, k / D) = componentF(e, k)[q];
    return m;
  }
  const double* gradient(int node, int direction) const {
    return &gradients[(static_cast<std::size_t>(node) * D + static_cast<std::size_t>(direction)) *
                      static_cast<std::size_t>(points)];
  }
};

// One element of a node: its block, the node's place in it and the element's index in the block.
struct Incidence {
  int block = 0;
  int local = 0;
  std::size_t element = 0;
};

template <int D>
class WorkingMesh {
 public:
  using Mat = Eigen::Matrix<double, D, D>;
  using Vec = Eigen::Matrix<double, D, 1>;

  // `converting`: move the working node set's nodes (kWorkingSet) rather than the mesh's own
  // (never where the mesh holds pyramids, which have no such set).
  // `order`: the renumbering `mesh` has been given (applied); null: the mesh's own numbers.
  WorkingMesh(Mesh& mesh, bool converting, const SpatialOrder* order = nullptr);

  // The frame, the blocks (without their samples), the working positions and the incidence,
  // in that order. Throws ParameterError for a mesh without elements of dimension D.
  void build();

  // After build(): each block's energy samples by `choice` (energySamples), their basis
  // gradients, the ideal elements, the weights, room for F and J, and the node sizes. Throws
  // ParameterError for a straight-sided element of zero volume (named by the caller's number).
  void buildSamples(EnergyRule choice);

  // F and J at every quadrature point of the given elements (global indices): one matrix
  // product per element (its node coordinates times the tabulated basis gradients), each on its
  // owner's thread (`owners`).
  void computeGradients(const std::vector<std::size_t>& elements, const NodeColouring<D>& owners);

  // The node's equispaced position into mesh.xyz (in 2D only its in-plane part moves): with
  // CAD exactly its point; converting, through its first element's map.
  void writeBack(std::int64_t node);

  std::size_t globalIndex(const Incidence& inc) const {
    return blockOffset[inc.block] + inc.element;
  }
  // The block and the element within it of global element g.
  std::pair<std::size_t, std::size_t> locate(std::size_t g) const {
    const auto bi = static_cast<std::size_t>(
        std::upper_bound(blockOffset.begin(), blockOffset.end(), g) - blockOffset.begin() - 1);
    return {bi, g - blockOffset[bi]};
  }
  // The caller's number of element `g` (global index), for messages.
  std::size_t callersElement(std::size_t g) const {
    return elementRank != nullptr ? (*elementRank)[g] : g;
  }
  // f(block index, element in the block) for every element, in the caller's order.
  template <class F>
  void forEachElementInCallersOrder(F f) const {
    if (callersElements != nullptr) {
      for (const std::size_t g : *callersElements) {
        const auto [bi, e] = locate(g);
        f(bi, e);
      }
      return;
    }
    for (std::size_t bi = 0; bi < blocks.size(); ++bi)
      for (std::size_t e = 0; e < blocks[bi].cells->count(); ++e) f(bi, e);
  }

  Mesh& mesh;
  // Without CAD the optimiser moves the nodes of the well-conditioned set (kWorkingSet), but
  // for a mesh with pyramids (which have none). With
  // CAD it moves the mesh's own (equispaced) nodes, the ones that lie on the CAD, and so it does
  // with a region, where a fixed node of an element at the region's edge would otherwise change
  // its equispaced position with its free neighbours' working nodes.
  const bool converting;
  // elementRank: the caller's number of each element (global index). callersNodes,
  // callersElements: the node (element) with the caller's number i, walked in order for the
  // caller's order without a sort. Null without a renumbering.
  const std::vector<std::size_t>* const elementRank;
  const std::vector<std::int64_t>* const callersNodes;
  const std::vector<std::size_t>* const callersElements;

  Eigen::Matrix<double, D, 3> frame;  // rows: the coordinate axes (in 2D, of the plane)
  std::vector<Vec> position;          // node coordinates in the frame, of the working node set
  std::vector<Vec> start;             // equispaced node coordinates last written to mesh.xyz
  std::vector<Block<D>> blocks;
  std::vector<std::size_t> blockOffset;  // first global element index of each block
  std::size_t totalElements = 0;
  // Node n's elements: incidence[incidenceStart[n] .. incidenceStart[n + 1]), in the caller's
  // element order.
  std::vector<std::size_t> incidenceStart;
  std::vector<Incidence> incidence;
  std::vector<double> nodeSize;  // size of each node's smallest element (volume^(1/D))
  // Symmetric where buildSamples took it on some block (tetrahedra of orders 3 and 4).
  EnergyRule energyRule = EnergyRule::Collapsed;

 private:
  void setFrame();
  void buildBlocks();
  void convertToWorkingSet();
  void buildIncidence();
  void buildNodeSizes();
};

extern template class WorkingMesh<2>;
extern template class WorkingMesh<3>;

}  // namespace homesh::optimiser
