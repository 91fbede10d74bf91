#include "element/orthogonal_basis.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace homesh {
namespace {

// A value with its gradient in D reference coordinates (forward-mode differentiation).
template <int D>
struct Dual {
  double v = 0.0;
  std::array<double, D> g{};

  static Dual constant(double c) {
    Dual d;
    d.v = c;
    return d;
  }
  // The affine function c0 + sum_k c[k] x_k.
  static Dual affine(double c0, const std::array<double, D>& c) {
    Dual d;
    d.v = c0;
    d.g = c;
    return d;
  }
  // The function evaluated at point x (value only differs).
  Dual& at(const double* x) {
    for (int k = 0; k < D; ++k) v += g[k] * x[k];
    return *this;
  }
};

template <int D>
Dual<D> operator+(Dual<D> a, const Dual<D>& b) {
  a.v += b.v;
  for (int k = 0; k < D; ++k) a.g[k] += b.g[k];
  return a;
}
template <int D>
Dual<D> operator-(Dual<D> a, const Dual<D>& b) {
  a.v -= b.v;
  for (int k = 0; k < D; ++k) a.g[k] -= b.g[k];
  return a;
}
template <int D>
Dual<D> operator*(double s, Dual<D> a) {
  a.v *= s;
  for (int k = 0; k < D; ++k) a.g[k] *= s;
  return a;
}
template <int D>
Dual<D> operator/(const Dual<D>& a, const Dual<D>& b) {
  Dual<D> r;
  r.v = a.v / b.v;
  for (int k = 0; k < D; ++k) r.g[k] = (a.g[k] - r.v * b.g[k]) / b.v;
  return r;
}
template <int D>
Dual<D> operator*(const Dual<D>& a, const Dual<D>& b) {
  Dual<D> r;
  r.v = a.v * b.v;
  for (int k = 0; k < D; ++k) r.g[k] = a.g[k] * b.v + a.v * b.g[k];
  return r;
}

// Q_n = s^n P_n^{(alpha,0)}(X / s) for n = 0..n_max, by the scaled Jacobi recurrence.
template <int D>
std::vector<Dual<D>> scaledJacobi(int nMax, double alpha, const Dual<D>& x, const Dual<D>& s) {
  std::vector<Dual<D>> q;
  q.reserve(nMax + 1);
  q.push_back(Dual<D>::constant(1.0));
  if (nMax >= 1) q.push_back(0.5 * ((alpha + 2.0) * x + alpha * s));
  const Dual<D> s2 = s * s;
  for (int n = 1; n < nMax; ++n) {
    const double c = 2.0 * n + alpha;
    const double c0 = 2.0 * (n + 1) * (n + alpha + 1) * c;
    const double c1 = c + 1.0;
    const double c2 = (c + 2.0) * c;
    const double c3 = alpha * alpha;
    const double c4 = 2.0 * (n + alpha) * n * (c + 2.0);
    q.push_back((1.0 / c0) * ((c1 * (c2 * x + c3 * s)) * q[n] - c4 * (s2 * q[n - 1])));
  }
  return q;
}

template <int D>
void store(const std::vector<Dual<D>>& funcs, Eigen::VectorXd& values, Eigen::MatrixXd& grads) {
  const int n = static_cast<int>(funcs.size());
  values.resize(n);
  grads.resize(n, D);
  for (int i = 0; i < n; ++i) {
    values(i) = funcs[i].v;
    for (int k = 0; k < D; ++k) grads(i, k) = funcs[i].g[k];
  }
}

void lineBasis(int p, const double* xi, Eigen::VectorXd& values, Eigen::MatrixXd& grads) {
  using D1 = Dual<1>;
  D1 x = D1::affine(-1.0, {2.0});  // 2 xi - 1
  x.at(xi);
  store<1>(scaledJacobi<1>(p, 0.0, x, D1::constant(1.0)), values, grads);
}

void triangleBasis(int p, const double* xi, Eigen::VectorXd& values, Eigen::MatrixXd& grads) {
  using D2 = Dual<2>;
  D2 au = D2::affine(-1.0, {2.0, 1.0});  // a u = 2x + y - 1
  D2 u = D2::affine(1.0, {0.0, -1.0});   // u = 1 - y
  D2 b = D2::affine(-1.0, {0.0, 2.0});   // b = 2y - 1
  au.at(xi);
  u.at(xi);
  b.at(xi);
  const auto qi = scaledJacobi<2>(p, 0.0, au, u);
  std::vector<D2> funcs;
  for (int i = 0; i <= p; ++i) {
    const auto rj = scaledJacobi<2>(p - i, 2.0 * i + 1.0, b, D2::constant(1.0));
    for (int j = 0; i + j <= p; ++j) funcs.push_back(qi[i] * rj[j]);
  }
  store<2>(funcs, values, grads);
}

void tetrahedronBasis(int p, const double* xi, Eigen::VectorXd& values, Eigen::MatrixXd& grads) {
  using D3 = Dual<3>;
  D3 au = D3::affine(-1.0, {2.0, 1.0, 1.0});  // a u = 2x + y + z - 1
  D3 u = D3::affine(1.0, {0.0, -1.0, -1.0});  // u = 1 - y - z
  D3 bv = D3::affine(-1.0, {0.0, 2.0, 1.0});  // b v = 2y + z - 1
  D3 v = D3::affine(1.0, {0.0, 0.0, -1.0});   // v = 1 - z
  D3 c = D3::affine(-1.0, {0.0, 0.0, 2.0});   // c = 2z - 1
  for (D3* d : {&au, &u, &bv, &v, &c}) d->at(xi);
  const auto qi = scaledJacobi<3>(p, 0.0, au, u);
  std::vector<D3> funcs;
  for (int i = 0; i <= p; ++i) {
    const auto rj = scaledJacobi<3>(p - i, 2.0 * i + 1.0, bv, v);
    for (int j = 0; i + j <= p; ++j) {
      const auto sk = scaledJacobi<3>(p - i - j, 2.0 * (i + j) + 2.0, c, D3::constant(1.0));
      const D3 qr = qi[i] * rj[j];
      for (int k = 0; i + j + k <= p; ++k) funcs.push_back(qr * sk[k]);
    }
  }
  store<3>(funcs, values, grads);
}

void quadrilateralBasis(int p, const double* xi, Eigen::VectorXd& values, Eigen::MatrixXd& grads) {
  using D2 = Dual<2>;
  D2 x = D2::affine(-1.0, {2.0, 0.0});
  D2 y = D2::affine(-1.0, {0.0, 2.0});
  x.at(xi);
  y.at(xi);
  const auto px = scaledJacobi<2>(p, 0.0, x, D2::constant(1.0));
  const auto py = scaledJacobi<2>(p, 0.0, y, D2::constant(1.0));
  std::vector<D2> funcs;
  for (int j = 0; j <= p; ++j)
    for (int i = 0; i <= p; ++i) funcs.push_back(px[i] * py[j]);
  store<2>(funcs, values, grads);
}

void hexahedronBasis(int p, const double* xi, Eigen::VectorXd& values, Eigen::MatrixXd& grads) {
  using D3 = Dual<3>;
  D3 x = D3::affine(-1.0, {2.0, 0.0, 0.0});
  D3 y = D3::affine(-1.0, {0.0, 2.0, 0.0});
  D3 z = D3::affine(-1.0, {0.0, 0.0, 2.0});
  for (D3* d : {&x, &y, &z}) d->at(xi);
  const auto px = scaledJacobi<3>(p, 0.0, x, D3::constant(1.0));
  const auto py = scaledJacobi<3>(p, 0.0, y, D3::constant(1.0));
  const auto pz = scaledJacobi<3>(p, 0.0, z, D3::constant(1.0));
  std::vector<D3> funcs;
  for (int k = 0; k <= p; ++k)
    for (int j = 0; j <= p; ++j) {
      const D3 yz = py[j] * pz[k];
      for (int i = 0; i <= p; ++i) funcs.push_back(px[i] * yz);
    }
  store<3>(funcs, values, grads);
}

void prismBasis(int p, const double* xi, Eigen::VectorXd& values, Eigen::MatrixXd& grads) {
  using D3 = Dual<3>;
  D3 au = D3::affine(-1.0, {2.0, 1.0, 0.0});  // a u = 2x + y - 1 (triangle factor)
  D3 u = D3::affine(1.0, {0.0, -1.0, 0.0});   // u = 1 - y
  D3 b = D3::affine(-1.0, {0.0, 2.0, 0.0});   // b = 2y - 1
  D3 z = D3::affine(-1.0, {0.0, 0.0, 2.0});
  for (D3* d : {&au, &u, &b, &z}) d->at(xi);
  const auto qi = scaledJacobi<3>(p, 0.0, au, u);
  const auto pz = scaledJacobi<3>(p, 0.0, z, D3::constant(1.0));
  std::vector<D3> funcs;
  for (int k = 0; k <= p; ++k)
    for (int i = 0; i <= p; ++i) {
      const auto rj = scaledJacobi<3>(p - i, 2.0 * i + 1.0, b, D3::constant(1.0));
      for (int j = 0; i + j <= p; ++j) funcs.push_back(qi[i] * rj[j] * pz[k]);
    }
  store<3>(funcs, values, grads);
}

// Bergot, Cohen and Durufle's basis ("Higher-order finite elements for hybrid meshes using new
// nodal pyramidal elements", J. Sci. Comput. 2010), which Gmsh's pyramids use:
// P_i(xi) P_j(eta) s^max(i,j) P_k^(2 max(i,j) + 2, 0)(2z - 1) for 0 <= i, j <= p and
// 0 <= k <= p - max(i,j), with s = 1 - z and xi, eta the base's coordinates scaled to [-1, 1] at
// every level: X / s and Y / s, X = 2x - s and Y = 2y - s. P_i(xi) s^i is the scaled Legendre
// polynomial q_i(X, s), so a function is q_i q_j / s^min(i,j) times a polynomial in z: a
// polynomial where i or j is 0, rational otherwise (x y / (1 - z) at order 1). The space holds
// every polynomial of degree p, is Q_p on the base and P_p on the triangles, so pyramids conform
// to hexahedra, prisms and tetrahedra. At the apex (s = 0) a rational function, homogeneous of
// degree max(i,j) >= 1 in (X, Y, s), is 0, and so are its derivatives for max(i,j) >= 2; for
// i = j = 1 they depend on the direction the apex is approached from, and the value given is
// their limit along the axis (0), where the base's centre rises to the apex.
void pyramidBasis(int p, const double* xi, Eigen::VectorXd& values, Eigen::MatrixXd& grads) {
  using D3 = Dual<3>;
  D3 s = D3::affine(1.0, {0.0, 0.0, -1.0});  // s = 1 - z
  D3 x = D3::affine(-1.0, {2.0, 0.0, 1.0});  // X = 2x - s
  D3 y = D3::affine(-1.0, {0.0, 2.0, 1.0});  // Y = 2y - s
  D3 c = D3::affine(-1.0, {0.0, 0.0, 2.0});  // 2z - 1
  for (D3* d : {&s, &x, &y, &c}) d->at(xi);
  const bool apex = !(s.v > 0.0) && !(s.v < 0.0);
  const auto qx = scaledJacobi<3>(p, 0.0, x, s);
  const auto qy = scaledJacobi<3>(p, 0.0, y, s);
  std::vector<D3> funcs;
  for (int i = 0; i <= p; ++i)
    for (int j = 0; j <= p; ++j) {
      const int high = std::max(i, j), low = std::min(i, j);
      D3 base = qx[static_cast<std::size_t>(i)] * qy[static_cast<std::size_t>(j)];
      if (low > 0) {
        if (apex) {
          base = D3::constant(0.0);
        } else {
          D3 power = s;
          for (int e = 1; e < low; ++e) power = power * s;
          base = base / power;
        }
      }
      const auto rk = scaledJacobi<3>(p - high, 2.0 * high + 2.0, c, D3::constant(1.0));
      for (const D3& r : rk) funcs.push_back(base * r);
    }
  store<3>(funcs, values, grads);
}

}  // namespace

void orthogonalBasis(CellType type, int order, const double* xi, Eigen::VectorXd& values,
                     Eigen::MatrixXd& gradients) {
  if (order < 0) throw ParameterError("basis order must be >= 0");
  switch (type) {
    case CellType::Line:
      return lineBasis(order, xi, values, gradients);
    case CellType::Triangle:
      return triangleBasis(order, xi, values, gradients);
    case CellType::Tetrahedron:
      return tetrahedronBasis(order, xi, values, gradients);
    case CellType::Quadrilateral:
      return quadrilateralBasis(order, xi, values, gradients);
    case CellType::Hexahedron:
      return hexahedronBasis(order, xi, values, gradients);
    case CellType::Prism:
      return prismBasis(order, xi, values, gradients);
    case CellType::Pyramid:
      return pyramidBasis(order, xi, values, gradients);
    default:
      throw ParameterError("no polynomial basis for " + cellShortName(type));
  }
}

}  // namespace homesh
