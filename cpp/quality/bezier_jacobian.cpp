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

constexpr int kMaxDepth = 12;
constexpr int kMaxSubdivisions = 1000;

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

// An affine part of the reference shape: xi = origin + map * local.
struct Domain {
  Eigen::VectorXd origin;
  Eigen::MatrixXd map;
};

Domain simplexDomain(const std::vector<Eigen::VectorXd>& v) {
  Domain d;
  d.origin = v[0];
  d.map.resize(v[0].size(), static_cast<Eigen::Index>(v.size()) - 1);
  for (std::size_t k = 1; k < v.size(); ++k)
    d.map.col(static_cast<Eigen::Index>(k) - 1) = v[k] - v[0];
  return d;
}

// Regular refinement of a triangle (4 parts) or tetrahedron (8 parts, octahedron split along
// the diagonal between the midpoints of edges 02 and 13).
std::vector<std::vector<Eigen::VectorXd>> splitSimplex(const std::vector<Eigen::VectorXd>& w) {
  const auto mid = [&](int a, int b) { return Eigen::VectorXd(0.5 * (w[a] + w[b])); };
  if (w.size() == 3) {
    const auto m01 = mid(0, 1), m12 = mid(1, 2), m20 = mid(2, 0);
    return {{w[0], m01, m20}, {m01, w[1], m12}, {m20, m12, w[2]}, {m12, m20, m01}};
  }
  const auto m01 = mid(0, 1), m02 = mid(0, 2), m03 = mid(0, 3), m12 = mid(1, 2), m13 = mid(1, 3),
             m23 = mid(2, 3);
  return {{w[0], m01, m02, m03}, {m01, w[1], m12, m13}, {m02, m12, w[2], m23},
          {m03, m13, m23, w[3]}, {m01, m02, m03, m13},  {m01, m02, m12, m13},
          {m02, m03, m13, m23},  {m02, m12, m13, m23}};
}

// The parts of the reference shape one subdivision step makes.
std::vector<Domain> subdomains(CellType type) {
  const int dim = cellDimension(type);
  std::vector<Domain> out;
  if (type == CellType::Triangle || type == CellType::Tetrahedron) {
    std::vector<Eigen::VectorXd> w{Eigen::VectorXd::Zero(dim)};
    for (int k = 0; k < dim; ++k) w.push_back(Eigen::VectorXd::Unit(dim, k));
    for (const auto& part : splitSimplex(w)) out.push_back(simplexDomain(part));
  } else if (type == CellType::Quadrilateral || type == CellType::Hexahedron) {
    for (int c = 0; c < (1 << dim); ++c) {
      Domain d;
      d.origin = Eigen::VectorXd::Zero(dim);
      d.map = 0.5 * Eigen::MatrixXd::Identity(dim, dim);
      for (int k = 0; k < dim; ++k)
        if ((c & (1 << k)) != 0) d.origin(k) = 0.5;
      out.push_back(d);
    }
  } else {  // prism: the triangle's parts times the halves in z
    const std::vector<Eigen::VectorXd> w{Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0),
                                         Eigen::Vector2d(0, 1)};
    for (const auto& part : splitSimplex(w))
      for (const double z0 : {0.0, 0.5}) {
        Domain d;
        d.origin = Eigen::Vector3d(part[0].x(), part[0].y(), z0);
        d.map = Eigen::Matrix3d::Zero();
        d.map.block<2, 1>(0, 0) = part[1] - part[0];
        d.map.block<2, 1>(0, 1) = part[2] - part[0];
        d.map(2, 2) = 0.5;
        out.push_back(d);
      }
  }
  return out;
}

struct ProductTerm {
  int a, b, c;
  double weight;
};

// The (a, b) -> c terms of the product of two Bernstein spaces.
std::vector<ProductTerm> productTerms(const BernsteinSpace& sa, const BernsteinSpace& sb) {
  const BernsteinSpace& sc =
      BernsteinSpace::get(BernsteinSpace::productFactors(sa.factors(), sb.factors()));
  std::vector<ProductTerm> terms;
  terms.reserve(static_cast<std::size_t>(sa.size()) * sb.size());
  std::vector<int> flat(sc.dim());
  for (int i = 0; i < sa.size(); ++i)
    for (int j = 0; j < sb.size(); ++j) {
      for (int k = 0; k < sc.dim(); ++k) flat[k] = sa.multiIndex(i)[k] + sb.multiIndex(j)[k];
      const int c = sc.indexOf(flat);
      terms.push_back(
          {i, j, c, sa.multinomialWeight(i) * sb.multinomialWeight(j) / sc.multinomialWeight(c)});
    }
  return terms;
}

// Everything about a shape and order that does not depend on the element: J's Bezier
// coefficients are J = d0 . (d1 x d2) (or (d0 x d1) . n in 2D) with d_k = derivative[k] * x the
// control points of dx/dxi_k, multiplied term by term.
struct BezierTables {
  int dim = 3;
  std::vector<Eigen::MatrixXd> derivative;  // per k: (size of d_k's space) x nodes
  std::vector<ProductTerm> inner;           // d1 x d2 (3D) or d0 x d1 (2D)
  std::vector<ProductTerm> outer;           // d0 . (d1 x d2) (3D only)
  int innerSize = 0, jacobianSize = 0;
  std::vector<int> corners;                  // corner functions of J's space
  std::vector<Eigen::MatrixXd> childNodal;   // a part's nodal values = this * parent's
  std::vector<double> childDeterminant;      // det of the part's map
  std::unique_ptr<JacobianSampler> lattice;  // J at the Bezier points of J's space
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
  t->inner = productTerms(innerA, innerB);
  const BernsteinSpace& innerSpace =
      BernsteinSpace::get(BernsteinSpace::productFactors(innerA.factors(), innerB.factors()));
  t->innerSize = innerSpace.size();
  const BernsteinSpace* jacobian = &innerSpace;
  if (dim == 3) {
    t->outer = productTerms(*spaces[0], innerSpace);
    jacobian = &BernsteinSpace::get(
        BernsteinSpace::productFactors(spaces[0]->factors(), innerSpace.factors()));
  }
  t->jacobianSize = jacobian->size();
  Eigen::MatrixXd points(jacobian->size(), dim);
  for (int j = 0; j < jacobian->size(); ++j) {
    if (jacobian->isCorner(j)) t->corners.push_back(j);
    points.row(j) = jacobian->point(j).transpose();
  }
  t->lattice = std::make_unique<JacobianSampler>(ref, points);
  for (const Domain& d : subdomains(type)) {
    const Eigen::MatrixXd childPoints =
        (ref.nodes() * d.map.transpose()).rowwise() + d.origin.transpose();
    t->childNodal.push_back(ref.valuesAt(childPoints));
    t->childDeterminant.push_back(d.map.determinant());
  }
  slot = std::move(t);
  return *slot;
}

// Bezier coefficients of J for nodal coordinates x (in the element's current parametrisation).
void jacobianCoefficients(const BezierTables& t, const NodeCoordinates& x,
                          const Eigen::Vector3d* normal, Eigen::VectorXd& out) {
  std::array<NodeCoordinates, 3> d;
  for (int k = 0; k < t.dim; ++k) d[k].noalias() = t.derivative[k].lazyProduct(x);
  const NodeCoordinates& p = t.dim == 3 ? d[1] : d[0];
  const NodeCoordinates& q = t.dim == 3 ? d[2] : d[1];
  NodeCoordinates cross = NodeCoordinates::Zero(t.innerSize, 3);
  for (const ProductTerm& term : t.inner) {
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
  for (const ProductTerm& term : t.outer)
    out(term.c) += term.weight * d[0].row(term.a).dot(cross.row(term.b));
}

}  // namespace

JacobianBounds boundJacobian(CellType type, int order, const NodeCoordinates& x,
                             const Eigen::Vector3d* normal, double tolerance) {
  const BezierTables& t = tables(type, order);
  struct Part {
    NodeCoordinates x;
    double scale;  // J of the part's own parametrisation = scale * J of the element
    int depth;
    double lo, hi;  // bounds of J on the part: its extreme Bezier coefficients
  };
  // Values of J at the Bezier points of the whole element: first estimates of its extremes.
  Eigen::VectorXd values;
  t.lattice->jacobians(x, normal, values);
  double minFound = values.minCoeff(), maxFound = values.maxCoeff();
  std::vector<Part> parts;
  Eigen::VectorXd coeffs;
  const auto make = [&](NodeCoordinates px, double scale, int depth) {
    jacobianCoefficients(t, px, normal, coeffs);
    coeffs /= scale;
    for (const int c : t.corners) {  // corner coefficients are values of J
      minFound = std::min(minFound, coeffs(c));
      maxFound = std::max(maxFound, coeffs(c));
    }
    parts.push_back({std::move(px), scale, depth, coeffs.minCoeff(), coeffs.maxCoeff()});
  };
  make(x, 1.0, 0);
  // Best first (Johnen et al.): always split the part with the lowest lower bound (then the
  // highest upper bound) until that bound is within the tolerance of the extreme value found
  // and the sign of J is decided, or the subdivision budget is spent.
  int budget = kMaxSubdivisions;
  const auto refine = [&](auto worse, auto open) {
    std::make_heap(parts.begin(), parts.end(), worse);
    while (budget > 0) {
      const double tol = tolerance * std::max({std::abs(minFound), std::abs(maxFound), 1e-300});
      const Part& top = parts.front();
      if (!open(top, tol) || top.depth >= kMaxDepth) break;
      std::pop_heap(parts.begin(), parts.end(), worse);
      Part parent = std::move(parts.back());
      parts.pop_back();
      --budget;
      for (std::size_t c = 0; c < t.childNodal.size(); ++c) {
        make(t.childNodal[c].lazyProduct(parent.x), parent.scale * t.childDeterminant[c],
             parent.depth + 1);
        std::push_heap(parts.begin(), parts.end(), worse);
      }
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
