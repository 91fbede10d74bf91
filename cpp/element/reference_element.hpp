// Reference Lagrange elements: node positions and the nodal basis with its derivatives.
//
// Nodes are in Gmsh's order (element/node_ordering.hpp) on the unit reference simplex. The
// nodal basis is l(xi)^T = psi(xi)^T V^{-1} with psi the orthogonal simplex basis and
// V_ij = psi_j(node_i), which stays well conditioned at high order. Node sets are equispaced for
// now; the lattice indices let a better-conditioned symmetric set replace them without changing
// connectivity.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/cell_type.hpp"
#include "element/node_ordering.hpp"

namespace homesh {

class ReferenceElement {
 public:
  // The shared, immutable element for a shape and order (built on first use; thread-safe).
  // Throws ParameterError for shapes or orders the library does not provide.
  static const ReferenceElement& get(CellType type, int order);

  ReferenceElement(CellType type, int order);

  CellType type() const { return type_; }
  int order() const { return order_; }
  int dim() const { return dim_; }
  int numNodes() const { return static_cast<int>(lattice_.size()); }

  // Integer barycentric index of each node (Gmsh order).
  const std::vector<Lattice>& lattice() const { return lattice_; }
  // Reference coordinates, numNodes() x dim().
  const Eigen::MatrixXd& nodes() const { return nodes_; }

  // Lagrange basis at reference point xi (dim() coordinates): values (numNodes()) and
  // gradients (numNodes() x dim()).
  void evaluate(const double* xi, Eigen::VectorXd& values, Eigen::MatrixXd& gradients) const;

 private:
  CellType type_;
  int order_;
  int dim_;
  std::vector<Lattice> lattice_;
  Eigen::MatrixXd nodes_;
  Eigen::MatrixXd inverseVandermonde_;
};

}  // namespace homesh
