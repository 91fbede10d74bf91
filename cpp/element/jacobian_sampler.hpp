// The Jacobian of a curved element at chosen reference points.
//
// J(xi) = det(dx/dxi) for volume cells; for 2D cells in a plane with normal n,
// J = (dx/dxi x dx/deta) . n (signed), and without a normal the area element
// |dx/dxi x dx/deta| (or the length element |dx/dxi| of a line).
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "element/reference_element.hpp"

namespace homesh {

using NodeCoordinates = Eigen::Matrix<double, Eigen::Dynamic, 3>;  // numNodes x 3

class JacobianSampler {
 public:
  // Points: one reference point per row (dim columns).
  JacobianSampler(const ReferenceElement& ref, const Eigen::MatrixXd& points);

  int numPoints() const { return static_cast<int>(dxi_[0].rows()); }
  int dim() const { return static_cast<int>(dxi_.size()); }

  // J at every point for an element whose node coordinates are the rows of x.
  void jacobians(const NodeCoordinates& x, const Eigen::Vector3d* normal,
                 Eigen::VectorXd& out) const;

  // dx/dxi_k at every point (points x 3), for k < dim: one matrix product per direction.
  void derivatives(const NodeCoordinates& x, std::array<NodeCoordinates, 3>& out) const;

 private:
  std::vector<Eigen::MatrixXd> dxi_;  // per reference direction: points x nodes
};

// J from the columns of dx/dxi (a, b, c as available), as described above.
double jacobianDeterminant(const Eigen::Matrix<double, 3, Eigen::Dynamic>& columns,
                           const Eigen::Vector3d* normal);

}  // namespace homesh
