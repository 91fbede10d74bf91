#include "curving/curve_node_placement.hpp"

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

// Composite 5-point Gauss-Legendre on the curve's speed: arc length from t0 to t1 (signed).
double arcLength(const CadModel& cad, int edge, double t0, double t1, int pieces) {
  static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                              0.9061798459386640};
  static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                              0.4786286704993665, 0.2369268850561891};
  const double h = (t1 - t0) / pieces;
  double sum = 0.0;
  for (int k = 0; k < pieces; ++k)
    for (int q = 0; q < 5; ++q)
      sum += 0.5 * h * w[q] * cad.evaluateCurve(edge, t0 + h * (k + 0.5 * (1.0 + x[q]))).d1.norm();
  return sum;
}

// Parameters at arc-length fractions z of the span: a table of arc length over 16 pieces per
// node, then Newton on s(t) = target inside the piece (safeguarded by the piece's ends).
std::vector<double> equalArcParameters(const CadModel& cad, int edge, double ta, double tb,
                                       const std::vector<double>& z) {
  const int pieces = 16 * static_cast<int>(z.size());
  std::vector<double> cumulative(static_cast<std::size_t>(pieces) + 1, 0.0);
  const double h = (tb - ta) / pieces;
  for (int k = 0; k < pieces; ++k)
    cumulative[k + 1] = cumulative[k] + arcLength(cad, edge, ta + k * h, ta + (k + 1) * h, 1);
  const double total = cumulative.back();
  std::vector<double> t(z.size());
  t.front() = ta;
  t.back() = tb;
  for (std::size_t i = 1; i + 1 < z.size(); ++i) {
    const double target = z[i] * total;
    const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), target);
    const int k = std::clamp(static_cast<int>(it - cumulative.begin()) - 1, 0, pieces - 1);
    const double lo = ta + k * h, hi = ta + (k + 1) * h;
    const double span = cumulative[k + 1] - cumulative[k];
    double ti = span > 0.0 ? lo + h * (target - cumulative[k]) / span : 0.5 * (lo + hi);
    for (int newton = 0; newton < 4; ++newton) {
      const double speed = cad.evaluateCurve(edge, ti).d1.norm();
      if (!(speed > 0.0)) break;
      const double residual = cumulative[k] + arcLength(cad, edge, lo, ti, 1) - target;
      // ds/dt = speed * sign(h): the table runs from ta to tb.
      ti -= residual / (speed * (h > 0.0 ? 1.0 : -1.0));
      ti = std::clamp(ti, std::min(lo, hi), std::max(lo, hi));
    }
    t[i] = ti;
  }
  return t;
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

bool strictlyMonotone(const std::vector<double>& t) {
  if (t.size() < 2) return true;
  const double sign = t.back() > t.front() ? 1.0 : -1.0;
  for (std::size_t i = 1; i < t.size(); ++i)
    if (!(sign * (t[i] - t[i - 1]) > 0.0)) return false;
  return true;
}

CurvePlacement placeOnCurve(const CadModel& cad, int edge, double ta, double tb,
                            const std::vector<double>& z) {
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
  // Start at equal arc length and keep each node within its own arc-length cell (half-way to
  // its neighbours' equal-arc parameters): on resolved edges the energy's minimiser lies well
  // inside the cells, while on a coarse edge over a blunt nose the energy has minimisers that
  // cut across the nose with the nodes bunched on one flank, which the cells exclude. Disjoint
  // ordered cells also make the result monotone by construction.
  const std::vector<double> arc = equalArcParameters(cad, edge, ta, tb, z);
  SpringSystem system;
  system.paramDim = 1;
  system.fixed.assign(z.size(), 0);
  system.fixed.front() = system.fixed.back() = 1;
  system.lower.assign(z.size(), 0.0);
  system.upper.assign(z.size(), 0.0);
  if (strictlyMonotone(arc)) {
    result.t = arc;
    for (int i = 1; i + 1 < n; ++i) {
      const double a = 0.5 * (arc[i - 1] + arc[i]), b = 0.5 * (arc[i] + arc[i + 1]);
      system.lower[i] = std::min(a, b);
      system.upper[i] = std::max(a, b);
    }
  } else {  // the quadrature failed (a curve with a vanishing speed): t between the ends
    const double lo = std::min(ta, tb), hi = std::max(ta, tb), margin = 1e-9 * (hi - lo);
    for (int i = 1; i + 1 < n; ++i) {
      system.lower[i] = lo + margin;
      system.upper[i] = hi - margin;
    }
  }
  system.params = result.t;
  system.lower.front() = system.upper.front() = ta;
  system.lower.back() = system.upper.back() = tb;
  for (int i = 0; i + 1 < n; ++i) system.springs.push_back({i, i + 1, 1.0 / (z[i + 1] - z[i])});
  const ParameterMap map = [&](const double* t) {
    const CurveDerivatives c = cad.evaluateCurve(edge, *t);
    MappedPoint p;
    p.point = c.point;
    p.jacobian.setZero();
    p.jacobian.col(0) = c.d1;
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
