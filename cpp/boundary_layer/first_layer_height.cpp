#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <optional>

#include "boundary_layer/layer_splitter.hpp"
#include "element/element_map.hpp"
#include "element/quadrature.hpp"

namespace homesh::layer_splitting {

namespace {

// The height of the top (reference coordinate zeta = 1) of layer cell `v` above the wall point
// `bottom` (at wall coordinates (a, b)) along the unit wall normal `n` there: the distance to
// where the normal line meets the top, found by Newton's method on the top's offset
// perpendicular to n over the top's reference coordinates (a', b'), started at (a, b). Where
// the columns fan out (a wall curved more tightly than the layer is thick) the top point at
// (a, b) lies well to the side of the normal line, and its component along n understates the
// height. Returns nullopt when the search does not converge inside the cell's own top (the
// normal line leaves it through a neighbour's).
std::optional<double> heightAlongNormal(const ElementMap& map, const Eigen::Vector3d& plane,
                                        double a, double b, const Eigen::Vector3d& bottom,
                                        const Eigen::Vector3d& n) {
  const LayerShape shape = layerShape(map.reference().type());
  const bool volume = shape.across == 2;
  Eigen::Vector3d t1, t2 = Eigen::Vector3d::Zero();
  if (volume) {
    t1 = n.unitOrthogonal();
    t2 = n.cross(t1);
  } else {
    t1 = plane.cross(n);
    if (!(t1.norm() > 0.0)) return std::nullopt;
    t1.normalize();
  }
  Eigen::Matrix3d d;
  // Newton converges quadratically from a start within the cell; steps of 1e-12 in reference
  // coordinates (of order 1) are far below what the height needs and above rounding.
  constexpr int kIterations = 30;
  constexpr double kStep = 1e-12, kInside = 1e-9;
  for (int it = 0; it < kIterations; ++it) {
    const double xi[3] = {a, volume ? b : 1.0, 1.0};
    const Eigen::Vector3d x = map.position(xi, d);
    const Eigen::Vector3d da = d.col(0), db = d.col(1);
    const Eigen::Vector3d offset = x - bottom;
    Eigen::Vector2d step(0.0, 0.0);
    if (volume) {
      Eigen::Matrix2d jac;
      jac << da.dot(t1), db.dot(t1), da.dot(t2), db.dot(t2);
      step = jac.fullPivLu().solve(-Eigen::Vector2d(offset.dot(t1), offset.dot(t2)));
    } else {
      step[0] = -offset.dot(t1) / da.dot(t1);
    }
    if (!step.allFinite()) return std::nullopt;
    const bool inside = shape.inWall(a, b, kInside);
    if (step.norm() < kStep) return inside ? std::optional<double>(offset.dot(n)) : std::nullopt;
    a += step[0];
    b += step[1];
  }
  return std::nullopt;
}

}  // namespace

void LayerSplitter::measureFirstLayer() {
  std::size_t cell = 0;  // the macro cell, in split order
  for (const ElementBlock& b : out_.blocks) {
    if (!layerCell(b)) continue;
    const LayerShape shape = layerShape(b.type);
    const bool volume = shape.across == 2;
    const ReferenceElement& ref = ReferenceElement::get(b.type, p_);
    const QuadratureRule rule = quadratureRule(shape.wall, 2 * p_);
    const Eigen::Vector3d plane(out_.planeNormal[0], out_.planeNormal[1], out_.planeNormal[2]);
    for (std::size_t e = 0; e < b.count(); e += static_cast<std::size_t>(n_)) {
      const std::int64_t* v = b.element(e);  // the column's first layer
      const bool corner = cellCorner_.at(cell++) != 0;
      if (corner) ++stats_.cornerCells;
      const ElementMap map(ref, out_.xyz.data(), v);
      for (int q = 0; q < rule.size(); ++q) {
        const auto qq = static_cast<std::size_t>(q);
        const double a = rule.points[qq * static_cast<std::size_t>(rule.dim)];
        const double bb = volume ? rule.points[qq * 2 + 1] : 0.0;
        const double atWall[3] = {a, volume ? bb : 0.0, 0.0},
                     atTop[3] = {a, volume ? bb : 1.0, 1.0};
        const Eigen::Vector3d bottom = map.position(atWall), top = map.position(atTop);
        const Eigen::Vector3d n = wallNormal(map, a, bb, plane, top - bottom);
        const std::optional<double> along = heightAlongNormal(map, plane, a, bb, bottom, n);
        if (!along) ++stats_.firstHeightOffNormal;
        const double h = along ? *along : (top - bottom).dot(n);
        const std::array<double, 4> l = shape.weights(a, bb);
        const double target = z_[1] * grownHeight(v, shape.walls, l.data());
        if (stats_.firstHeightMeasured == 0) stats_.firstHeightMin = stats_.firstHeightMax = h;
        stats_.firstHeightMin = std::min(stats_.firstHeightMin, h);
        stats_.firstHeightMax = std::max(stats_.firstHeightMax, h);
        ++stats_.firstHeightMeasured;
        if (std::isfinite(target) && target > 0.0) {
          double& worst = corner ? stats_.firstHeightCornerDeviation : stats_.firstHeightDeviation;
          worst = std::max(worst, std::fabs(h / target - 1.0));
        }
      }
    }
  }
}

}  // namespace homesh::layer_splitting
