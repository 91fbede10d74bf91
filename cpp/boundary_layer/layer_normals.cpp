#include "boundary_layer/layer_normals.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <optional>

#include "core/error.hpp"
#include "curving/curve_node_placement.hpp"

namespace homesh {

Eigen::Vector3d wallNormal(const Mesh& mesh, const ReferenceElement& ref, const std::int64_t* v,
                           double a, double b, const Eigen::Vector3d& towards) {
  return wallNormal(ElementMap(ref, mesh.xyz.data(), v), a, b,
                    Eigen::Vector3d(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]),
                    towards);
}

Eigen::Vector3d wallNormal(const ElementMap& map, double a, double b, const Eigen::Vector3d& plane,
                           const Eigen::Vector3d& towards) {
  const bool volume = map.reference().dim() == 3;
  const double xi[3] = {a, volume ? b : 0.0, 0.0};
  Eigen::Matrix3d d;
  map.position(xi, d);
  Eigen::Vector3d n = volume ? Eigen::Vector3d(d.col(0).cross(d.col(1))) : plane.cross(d.col(0));
  if (!(n.norm() > 0.0)) return Eigen::Vector3d::Zero();
  n.normalize();
  return n.dot(towards) < 0.0 ? Eigen::Vector3d(-n) : n;
}

Eigen::Vector3d curveNormal(const Mesh& mesh, const CadModel& cad, std::int64_t node, int curve,
                            double near, const Eigen::Vector3d& towards) {
  try {
    const double t = nodeCurveParameter(
        cad, mesh, node, curve, std::isfinite(near) ? std::optional<double>(near) : std::nullopt);
    const Eigen::Vector3d plane(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
    Eigen::Vector3d n = plane.cross(cad.evaluateCurve(curve, t).d1);
    if (!(n.norm() > 0.0)) return Eigen::Vector3d::Zero();
    n.normalize();
    return n.dot(towards) < 0.0 ? Eigen::Vector3d(-n) : n;
  } catch (const Error&) {
    return Eigen::Vector3d::Zero();
  }
}

std::vector<double> layerTopNormals(const Mesh& mesh) {
  std::map<std::int64_t, NormalSum> tops;
  forEachColumn(
      mesh, [&](std::int64_t, std::int64_t top, const Eigen::Vector3d& n) { tops[top].add(n); });
  std::vector<double> normals(3 * mesh.numNodes(), std::nan(""));
  for (const auto& [id, n] : tops) {
    // Above a sharp corner the column follows the corner's bisector and no plane keeps both
    // walls' heights: free.
    if (n.sharp() || !(n.sum.norm() > 0.0)) continue;
    const Eigen::Vector3d unit = n.sum.normalized();
    for (std::size_t d = 0; d < 3; ++d)
      normals[3 * static_cast<std::size_t>(id) + d] = unit(static_cast<Eigen::Index>(d));
  }
  return normals;
}

}  // namespace homesh
