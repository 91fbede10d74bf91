#include "quality/jacobian_quality.hpp"

#include <Eigen/Dense>
#include <algorithm>

#include "core/error.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"

namespace homesh {

JacobianSampler::JacobianSampler(CellType type, int order) : dim_(cellDimension(type)) {
  if (dim_ < 1) throw Error("Jacobian sampling needs a 1D, 2D or 3D cell");
  const ReferenceElement& ref = ReferenceElement::get(type, order);
  const QuadratureRule rule = quadratureRule(type, 2 * order + 2);
  const int n = ref.numNodes();
  const int samples = rule.size() + n;
  dxi_.assign(dim_, Eigen::MatrixXd(samples, n));
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  for (int s = 0; s < samples; ++s) {
    Eigen::VectorXd xi(dim_);
    for (int k = 0; k < dim_; ++k)
      xi(k) = s < rule.size() ? rule.points[s * dim_ + k] : ref.nodes()(s - rule.size(), k);
    ref.evaluate(xi.data(), values, gradients);
    for (int k = 0; k < dim_; ++k) dxi_[k].row(s) = gradients.col(k).transpose();
  }
}

void JacobianSampler::sample(const Eigen::Matrix<double, Eigen::Dynamic, 3>& x,
                             const Eigen::Vector3d* normal, Eigen::VectorXd& jacobians) const {
  const int samples = numSamples();
  jacobians.resize(samples);
  // Columns of the Jacobian matrix at every sample: (samples x 3) per reference direction.
  const Eigen::Matrix<double, Eigen::Dynamic, 3> a = dxi_[0] * x;
  if (dim_ == 1) {
    jacobians = a.rowwise().norm();
    return;
  }
  const Eigen::Matrix<double, Eigen::Dynamic, 3> b = dxi_[1] * x;
  if (dim_ == 2) {
    for (int s = 0; s < samples; ++s) {
      const Eigen::RowVector3d n = a.row(s).cross(b.row(s));
      jacobians(s) = normal != nullptr ? n.dot(normal->transpose()) : n.norm();
    }
    return;
  }
  const Eigen::Matrix<double, Eigen::Dynamic, 3> c = dxi_[2] * x;
  for (int s = 0; s < samples; ++s) jacobians(s) = a.row(s).cross(b.row(s)).dot(c.row(s));
}

double scaledJacobian(double minJ, double maxJ) {
  return maxJ > 0.0 ? minJ / maxJ : -1.0;
}

QualitySummary evaluateQuality(const Mesh& mesh) {
  QualitySummary summary;
  const Eigen::Vector3d normal(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
  double sum = 0.0;
  for (const ElementBlock& block : mesh.blocks) {
    const bool element = cellDimension(block.type) == mesh.dim;
    const JacobianSampler sampler(block.type, block.order);
    const int n = block.nodesPerElement();
    Eigen::Matrix<double, Eigen::Dynamic, 3> x(n, 3);
    Eigen::VectorXd jacobians;
    TypeQuality* type = element ? &summary.byType[block.type] : nullptr;
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* nodes = block.element(e);
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) x(i, c) = mesh.xyz[3 * nodes[i] + c];
      sampler.sample(x, element && mesh.dim == 2 ? &normal : nullptr, jacobians);
      const double q = scaledJacobian(jacobians.minCoeff(), jacobians.maxCoeff());
      if (!element) {
        summary.boundaryScaledJacobian.push_back(q);
        continue;
      }
      summary.scaledJacobian.push_back(q);
      ++type->count;
      type->mean += q;
      type->min = std::min(type->min, q);
      if (q <= 0.0) ++type->invalid;
    }
  }
  if (summary.scaledJacobian.empty()) throw Error("quality: the mesh has no elements");
  for (auto& [cell, type] : summary.byType) {
    sum += type.mean;
    type.mean /= static_cast<double>(type.count);
    summary.invalid += type.invalid;
    summary.min = std::min(summary.min, type.min);
  }
  summary.mean = sum / static_cast<double>(summary.scaledJacobian.size());
  return summary;
}

}  // namespace homesh
