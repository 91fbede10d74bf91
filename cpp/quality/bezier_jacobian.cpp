#include "quality/bezier_jacobian.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "element/cell_table_cache.hpp"
#include "quality/bernstein.hpp"

namespace homesh {
namespace {

// Limits on the refinement of one element: bisections deep (times the dimension) and in all.
constexpr int kMaxDepth = 12;
constexpr int kMaxSubdivisions = 4000;
constexpr int kMaxCoefficients = 10'000'000;  // 80 MB of open parts per element at most

BernsteinFactors geometryFactors(CellType type, int p) {
  switch (type) {
    case CellType::Triangle:
      return {{2, p}};
    case CellType::Tetrahedron:
      return {{3, p}};
    case CellType::Quadrilateral:
      return {{1, p}, {1, p}};
    case CellType::Hexahedron:
      return {{1, p}, {1, p}, {1, p}};
    case CellType::Prism:
      return {{2, p}, {1, p}};
    default:
      throw ParameterError("no Jacobian bounds for " + cellShortName(type));
  }
}

// The reference shape's vertices per factor of J's space (simplex factors: the origin, then
// the unit vectors), flattened: what a part of the domain remembers to choose its next split.
using Corners = std::array<double, 12>;

Corners referenceCorners(const BernsteinFactors& factors) {
  Corners v{};
  int at = 0;
  for (const auto& [d, m] : factors) {
    for (int slot = 0; slot <= d; ++slot)
      for (int k = 0; k < d; ++k) v[at++] = slot == k + 1 ? 1.0 : 0.0;
  }
  return v;
}

// Offset of each factor's block of (d + 1) x d vertex coordinates in Corners.
std::vector<int> cornerOffsets(const BernsteinFactors& factors) {
  std::vector<int> offsets;
  int at = 0;
  for (const auto& [d, m] : factors) {
    offsets.push_back(at);
    at += (d + 1) * d;
  }
  return offsets;
}

// Everything about a shape and order that does not depend on the element: J's Bezier
// coefficients are J = d0 . (d1 x d2) (or (d0 x d1) . n in 2D) with d_k = derivative[k] * x the
// control points of dx/dxi_k, multiplied term by term.
struct BezierTables {
  using Terms = std::vector<BernsteinSpace::ProductTerm>;
  int dim = 3;
  std::vector<Eigen::MatrixXd> derivative;  // per k: (size of d_k's space) x nodes
  std::vector<double> derivativeNorm;       // per k: its largest row sum of |entries|
  std::vector<double> derivativeError;      // per k: relative error of its entries (estimate)
  int maxTerms = 0;  // most product terms summed into one coefficient (inner plus outer)
  const Terms* inner = nullptr;  // d1 x d2 (3D) or d0 x d1 (2D)
  const Terms* outer = nullptr;  // d0 . (d1 x d2) (3D only)
  int innerSize = 0, jacobianSize = 0;
  const BernsteinSpace* jacobian = nullptr;  // J's space
  std::vector<int> corners;                  // corner functions of J's space
  std::vector<int> cornerOffsets;            // per factor of J's space, into Corners
};

// Lagrange (equispaced nodes) to Bernstein coefficients of the geometry. The geometry space is a
// product of factors (a hexahedron's three intervals, a prism's triangle and interval), and so
// is this matrix: each entry is a product of the factors' own inverses, which are small and well
// conditioned, where inverting the whole n x n matrix of a tensor-product shape at once loses
// digits that then leak into J (rows of the derivative matrices that should sum to zero would
// not, and J would depend on where the element sits).
Eigen::MatrixXd lagrangeToBezier(const ReferenceElement& ref, const BernsteinSpace& geometry) {
  const int n = ref.numNodes(), p = ref.order();
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < ref.dim(); ++c)
      if (std::abs(ref.nodes()(i, c) - static_cast<double>(ref.lattice()[i][c]) / p) > 1e-12)
        throw Error("Bezier tables need equispaced nodes on the lattice");
  struct Factor {
    const BernsteinSpace* space;
    Eigen::MatrixXd inverse;  // (function, node) of the factor alone
    int col, d;
  };
  std::vector<Factor> factors;
  int col = 0;
  for (const auto& [d, m] : geometry.factors()) {
    const BernsteinSpace& s = BernsteinSpace::get({{d, m}});
    Eigen::MatrixXd values(s.size(), s.size());  // function j at the node with its own index r
    for (int r = 0; r < s.size(); ++r) {
      const Eigen::VectorXd x = s.point(r);
      for (int j = 0; j < s.size(); ++j) values(r, j) = s.basis(j, x.data());
    }
    factors.push_back({&s, values.fullPivLu().inverse(), col, d});
    col += d;
  }
  Eigen::MatrixXd out(n, n);
  std::vector<int> sub;
  for (int f = 0; f < n; ++f)
    for (int node = 0; node < n; ++node) {
      double v = 1.0;
      for (const Factor& factor : factors) {
        const std::vector<int>& fi = geometry.multiIndex(f);
        sub.assign(fi.begin() + factor.col, fi.begin() + factor.col + factor.d);
        const int j = factor.space->indexOf(sub);
        for (int k = 0; k < factor.d; ++k) sub[k] = ref.lattice()[node][factor.col + k];
        v *= factor.inverse(j, factor.space->indexOf(sub));
      }
      out(f, node) = v;
    }
  return out;
}

// The columns of J's matrix in Bezier form: per reference direction k, the matrix from the
// nodes' coordinates to the control points of the column, and the column's space.
struct Columns {
  std::vector<Eigen::MatrixXd> matrix;
  std::vector<const BernsteinSpace*> space;
};

// The columns dx/dxi_k (k < dim) of a geometry in `geometry`'s space whose control points are
// toBezier times the nodes: the derivatives of the control points.
Columns derivativeColumns(const BernsteinSpace& geometry, const Eigen::MatrixXd& toBezier,
                          int dim) {
  Columns c;
  for (int k = 0; k < dim; ++k) {
    c.space.push_back(&BernsteinSpace::get(geometry.derivativeFactors(k)));
    Eigen::MatrixXd d(c.space.back()->size(), toBezier.cols());
    for (Eigen::Index j = 0; j < toBezier.cols(); ++j)
      d.col(j) = geometry.derivative(k, toBezier.col(j));
    c.matrix.push_back(std::move(d));
  }
  return c;
}

// A polynomial shape: its own geometry space, Lagrange-to-Bezier on its nodes.
Columns polynomialColumns(const ReferenceElement& ref) {
  const BernsteinSpace& geometry = BernsteinSpace::get(geometryFactors(ref.type(), ref.order()));
  return derivativeColumns(geometry, lagrangeToBezier(ref, geometry), ref.dim());
}

// Control points of f / (1 - z), rows of `coeffs` in `space` (three intervals, z the last, of
// degree m), for f that vanishes at z = 1: B_k^m(z) / (1 - z) = m / (m - k) B_k^(m-1)(z); the
// coefficients at k = m, zero but for rounding, are dropped.
Eigen::MatrixXd divideByOneMinusZ(const BernsteinSpace& space, const Eigen::MatrixXd& coeffs,
                                  const BernsteinSpace& quotient) {
  const int m = space.factors()[2].second;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(quotient.size(), coeffs.cols());
  for (int j = 0; j < space.size(); ++j) {
    const std::vector<int>& index = space.multiIndex(j);
    if (index[2] == m) continue;
    out.row(quotient.indexOf(index)) = coeffs.row(j) * (static_cast<double>(m) / (m - index[2]));
  }
  return out;
}

// A pyramid's map is rational in its own coordinates, but in collapsed ones (u, v, z) on the unit
// cube, x = u (1 - z) and y = v (1 - z), every function of its basis (xi^a eta^b s^max(a,b) z^c,
// orthogonal_basis.hpp, with xi = u and eta = v) is a polynomial of degree p in each of u, v, z:
// the geometry has control points in the hexahedron's space, interpolated at its equispaced
// points (the top face's all at the apex). There dx/du and dx/dv vanish with s = 1 - z and,
// divided by it, are the pyramid's dx/dx and dx/dy; dx/dz at fixed (u, v) is dx/dz - u dx/dx -
// v dx/dy; so the determinant of the three is the pyramid's own J, a polynomial on the cube (of
// degree 3p - 1 in u and v, 3p - 3 in z) whose Bezier coefficients bound J over the pyramid and,
// on the top face, its limits at the apex from every direction (where J itself depends on the
// direction once the geometry holds the rational functions, x y / (1 - z) at order 1).
Columns pyramidColumns(const ReferenceElement& ref) {
  const int p = ref.order();
  const ReferenceElement& cube = ReferenceElement::get(CellType::Hexahedron, p);
  const BernsteinSpace& geometry = BernsteinSpace::get(geometryFactors(CellType::Hexahedron, p));
  Eigen::MatrixXd points(cube.numNodes(), 3);
  for (int h = 0; h < cube.numNodes(); ++h) {
    const Eigen::Vector3d uvz = cube.nodes().row(h).transpose();
    points.row(h) << uvz.x() * (1.0 - uvz.z()), uvz.y() * (1.0 - uvz.z()), uvz.z();
  }
  Columns c =
      derivativeColumns(geometry, lagrangeToBezier(cube, geometry) * ref.valuesAt(points), 3);
  for (std::size_t k = 0; k < 2; ++k) {  // dx/du and dx/dv over 1 - z
    const BernsteinSpace& derivative = *c.space[k];
    BernsteinFactors reduced = derivative.factors();
    reduced[2].second -= 1;
    c.space[k] = &BernsteinSpace::get(reduced);
    c.matrix[k] = divideByOneMinusZ(derivative, c.matrix[k], *c.space[k]);
  }
  return c;
}

std::unique_ptr<BezierTables> buildTables(CellType type, int order) {
  auto t = std::make_unique<BezierTables>();
  const ReferenceElement& ref = ReferenceElement::get(type, order);
  const int dim = ref.dim();
  t->dim = dim;
  const Columns columns = type == CellType::Pyramid ? pyramidColumns(ref) : polynomialColumns(ref);
  const std::vector<const BernsteinSpace*>& spaces = columns.space;
  for (int k = 0; k < dim; ++k) {
    const Eigen::MatrixXd& d = columns.matrix[static_cast<std::size_t>(k)];
    t->derivative.push_back(d);
    t->derivativeNorm.push_back(d.cwiseAbs().rowwise().sum().maxCoeff());
    // Exact rows sum to zero (a constant has no derivative): what they sum to measures the
    // tables' own rounding, relative to the row norms; four times it is allowed for.
    t->derivativeError.push_back(4.0 * d.rowwise().sum().cwiseAbs().maxCoeff() /
                                 t->derivativeNorm.back());
  }
  const BernsteinSpace& innerA = dim == 3 ? *spaces[1] : *spaces[0];
  const BernsteinSpace& innerB = dim == 3 ? *spaces[2] : *spaces[1];
  t->inner = &innerA.productTerms(innerB);
  const BernsteinSpace& innerSpace =
      BernsteinSpace::get(BernsteinSpace::productFactors(innerA.factors(), innerB.factors()));
  t->innerSize = innerSpace.size();
  const BernsteinSpace* jacobian = &innerSpace;
  if (dim == 3) {
    t->outer = &spaces[0]->productTerms(innerSpace);
    jacobian = &BernsteinSpace::get(
        BernsteinSpace::productFactors(spaces[0]->factors(), innerSpace.factors()));
  }
  t->jacobianSize = jacobian->size();
  t->jacobian = jacobian;
  const auto mostTerms = [](const BezierTables::Terms* terms, int size) {
    std::vector<int> count(static_cast<std::size_t>(size), 0);
    for (const auto& term : *terms) ++count[static_cast<std::size_t>(term.c)];
    return *std::max_element(count.begin(), count.end());
  };
  t->maxTerms =
      mostTerms(t->inner, t->innerSize) + (dim == 3 ? mostTerms(t->outer, t->jacobianSize) : 0);
  t->cornerOffsets = cornerOffsets(jacobian->factors());
  for (int j = 0; j < jacobian->size(); ++j)
    if (jacobian->isCorner(j)) t->corners.push_back(j);
  return t;
}

const BezierTables& tables(CellType type, int order) {
  static CellTableCache<BezierTables> cache;
  return cache.get(type, order, [&] { return buildTables(type, order); });
}

// Bezier coefficients of J on the whole element for nodal coordinates x.
// What the coefficients' computation knows of its own accuracy.
struct Rounding {
  double error = 0.0;  // a bound on the rounding error of every coefficient
  double size = 0.0;   // the element's extent (largest centred coordinate)
};

Rounding jacobianCoefficients(const BezierTables& t, const NodeCoordinates& x,
                              const Eigen::Vector3d* normal, Eigen::VectorXd& out) {
  // J does not change when the element moves; centred coordinates keep the products' rounding
  // proportional to the element's size, not to its distance from the origin.
  thread_local NodeCoordinates centred;
  centred = x.rowwise() - x.row(0);
  std::array<NodeCoordinates, 3> d;
  for (int k = 0; k < t.dim; ++k) d[k].noalias() = t.derivative[k].lazyProduct(centred);
  // Rounding (Higham's gamma_n bounds): each entry of d_k is a sum of n products, off by at most
  // gamma * |D_k| |x|, plus the tables' own error (estimated when they were built); the product
  // sums add gamma_m * |terms|, and the Bernstein product weights into one coefficient sum to 1.
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const double size = centred.cwiseAbs().maxCoeff();
  const double gammaD = (static_cast<double>(x.rows()) + 16.0) * eps;
  std::array<double, 3> m{}, delta{};
  for (int k = 0; k < t.dim; ++k) {
    delta[k] = (gammaD + t.derivativeError[k]) * t.derivativeNorm[k] * size;
    m[k] = d[k].cwiseAbs().maxCoeff() + delta[k];
  }
  const double gammaP = (t.maxTerms + 10.0) * eps;
  const double error =
      t.dim == 3
          ? 6.0 * (delta[0] * m[1] * m[2] + m[0] * delta[1] * m[2] + m[0] * m[1] * delta[2]) +
                gammaP * 6.0 * m[0] * m[1] * m[2]
          : 2.0 * (delta[0] * m[1] + m[0] * delta[1]) + gammaP * 2.0 * m[0] * m[1];
  const NodeCoordinates& p = t.dim == 3 ? d[1] : d[0];
  const NodeCoordinates& q = t.dim == 3 ? d[2] : d[1];
  NodeCoordinates cross = NodeCoordinates::Zero(t.innerSize, 3);
  for (const BernsteinSpace::ProductTerm& term : *t.inner) {
    const double w = term.weight;
    cross(term.c, 0) += w * (p(term.a, 1) * q(term.b, 2) - p(term.a, 2) * q(term.b, 1));
    cross(term.c, 1) += w * (p(term.a, 2) * q(term.b, 0) - p(term.a, 0) * q(term.b, 2));
    cross(term.c, 2) += w * (p(term.a, 0) * q(term.b, 1) - p(term.a, 1) * q(term.b, 0));
  }
  if (t.dim == 2) {
    if (normal == nullptr) throw Error("Bezier bounds of a 2D cell need its plane normal");
    out = cross * *normal;
    return {error * std::max(1.0, normal->lpNorm<1>()), size};
  }
  out.setZero(t.jacobianSize);
  for (const BernsteinSpace::ProductTerm& term : *t.outer)
    out(term.c) += term.weight * d[0].row(term.a).dot(cross.row(term.b));
  return {error, size};
}

// The edge a part is split across: the longest of its factors' simplex edges, in reference
// coordinates (longest-edge bisection keeps the parts well shaped as they shrink).
const BernsteinSpace::EdgeLines& longestEdge(const BezierTables& t, const Corners& v) {
  const auto& edges = t.jacobian->edgeLines();
  const BernsteinSpace::EdgeLines* best = &edges.front();
  double bestLength = -1.0;
  for (const auto& e : edges) {
    const int d = t.jacobian->factors()[e.factor].first;
    const double* p = &v[t.cornerOffsets[e.factor]];
    double length = 0.0;
    for (int k = 0; k < d; ++k) length += std::pow(p[e.i * d + k] - p[e.j * d + k], 2);
    if (length > bestLength + 1e-12) {
      bestLength = length;
      best = &e;
    }
  }
  return *best;
}

}  // namespace

JacobianBounds boundJacobian(CellType type, int order, const NodeCoordinates& x,
                             const Eigen::Vector3d* normal, double tolerance) {
  const BezierTables& t = tables(type, order);
  JacobianBounds b;
  if (!x.allFinite()) {  // nothing can be proven about an element with undefined nodes
    b.minLower = b.minUpper = b.maxLower = b.maxUpper = std::numeric_limits<double>::quiet_NaN();
    b.validity = Validity::Undecided;
    b.certified = false;
    return b;
  }
  struct Part {
    Eigen::VectorXd coeffs;  // J's Bezier coefficients on the part
    Corners corners;         // the part's vertices (see Corners)
    int depth;
    double lo, hi;  // bounds of J on the part: its extreme coefficients
  };
  // Extreme values of J found so far: true values, so the minimum lies in [lower bound, found].
  double minFound = std::numeric_limits<double>::infinity();
  double maxFound = -std::numeric_limits<double>::infinity();
  std::vector<Part> parts;
  const auto add = [&](Eigen::VectorXd coeffs, const Corners& corners, int depth) {
    for (const int c : t.corners) {  // corner coefficients are values of J
      minFound = std::min(minFound, coeffs(c));
      maxFound = std::max(maxFound, coeffs(c));
    }
    const double lo = coeffs.minCoeff(), hi = coeffs.maxCoeff();
    parts.push_back({std::move(coeffs), corners, depth, lo, hi});
  };
  Eigen::VectorXd whole;
  // Every coefficient, and so every bound and found value, is within `margin` of its exact
  // value: the products' rounding, plus one rounding per de Casteljau level.
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const Rounding rounding = jacobianCoefficients(t, x, normal, whole);
  const double margin =
      rounding.error + 4.0 * kMaxDepth * t.dim * eps * whole.cwiseAbs().maxCoeff();
  add(std::move(whole), referenceCorners(t.jacobian->factors()), 0);
  // Best first (Johnen et al.): always split the part with the lowest lower bound (then the
  // highest upper bound) until that bound is within the tolerance of the extreme value found
  // and the sign of J is decided, or the subdivision budget is spent. A split is a de Casteljau
  // bisection of the part's coefficients: no geometry is evaluated again.
  // The budget also bounds the memory: every open part keeps its coefficients.
  int budget = std::min(kMaxSubdivisions, std::max(1, kMaxCoefficients / t.jacobianSize));
  const int maxDepth = kMaxDepth * t.dim;
  const auto refine = [&](auto worse, auto open) {
    std::make_heap(parts.begin(), parts.end(), worse);
    while (budget > 0) {
      const double tol = tolerance * std::max({std::abs(minFound), std::abs(maxFound), 1e-300});
      const Part& top = parts.front();
      if (!open(top, tol) || top.depth >= maxDepth) break;
      std::pop_heap(parts.begin(), parts.end(), worse);
      Part parent = std::move(parts.back());
      parts.pop_back();
      --budget;
      const BernsteinSpace::EdgeLines& edge = longestEdge(t, parent.corners);
      Eigen::VectorXd keepJ(t.jacobianSize), keepI(t.jacobianSize);
      BernsteinSpace::bisect(edge, parent.coeffs.data(), keepJ.data(), keepI.data());
      const int d = t.jacobian->factors()[edge.factor].first;
      Corners cornersJ = parent.corners, cornersI = parent.corners;
      double* vi = &cornersJ[t.cornerOffsets[edge.factor] + edge.i * d];
      double* vj = &cornersI[t.cornerOffsets[edge.factor] + edge.j * d];
      const double* pi = &parent.corners[t.cornerOffsets[edge.factor] + edge.i * d];
      const double* pj = &parent.corners[t.cornerOffsets[edge.factor] + edge.j * d];
      for (int k = 0; k < d; ++k) vi[k] = vj[k] = 0.5 * (pi[k] + pj[k]);
      add(std::move(keepJ), cornersJ, parent.depth + 1);
      std::push_heap(parts.begin(), parts.end(), worse);
      add(std::move(keepI), cornersI, parent.depth + 1);
      std::push_heap(parts.begin(), parts.end(), worse);
    }
  };
  refine([](const Part& p, const Part& q) { return p.lo > q.lo; },
         [&](const Part& p, double tol) {
           return p.lo < minFound - tol || (p.lo <= margin && minFound > margin);
         });
  refine([](const Part& p, const Part& q) { return p.hi < q.hi; },
         [&](const Part& p, double tol) {
           return p.hi > maxFound + tol || (p.hi >= -margin && maxFound < -margin);
         });
  double lowest = minFound, highest = maxFound;
  for (const Part& p : parts) {
    lowest = std::min(lowest, p.lo);
    highest = std::max(highest, p.hi);
  }
  // Widened by the rounding margin, these hold the exact extremes of J.
  b.minLower = lowest - margin;
  b.minUpper = minFound + margin;
  b.maxLower = maxFound - margin;
  b.maxUpper = highest + margin;
  b.certified = true;
  // Flat: J is proven below 1e-10 of the element's size to the power d everywhere.
  const bool flat = b.maxUpper <= 1e-10 * std::pow(rounding.size, t.dim);
  if (b.minLower > 0.0)
    b.validity = Validity::Valid;
  else if (b.minUpper < 0.0 || flat)
    b.validity = Validity::Invalid;
  else
    b.validity = Validity::Undecided;  // undecided within the budget, or lost in rounding
  return b;
}

}  // namespace homesh
