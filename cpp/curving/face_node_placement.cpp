#include "curving/face_node_placement.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace homesh {
namespace {

Eigen::Vector3d position(const Mesh& mesh, std::int64_t node) {
  return {mesh.xyz[3 * node], mesh.xyz[3 * node + 1], mesh.xyz[3 * node + 2]};
}

double shiftNear(double value, double reference, double period) {
  if (!(period > 0.0)) return value;
  return value - period * std::round((value - reference) / period);
}

// Reference positions must rise from 0 to 1 (the callers build them).
void checkPositions(const std::vector<double>& z) {
  if (z.size() < 2 || z.front() != 0.0 || z.back() != 1.0)
    throw ParameterError("face node placement needs positions from 0 to 1");
  for (std::size_t i = 1; i < z.size(); ++i)
    if (!(z[i] > z[i - 1])) throw ParameterError("face node placement needs increasing positions");
}

}  // namespace

FaceChart::FaceChart(const CadModel& cad, int face)
    : cad_(cad), face_(face), period_(cad.facePeriods(face)), bounds_(cad.faceBounds(face)) {}

FaceParameter FaceChart::unwrapNear(FaceParameter uv, const FaceParameter& reference) const {
  for (int d = 0; d < 2; ++d) uv[d] = shiftNear(uv[d], reference[d], period_[d]);
  return uv;
}

FaceParameter FaceChart::wrap(FaceParameter uv) const {
  const double lo[2] = {bounds_.uMin, bounds_.vMin}, hi[2] = {bounds_.uMax, bounds_.vMax};
  for (int d = 0; d < 2; ++d) {
    const double p = period_[d];
    if (!(p > 0.0)) continue;
    // Into [lo, lo + p); a value just below lo (rounding at the seam) stays at lo's side.
    const double slack = 1e-12 * p;
    double w = lo[d] + std::fmod(uv[d] - lo[d], p);
    if (w < lo[d] - slack) w += p;
    if (w > hi[d] + slack && w - p >= lo[d] - slack) w -= p;
    uv[d] = w;
  }
  return uv;
}

std::array<bool, 2> FaceChart::singular(const FaceParameter& uv) const {
  return cad_.evaluateSurface(face_, uv[0], uv[1]).degenerate();
}

bool FaceChart::contains(const FaceParameter& uv) const {
  const FaceParameter w = wrap(uv);
  return cad_.faceContains(face_, w[0], w[1]);
}

MappedPoint FaceChart::map(const double* uv) const {
  const SurfaceDerivatives s = cad_.evaluateSurface(face_, uv[0], uv[1]);
  MappedPoint p;
  p.point = s.point;
  p.jacobian.col(0) = s.du;
  p.jacobian.col(1) = s.dv;
  return p;
}

Eigen::Vector3d FaceChart::point(const FaceParameter& uv) const {
  return cad_.evaluateSurface(face_, uv[0], uv[1]).point;
}

FaceParameter nodeFaceParameter(const FaceChart& chart, const Mesh& mesh, std::int64_t node,
                                std::optional<FaceParameter> near) {
  const CadModel& cad = chart.cad();
  const int face = chart.face();
  const Eigen::Vector3d x = position(mesh, node);
  const int dim = mesh.nodeCadDim[node];
  const int index = mesh.nodeCadIndex[node];
  const double p0 = mesh.nodeCadParam[2 * node], p1 = mesh.nodeCadParam[2 * node + 1];
  // A recorded parameter is trusted when it reproduces the node within the CAD's tolerance
  // (floored by the model's rounding scale).
  const double floor = 1e-7 * cad.boundingDiagonal();
  const double faceTol = std::max(cad.tolerance(2, face), floor);
  if (dim == 2 && index == face && std::isfinite(p0) && std::isfinite(p1)) {
    const FaceParameter uv{p0, p1};
    if ((chart.point(uv) - x).norm() <= faceTol) return uv;
  }
  if (dim == 1 && index > 0 && std::isfinite(p0)) {
    try {
      const FaceParameter uv = cad.edgeParameterOnFace(index, face, p0);
      if ((chart.point(uv) - x).norm() <= std::max(faceTol, cad.tolerance(1, index))) return uv;
    } catch (const CadError&) {
      // The curve does not bound this face: projection below.
    }
  }
  const SurfaceProjection proj =
      near ? cad.projectOnSurface(face, x, *near) : cad.projectOnSurface(face, x);
  return {proj.u, proj.v};
}

std::array<FaceParameter, 2> edgeEnds(const FaceChart& chart, FaceParameter a, FaceParameter b) {
  b = chart.unwrapNear(b, a);
  const std::array<bool, 2> sa = chart.singular(a), sb = chart.singular(b);
  for (int d = 0; d < 2; ++d) {
    // At a pole this parameter is arbitrary: the edge arrives along the other end's line.
    if (sa[d] && !sb[d]) a[d] = b[d];
    if (sb[d] && !sa[d]) b[d] = a[d];
  }
  return {a, b};
}

bool advancesAlongChord(const std::vector<FaceParameter>& uv) {
  if (uv.size() < 2) return true;
  const double du = uv.back()[0] - uv.front()[0], dv = uv.back()[1] - uv.front()[1];
  double last = 0.0;
  for (std::size_t i = 1; i < uv.size(); ++i) {
    const double s = (uv[i][0] - uv.front()[0]) * du + (uv[i][1] - uv.front()[1]) * dv;
    if (!(s > last)) return false;
    last = s;
  }
  return true;
}

FaceEdgePlacement placeOnFaceEdge(const FaceChart& chart, const FaceParameter& a,
                                  const FaceParameter& b, const Eigen::Vector3d& xa,
                                  const Eigen::Vector3d& xb, const std::vector<double>& z) {
  checkPositions(z);
  const int n = static_cast<int>(z.size());
  FaceEdgePlacement result;
  result.uv.resize(z.size());
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < 2; ++d) result.uv[i][d] = a[d] + (b[d] - a[d]) * z[i];
  const auto acceptable = [&](const std::vector<FaceParameter>& uv) {
    if (!advancesAlongChord(uv)) return false;
    for (int i = 1; i + 1 < n; ++i)
      if (!chart.contains(uv[i])) return false;
    return true;
  };
  if (n == 2) {
    result.valid = true;
    return result;
  }

  SpringSystem system;
  system.paramDim = 2;
  system.fixed.assign(z.size(), 0);
  system.fixed.front() = system.fixed.back() = 1;
  system.pinned.assign(z.size(), Eigen::Vector3d::Zero());
  system.pinned.front() = xa;
  system.pinned.back() = xb;
  for (const FaceParameter& uv : result.uv)
    system.params.insert(system.params.end(), uv.begin(), uv.end());
  for (int i = 0; i + 1 < n; ++i) system.springs.push_back({i, i + 1, 1.0 / (z[i + 1] - z[i])});
  minimiseSprings(system, [&](const double* uv) { return chart.map(uv); });
  std::vector<FaceParameter> optimum(z.size());
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(2) * static_cast<std::size_t>(i);
    optimum[i] = {system.params[k], system.params[k + 1]};
  }
  if (acceptable(optimum)) {
    result.uv = std::move(optimum);
    result.optimised = result.valid = true;
  } else {
    result.valid = acceptable(result.uv);
  }
  return result;
}

TrianglePlacement placeTriangleInterior(const FaceChart& chart, int order,
                                        const std::vector<FaceParameter>& uv,
                                        const std::vector<Eigen::Vector3d>& x) {
  const int p = order;
  const auto count = static_cast<std::size_t>((p + 1) * (p + 2) / 2);
  if (p < 1 || uv.size() != count || x.size() != count)
    throw ParameterError("triangle placement: the lattice arrays do not match order " +
                         std::to_string(order));
  TrianglePlacement result;
  result.uv = uv;
  if (p < 3) {
    result.valid = true;
    return result;
  }
  const auto at = [p](int i, int j) { return latticeIndex(p, i, j); };
  const auto interior = [p](int i, int j) { return i >= 1 && j >= 1 && i + j <= p - 1; };

  // Harmonic start: every interior node is the mean of its six lattice neighbours. On the
  // uniform lattice this stencil is exact for affine functions, so a triangle with straight
  // edges in (u, v) gets exactly its equispaced lattice.
  std::vector<int> slot(count, -1);
  std::vector<std::array<int, 2>> free;
  for (int j = 0; j <= p; ++j)
    for (int i = 0; i + j <= p; ++i)
      if (interior(i, j)) {
        slot[at(i, j)] = static_cast<int>(free.size());
        free.push_back({i, j});
      }
  const int m = static_cast<int>(free.size());
  static const int kNeighbour[6][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, -1}, {-1, 1}};
  Eigen::MatrixXd laplacian = Eigen::MatrixXd::Zero(m, m);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(m, 2);
  for (int r = 0; r < m; ++r) {
    laplacian(r, r) = 6.0;
    for (const auto& d : kNeighbour) {
      const int ni = free[r][0] + d[0], nj = free[r][1] + d[1];
      const int s = slot[at(ni, nj)];
      if (s >= 0) {
        laplacian(r, s) -= 1.0;
      } else {
        rhs(r, 0) += uv[at(ni, nj)][0];
        rhs(r, 1) += uv[at(ni, nj)][1];
      }
    }
  }
  const Eigen::MatrixXd harmonic = laplacian.ldlt().solve(rhs);
  std::vector<FaceParameter> start = uv;
  for (int r = 0; r < m; ++r) start[at(free[r][0], free[r][1])] = {harmonic(r, 0), harmonic(r, 1)};

  // The lattice's small triangles must keep one orientation on the surface: each is measured
  // against the surface normal at its nodes (not in (u, v), whose chart bends strongly near a
  // pole; the normal is skipped where the chart is singular).
  std::vector<std::array<int, 3>> cells;
  for (int j = 0; j < p; ++j)
    for (int i = 0; i + j < p; ++i) {
      cells.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
      if (i + j + 1 < p) cells.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  std::vector<char> isFree(count, 0);
  for (const auto& f : free) isFree[at(f[0], f[1])] = 1;
  const auto acceptable = [&](const std::vector<FaceParameter>& l) {
    std::vector<Eigen::Vector3d> pts(count), normal(count);
    for (std::size_t k = 0; k < count; ++k) {
      if (isFree[k] != 0 && !chart.contains(l[k])) return false;
      const SurfaceDerivatives d = chart.cad().evaluateSurface(chart.face(), l[k][0], l[k][1]);
      pts[k] = isFree[k] != 0 ? d.point : x[k];
      const Eigen::Vector3d n = d.du.cross(d.dv);
      const double scale = d.du.norm() * d.dv.norm();
      // Singular where du x dv vanishes up to rounding (see FaceChart::singular).
      normal[k] = n.norm() > 1e-7 * scale && scale > 0.0 ? Eigen::Vector3d(n.normalized())
                                                         : Eigen::Vector3d::Zero();
    }
    double sign = 0.0;
    for (const auto& c : cells) {
      const Eigen::Vector3d n = normal[c[0]] + normal[c[1]] + normal[c[2]];
      const double a = n.dot((pts[c[1]] - pts[c[0]]).cross(pts[c[2]] - pts[c[0]]));
      if (!(a != 0.0) || !std::isfinite(a)) return false;
      if (sign == 0.0) sign = a > 0.0 ? 1.0 : -1.0;
      if (a * sign < 0.0) return false;
    }
    return true;
  };

  SpringSystem system;
  system.paramDim = 2;
  system.fixed.assign(count, 1);
  system.pinned = x;
  for (const FaceParameter& q : start)
    system.params.insert(system.params.end(), q.begin(), q.end());
  for (const auto& f : free) system.fixed[at(f[0], f[1])] = 0;
  for (int j = 0; j <= p; ++j)
    for (int i = 0; i + j <= p; ++i) {
      if (i + j < p) {
        system.springs.push_back({at(i, j), at(i + 1, j), 1.0});
        system.springs.push_back({at(i, j), at(i, j + 1), 1.0});
        system.springs.push_back({at(i + 1, j), at(i, j + 1), 1.0});
      }
    }
  minimiseSprings(system, [&](const double* q) { return chart.map(q); });
  std::vector<FaceParameter> relaxed = start;
  for (const auto& f : free) {
    const int k = at(f[0], f[1]);
    relaxed[k] = {system.params[2 * static_cast<std::size_t>(k)],
                  system.params[2 * static_cast<std::size_t>(k) + 1]};
  }
  if (acceptable(relaxed)) {
    result.uv = std::move(relaxed);
    result.relaxed = result.valid = true;
  } else if (acceptable(start)) {
    result.uv = std::move(start);
    result.valid = true;
  }
  return result;
}

}  // namespace homesh
