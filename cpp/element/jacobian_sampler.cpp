#include "element/jacobian_sampler.hpp"

#include <Eigen/Geometry>

namespace homesh {

JacobianSampler::JacobianSampler(const ReferenceElement& ref, const Eigen::MatrixXd& points)
    : dxi_(ref.derivativesAt(points)) {}

void JacobianSampler::jacobians(const NodeCoordinates& x, const Eigen::Vector3d* normal,
                                Eigen::VectorXd& out) const {
  const int n = numPoints();
  out.resize(n);
  const NodeCoordinates a = dxi_[0] * x;
  if (dim() == 1) {
    out = a.rowwise().norm();
    return;
  }
  const NodeCoordinates b = dxi_[1] * x;
  if (dim() == 2) {
    for (int s = 0; s < n; ++s) {
      const Eigen::RowVector3d cross = a.row(s).cross(b.row(s));
      out(s) = normal != nullptr ? cross.dot(normal->transpose()) : cross.norm();
    }
    return;
  }
  const NodeCoordinates c = dxi_[2] * x;
  for (int s = 0; s < n; ++s) out(s) = a.row(s).cross(b.row(s)).dot(c.row(s));
}

void JacobianSampler::derivatives(const NodeCoordinates& x,
                                  std::array<NodeCoordinates, 3>& out) const {
  for (int k = 0; k < dim(); ++k) out[k].noalias() = dxi_[k] * x;
}

double jacobianDeterminant(const Eigen::Matrix<double, 3, Eigen::Dynamic>& columns,
                           const Eigen::Vector3d* normal) {
  switch (columns.cols()) {
    case 1:
      return columns.col(0).norm();
    case 2: {
      const Eigen::Vector3d cross = columns.col(0).cross(columns.col(1));
      return normal != nullptr ? cross.dot(*normal) : cross.norm();
    }
    default:
      return columns.col(0).cross(columns.col(1)).dot(columns.col(2));
  }
}

}  // namespace homesh
