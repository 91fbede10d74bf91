#include "quality/distortion.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

#include "element/cell_table_cache.hpp"
#include "element/quadrature.hpp"

namespace homesh {

namespace {

// d J^(2/d) / |F|^2, signed by J.
template <int D>
double qualityOfGradient(const Eigen::Matrix<double, D, D>& f) {
  const double j = f.determinant();
  const double norm2 = f.squaredNorm();
  if (!(norm2 > 0.0)) return 0.0;
  const double power = D == 3 ? std::cbrt(j * j) : std::abs(j);  // |J|^(2/d)
  const double q = D * power / norm2;
  return j >= 0.0 ? q : -q;
}

// An orthonormal frame (rows) of the plane of a 2D straight element's Jacobian columns.
Eigen::Matrix<double, 2, 3> planeFrame(const Eigen::Matrix3d& straight) {
  const Eigen::Vector3d e1 = straight.col(0).normalized();
  const Eigen::Vector3d n = straight.col(0).cross(straight.col(1)).normalized();
  Eigen::Matrix<double, 2, 3> frame;
  frame << e1.transpose(), n.cross(e1).transpose();
  return frame;
}

}  // namespace

double distortionQuality(const Eigen::Matrix3d& curved, const Eigen::Matrix3d& straight, int dim) {
  if (dim == 3) {
    if (!(std::abs(straight.determinant()) > 0.0)) return 0.0;  // degenerate straight element
    return qualityOfGradient<3>(curved * straight.inverse());
  }
  const Eigen::Matrix<double, 2, 3> frame = planeFrame(straight);
  const Eigen::Matrix2d b = frame * straight.leftCols<2>();
  if (!(std::abs(b.determinant()) > 0.0)) return 0.0;
  return qualityOfGradient<2>(frame * curved.leftCols<2>() * b.inverse());
}

namespace {

// The sample points' derivative matrices, stacked by direction: rows k * points + p hold
// d/dxi_k at point p, for the curved element (all nodes) and the straight one (vertices).
struct DistortionSamplers {
  int dim = 3, points = 0;
  Eigen::MatrixXd curved, straight;
};

Eigen::MatrixXd stackedDerivatives(const ReferenceElement& ref, const Eigen::MatrixXd& points) {
  const std::vector<Eigen::MatrixXd> d = ref.derivativesAt(points);
  Eigen::MatrixXd out(ref.dim() * points.rows(), ref.numNodes());
  for (int k = 0; k < ref.dim(); ++k)
    out.middleRows(k * points.rows(), points.rows()) = d[static_cast<std::size_t>(k)];
  return out;
}

const DistortionSamplers& samplers(CellType type, int order) {
  static CellTableCache<DistortionSamplers> cache;
  return cache.get(type, order, [&] {
    const ReferenceElement& ref = ReferenceElement::get(type, order);
    const QuadratureRule rule = quadratureRule(type, order);
    const int dim = ref.dim();
    const Eigen::MatrixXd points = pointRows(rule, ref.nodes());
    return std::make_unique<DistortionSamplers>(
        DistortionSamplers{dim, static_cast<int>(points.rows()), stackedDerivatives(ref, points),
                           stackedDerivatives(ReferenceElement::get(type, 1), points)});
  });
}

}  // namespace

double elementDistortion(CellType type, int order, const NodeCoordinates& x) {
  const DistortionSamplers& s = samplers(type, order);
  const int dim = s.dim, np = s.points;
  thread_local NodeCoordinates curved, straight;
  curved.noalias() = s.curved.lazyProduct(x);
  straight.noalias() = s.straight.lazyProduct(x.topRows(cellNumVertices(type)));
  // Simplices' straight-sided maps are affine: one inverse serves every point.
  const bool affine = type == CellType::Triangle || type == CellType::Tetrahedron;
  double worst = std::numeric_limits<double>::infinity();
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero(), b = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d inverse3 = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 2, 3> frame = Eigen::Matrix<double, 2, 3>::Zero();
  Eigen::Matrix2d inverse2 = Eigen::Matrix2d::Zero();
  for (int p = 0; p < np; ++p) {
    for (int k = 0; k < dim; ++k) a.col(k) = curved.row(k * np + p).transpose();
    if (!affine || p == 0) {
      for (int k = 0; k < dim; ++k) b.col(k) = straight.row(k * np + p).transpose();
      if (dim == 3) {
        const double det = b.determinant();
        if (!(std::abs(det) > 0.0)) return 0.0;  // degenerate straight element
        inverse3 = b.inverse();
      } else {
        frame = planeFrame(b);
        const Eigen::Matrix2d b2 = frame * b.leftCols<2>();
        if (!(std::abs(b2.determinant()) > 0.0)) return 0.0;
        inverse2 = b2.inverse();
      }
    }
    const double q = dim == 3 ? qualityOfGradient<3>(a * inverse3)
                              : qualityOfGradient<2>(frame * a.leftCols<2>() * inverse2);
    worst = std::min(worst, q);
  }
  return worst;
}

}  // namespace homesh
