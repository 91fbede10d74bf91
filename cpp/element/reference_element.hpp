// Reference Lagrange elements: node positions and the nodal basis with its derivatives.
//
// Nodes are in Gmsh's order (element/node_ordering.hpp) on the unit reference shape, placed by
// a node set (element/node_sets.hpp). The nodal basis is l(xi)^T = psi(xi)^T V^{-1} with psi
// the orthogonal basis of the shape (element/orthogonal_basis.hpp) and V_ij = psi_j(node_i),
// which stays well conditioned at high order.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/cell_type.hpp"
#include "element/node_ordering.hpp"
#include "element/node_sets.hpp"

namespace homesh {

inline constexpr int kMaxOrder = 10;

class ReferenceElement {
 public:
  // The shared, immutable element for a shape, order and node set (built on first use;
  // thread-safe). Throws ParameterError for shapes or orders the library does not provide.
  static const ReferenceElement& get(CellType type, int order, NodeSet set = NodeSet::Equispaced);

  ReferenceElement(CellType type, int order, NodeSet set);

  CellType type() const { return type_; }
  int order() const { return order_; }
  NodeSet nodeSet() const { return set_; }
  int dim() const { return dim_; }
  int numNodes() const { return static_cast<int>(lattice_.size()); }

  // Lattice point of each node (Gmsh order).
  const std::vector<LatticePoint>& lattice() const { return lattice_; }
  // Reference coordinates, numNodes() x dim().
  const Eigen::MatrixXd& nodes() const { return nodes_; }

  // Lagrange basis at reference point xi (dim() coordinates): values (numNodes()) and
  // gradients (numNodes() x dim()).
  void evaluate(const double* xi, Eigen::VectorXd& values, Eigen::MatrixXd& gradients) const;

  // Values of the basis at many points (rows of `points`): (points x numNodes()).
  Eigen::MatrixXd valuesAt(const Eigen::MatrixXd& points) const;
  // Derivatives of the basis at many points (rows of `points`): one (points x numNodes())
  // matrix per reference direction, d/dxi_k in entry k (dim() entries). The tables the
  // optimiser, its facet term and the quality samplers lay out in their own orders.
  std::vector<Eigen::MatrixXd> derivativesAt(const Eigen::MatrixXd& points) const;

  // A field given at the nodes (numNodes() x k, a row per node) as its coefficients in the
  // orthogonal basis, V^{-1} nodal: interpolate then evaluates it at a point in O(numNodes() k),
  // where the nodal basis costs O(numNodes()^2) a point (a dense product with V^{-1}).
  Eigen::MatrixXd modalCoefficients(const Eigen::MatrixXd& nodal) const;
  // The field with coefficients `modal` (modalCoefficients) at reference point xi: k values,
  // and, where `derivatives` is given, their derivatives there (dim() x k, d/dxi_j in row j).
  Eigen::RowVectorXd interpolate(const Eigen::MatrixXd& modal, const double* xi,
                                 Eigen::MatrixXd* derivatives = nullptr) const;

  // Lebesgue constant max_xi sum_n |l_n(xi)|, estimated on a lattice of `samples` points per
  // edge (a measure of how well the node set interpolates; 1 is ideal).
  double lebesgueConstant(int samples) const;

 private:
  CellType type_;
  int order_;
  NodeSet set_;
  int dim_;
  std::vector<LatticePoint> lattice_;
  Eigen::MatrixXd nodes_;
  Eigen::MatrixXd inverseVandermonde_;
};

// Lattice points of a shape at a sampling resolution (reference coordinates = point / n), used
// to sample elements uniformly.
std::vector<LatticePoint> samplingLattice(CellType type, int n);

}  // namespace homesh
