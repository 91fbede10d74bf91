#include "quality/bezier_jacobian.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "quality/bernstein.hpp"

namespace homesh {
namespace {

// Limits on the refinement of one element: bisections deep (times the dimension) and in all.
constexpr int kMaxDepth = 12;
constexpr int kMaxSubdivisions = 4000;

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
  const Terms* inner = nullptr;             // d1 x d2 (3D) or d0 x d1 (2D)
  const Terms* outer = nullptr;             // d0 . (d1 x d2) (3D only)
  int innerSize = 0, jacobianSize = 0;
  const BernsteinSpace* jacobian = nullptr;  // J's space
  std::vector<int> corners;                  // corner functions of J's space
  std::vector<int> cornerOffsets;            // per factor of J's space, into Corners
};

const BezierTables& tables(CellType type, int order) {
  static std::mutex mutex;
  static std::map<std::pair<CellType, int>, std::unique_ptr<BezierTables>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{type, order}];
  if (slot) return *slot;
  auto t = std::make_unique<BezierTables>();
  const ReferenceElement& ref = ReferenceElement::get(type, order);
  const int n = ref.numNodes(), dim = ref.dim();
  t->dim = dim;
  const BernsteinSpace& geometry = BernsteinSpace::get(geometryFactors(type, order));
  Eigen::MatrixXd b(n, n);  // Bernstein function j at node i
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd xi = ref.nodes().row(i).transpose();
    for (int j = 0; j < n; ++j) b(i, j) = geometry.basis(j, xi.data());
  }
  const Eigen::MatrixXd lagrangeToBezier = b.partialPivLu().inverse();
  std::vector<const BernsteinSpace*> spaces;
  for (int k = 0; k < dim; ++k) {
    // The derivative as a matrix on control points, composed with Lagrange-to-Bezier.
    Eigen::MatrixXd d(BernsteinSpace::get(geometry.derivativeFactors(k)).size(), n);
    for (int j = 0; j < n; ++j) d.col(j) = geometry.derivative(k, lagrangeToBezier.col(j));
    t->derivative.push_back(d);
    spaces.push_back(&BernsteinSpace::get(geometry.derivativeFactors(k)));
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
  t->cornerOffsets = cornerOffsets(jacobian->factors());
  for (int j = 0; j < jacobian->size(); ++j)
    if (jacobian->isCorner(j)) t->corners.push_back(j);
  slot = std::move(t);
  return *slot;
}

// Bezier coefficients of J on the whole element for nodal coordinates x.
void jacobianCoefficients(const BezierTables& t, const NodeCoordinates& x,
                          const Eigen::Vector3d* normal, Eigen::VectorXd& out) {
  std::array<NodeCoordinates, 3> d;
  for (int k = 0; k < t.dim; ++k) d[k].noalias() = t.derivative[k].lazyProduct(x);
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
    return;
  }
  out.setZero(t.jacobianSize);
  for (const BernsteinSpace::ProductTerm& term : *t.outer)
    out(term.c) += term.weight * d[0].row(term.a).dot(cross.row(term.b));
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
  jacobianCoefficients(t, x, normal, whole);
  add(std::move(whole), referenceCorners(t.jacobian->factors()), 0);
  // Best first (Johnen et al.): always split the part with the lowest lower bound (then the
  // highest upper bound) until that bound is within the tolerance of the extreme value found
  // and the sign of J is decided, or the subdivision budget is spent. A split is a de Casteljau
  // bisection of the part's coefficients: no geometry is evaluated again.
  int budget = kMaxSubdivisions;
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
  refine([](const Part& a, const Part& b) { return a.lo > b.lo; },
         [&](const Part& p, double tol) {
           return p.lo < minFound - tol || (p.lo <= 0.0 && minFound > 0.0);
         });
  refine([](const Part& a, const Part& b) { return a.hi < b.hi; },
         [&](const Part& p, double tol) {
           return p.hi > maxFound + tol || (p.hi >= 0.0 && maxFound < 0.0);
         });
  JacobianBounds b;
  b.minUpper = minFound;
  b.maxLower = maxFound;
  b.minLower = minFound;
  b.maxUpper = maxFound;
  for (const Part& p : parts) {
    b.minLower = std::min(b.minLower, p.lo);
    b.maxUpper = std::max(b.maxUpper, p.hi);
  }
  b.certified = true;
  if (b.minLower > 0.0)
    b.validity = Validity::Valid;
  else if (b.minUpper <= 0.0)
    b.validity = Validity::Invalid;
  else
    b.validity = Validity::Undecided;
  return b;
}

}  // namespace homesh
