#include "curving/curve_node_placement.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "curving/spring_energy.hpp"

namespace homesh {
namespace {

Eigen::Vector3d position(const Mesh& mesh, std::int64_t node) {
  return {mesh.xyz[3 * node], mesh.xyz[3 * node + 1], mesh.xyz[3 * node + 2]};
}

// How far a node may sit from the curve point of its recorded parameter before the parameter is
// distrusted and recomputed: the CAD's own tolerance, floored by the model's rounding scale.
double trustDistance(const CadModel& cad, int edge) {
  return std::max(cad.tolerance(1, edge), 1e-7 * cad.boundingDiagonal());
}

}  // namespace

double nodeCurveParameter(const CadModel& cad, const Mesh& mesh, std::int64_t node, int edge,
                          std::optional<double> near) {
  const Eigen::Vector3d x = position(mesh, node);
  const int dim = mesh.nodeCadDim[node];
  const int index = mesh.nodeCadIndex[node];
  if (dim == 0 && index > 0) {
    try {
      return cad.vertexParameter(index, edge, near);
    } catch (const CadError&) {
      // Not a vertex of this curve (an inconsistent record): fall through to projection.
    }
  }
  if (dim == 1 && index == edge && std::isfinite(mesh.nodeCadParam[2 * node])) {
    const double t = mesh.nodeCadParam[2 * node];
    if ((cad.evaluateCurve(edge, t).point - x).norm() <= trustDistance(cad, edge)) return t;
  }
  return cad.projectOnCurve(edge, x).t;
}

std::vector<double> equispacedPositions(int order) {
  std::vector<double> z(static_cast<std::size_t>(order) + 1);
  for (int i = 0; i <= order; ++i) z[i] = static_cast<double>(i) / order;
  return z;
}

std::optional<CurveDerivatives> offsetCurve(const CurveDerivatives& c, const CurveOffset& offset) {
  // n = u / |u| with u = c' x k; n' = (u' - n (n . u')) / |u| with u' = c'' x k.
  const Eigen::Vector3d u = c.d1.cross(offset.planeNormal);
  const double speed = u.norm();
  if (!(speed > 0.0)) return std::nullopt;
  const Eigen::Vector3d normal = u / speed;
  const Eigen::Vector3d du = c.d2.cross(offset.planeNormal);
  CurveDerivatives o;
  o.point = c.point + offset.height * normal;
  o.d1 = c.d1 + offset.height * (du - normal * normal.dot(du)) / speed;
  o.d2.setZero();
  return o;
}

bool strictlyMonotone(const std::vector<double>& t) {
  if (t.size() < 2) return true;
  const double sign = t.back() > t.front() ? 1.0 : -1.0;
  for (std::size_t i = 1; i < t.size(); ++i)
    if (!(sign * (t[i] - t[i - 1]) > 0.0)) return false;
  return true;
}

CurvePlacement placeOnCurve(const CadModel& cad, int edge, double ta, double tb,
                            const std::vector<double>& z,
                            const std::optional<CurveOffset>& offset) {
  if (z.size() < 2 || z.front() != 0.0 || z.back() != 1.0 || !strictlyMonotone(z))
    throw ParameterError("curve node placement needs increasing positions from 0 to 1");
  if (!(ta != tb) || !std::isfinite(ta) || !std::isfinite(tb))
    throw ParameterError("curve node placement on " + cadEntityName(1, edge) +
                         " needs two distinct end parameters");
  const int n = static_cast<int>(z.size());
  CurvePlacement result;
  result.t.resize(z.size());
  for (int i = 0; i < n; ++i) result.t[i] = ta + (tb - ta) * z[i];
  if (n == 2) return result;

  SpringSystem system;
  system.paramDim = 1;
  system.params = result.t;
  system.fixed.assign(z.size(), 0);
  system.fixed.front() = system.fixed.back() = 1;
  // Strictly inside the edge's span: a node may not reach an end.
  const double lo = std::min(ta, tb), hi = std::max(ta, tb), margin = 1e-9 * (hi - lo);
  system.lower.assign(z.size(), lo + margin);
  system.upper.assign(z.size(), hi - margin);
  for (int i = 0; i + 1 < n; ++i) system.springs.push_back({i, i + 1, 1.0 / (z[i + 1] - z[i])});
  const ParameterMap map = [&](const double* t) {
    const CurveDerivatives c = cad.evaluateCurve(edge, *t);
    MappedPoint p;
    p.point = c.point;
    p.jacobian.setZero();
    p.jacobian.col(0) = c.d1;
    if (offset) {
      if (const std::optional<CurveDerivatives> o = offsetCurve(c, *offset)) {
        p.point = o->point;
        p.jacobian.col(0) = o->d1;
      }
    }
    return p;
  };
  minimiseSprings(system, map);
  if (strictlyMonotone(system.params)) {
    result.t = system.params;
    result.optimised = true;
  }
  return result;
}

}  // namespace homesh
