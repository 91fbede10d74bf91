#include "element/element_map.hpp"

#include <cstddef>

namespace homesh {

ElementMap::ElementMap(const ReferenceElement& ref, const double* xyz, const std::int64_t* nodes)
    : ref_(&ref) {
  Eigen::MatrixXd x(ref.numNodes(), 3);
  for (int i = 0; i < ref.numNodes(); ++i)
    for (int d = 0; d < 3; ++d) x(i, d) = xyz[3 * static_cast<std::size_t>(nodes[i]) + d];
  modal_ = ref.modalCoefficients(x);
}

Eigen::Vector3d ElementMap::position(const double* xi) const {
  return ref_->interpolate(modal_, xi).transpose();
}

Eigen::Vector3d ElementMap::position(const double* xi, Eigen::Matrix3d& derivatives) const {
  Eigen::MatrixXd d;
  Eigen::Vector3d x = ref_->interpolate(modal_, xi, &d).transpose();
  derivatives.setZero();
  derivatives.leftCols(ref_->dim()) = d.transpose();
  return x;
}

}  // namespace homesh
