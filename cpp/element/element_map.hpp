// One element's geometric map x(xi) from its reference element to space, for evaluating it at
// many points: built once from the element's nodes (in the orthogonal basis, O(nodes^2)), it
// gives the position and its derivatives at a point in O(nodes), where the nodal basis costs
// O(nodes^2) a point (196 nodes for an order-6 prism). The map is the element's as it was
// when built: later moves of its nodes are not seen.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "element/reference_element.hpp"

namespace homesh {

class ElementMap {
 public:
  // The map of the element whose nodes (ref.numNodes() of them, Gmsh order) are `nodes`, each
  // the index of a point (x, y, z) in `xyz`.
  ElementMap(const ReferenceElement& ref, const double* xyz, const std::int64_t* nodes);

  const ReferenceElement& reference() const { return *ref_; }
  // x(xi).
  Eigen::Vector3d position(const double* xi) const;
  // x(xi) and its derivatives: column j of `derivatives` is dx/dxi_j (ref.dim() columns, the
  // rest zero).
  Eigen::Vector3d position(const double* xi, Eigen::Matrix3d& derivatives) const;

 private:
  const ReferenceElement* ref_;
  Eigen::MatrixXd modal_;  // numNodes x 3: the coordinates' coefficients in the orthogonal basis
};

}  // namespace homesh
