#include "quality/distortion.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>

#include "element/quadrature.hpp"

namespace homesh {

double distortionQuality(const Eigen::Matrix<double, 3, Eigen::Dynamic>& curved,
                         const Eigen::Matrix<double, 3, Eigen::Dynamic>& straight) {
  const int d = static_cast<int>(curved.cols());
  Eigen::MatrixXd a = curved, b = straight;
  if (d == 2) {  // express both in an orthonormal frame of the straight element's plane
    const Eigen::Vector3d e1 = straight.col(0).normalized();
    const Eigen::Vector3d n = straight.col(0).cross(straight.col(1)).normalized();
    const Eigen::Vector3d e2 = n.cross(e1);
    Eigen::Matrix<double, 2, 3> frame;
    frame << e1.transpose(), e2.transpose();
    a = frame * curved;
    b = frame * straight;
  }
  if (!(std::abs(b.determinant()) > 0.0)) return 0.0;  // degenerate straight element
  const Eigen::MatrixXd f = a * b.inverse();
  const double j = f.determinant();
  const double norm2 = f.squaredNorm();
  if (!(norm2 > 0.0)) return 0.0;
  const double q = d * std::pow(std::abs(j), 2.0 / d) / norm2;
  return j >= 0.0 ? q : -q;
}

namespace {

struct DistortionSamplers {
  JacobianSampler curved, straight;
};

const DistortionSamplers& samplers(CellType type, int order) {
  static std::mutex mutex;
  static std::map<std::pair<CellType, int>, std::unique_ptr<DistortionSamplers>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{type, order}];
  if (!slot) {
    const ReferenceElement& ref = ReferenceElement::get(type, order);
    const QuadratureRule rule = quadratureRule(type, 2 * order);
    const int dim = ref.dim();
    Eigen::MatrixXd points(rule.size() + ref.numNodes(), dim);
    for (int q = 0; q < rule.size(); ++q)
      for (int k = 0; k < dim; ++k)
        points(q, k) = rule.points[static_cast<std::size_t>(q) * dim + k];
    points.bottomRows(ref.numNodes()) = ref.nodes();
    slot = std::make_unique<DistortionSamplers>(DistortionSamplers{
        JacobianSampler(ref, points), JacobianSampler(ReferenceElement::get(type, 1), points)});
  }
  return *slot;
}

}  // namespace

double elementDistortion(CellType type, int order, const NodeCoordinates& x) {
  const DistortionSamplers& s = samplers(type, order);
  const NodeCoordinates vertices = x.topRows(cellNumVertices(type));
  double worst = std::numeric_limits<double>::infinity();
  for (int p = 0; p < s.curved.numPoints(); ++p)
    worst = std::min(worst, distortionQuality(s.curved.jacobianMatrix(x, p),
                                              s.straight.jacobianMatrix(vertices, p)));
  return worst;
}

}  // namespace homesh
