#include "element/node_sets.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <string>

#include "core/error.hpp"
#include "element/quadrature.hpp"

namespace homesh {

std::vector<double> gllPoints(int n) {
  if (n < 1) throw ParameterError("GLL points need n >= 1");
  std::vector<double> points{0.0};
  if (n >= 2) {  // interior GLL points: the Gauss-Jacobi(1, 1) points
    std::vector<double> x, w;
    gaussJacobi(n - 1, 1.0, 1.0, x, w);
    for (const double xi : x) points.push_back(0.5 * (xi + 1.0));
  }
  points.push_back(1.0);
  return points;
}

namespace {

// Interpolates the displacement of GLL from equispaced points on [-1, 1] at r and divides it by
// 1 - r^2 (Warburton's warp factor); 0 at the end points.
double warpFactor(int n, double r) {
  if (std::abs(r) >= 1.0 - 1e-12) return 0.0;
  const std::vector<double> gll = gllPoints(n);
  double warp = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double xi = -1.0 + 2.0 * i / n;
    double lagrange = 1.0;
    for (int j = 0; j <= n; ++j)
      if (j != i) lagrange *= (r - (-1.0 + 2.0 * j / n)) / (xi - (-1.0 + 2.0 * j / n));
    warp += (2.0 * gll[i] - 1.0 - xi) * lagrange;
  }
  return warp / (1.0 - r * r);
}

// Warburton's optimised blending exponents for orders 1..15 (2D and 3D).
double alpha2d(int n) {
  static const double a[] = {0.0,    0.0,    1.4152, 0.1001, 0.2751, 0.9800, 1.0999, 1.2832,
                             1.3648, 1.4773, 1.4959, 1.5743, 1.5770, 1.6223, 1.6258};
  return n <= 15 ? a[n - 1] : 5.0 / 3.0;
}
double alpha3d(int n) {
  static const double a[] = {0.0,    0.0,     0.0,    0.1002, 1.1332, 1.5608, 1.3413, 1.2577,
                             1.1603, 1.10153, 0.6080, 0.4523, 0.8856, 0.8717, 0.9655};
  return n <= 15 ? a[n - 1] : 1.0;
}

// The warp & blend displacement of a triangle point with barycentric coordinates l (one per
// vertex, summing to 1 on the triangle) whose vertices, an equilateral triangle of side 2, sit at
// p[0..2] (in 2D or 3D): each edge pushes its points towards the GLL distribution along it,
// blended to zero at the opposite vertex.
template <int D>
Eigen::Matrix<double, D, 1> triangleWarp(int n, double alpha, const double l[3],
                                         const Eigen::Matrix<double, D, 1> p[3]) {
  Eigen::Matrix<double, D, 1> shift = Eigen::Matrix<double, D, 1>::Zero();
  for (int e = 0; e < 3; ++e) {
    const int a = e, b = (e + 1) % 3, c = (e + 2) % 3;
    const double warp =
        4.0 * l[a] * l[b] * warpFactor(n, l[b] - l[a]) * (1.0 + (alpha * l[c]) * (alpha * l[c]));
    shift += warp * (p[b] - p[a]).normalized();
  }
  return shift;
}

// Warp & blend nodes of the unit triangle, by lattice point (i, j).
std::map<LatticePoint, Eigen::Vector2d> warpBlendTriangle(int n) {
  const Eigen::Vector2d p[3] = {
      {-1.0, -1.0 / std::sqrt(3.0)}, {1.0, -1.0 / std::sqrt(3.0)}, {0.0, 2.0 / std::sqrt(3.0)}};
  // Barycentric coordinates from a point of the equilateral triangle.
  Eigen::Matrix3d toBary;
  toBary << p[0].x(), p[1].x(), p[2].x(), p[0].y(), p[1].y(), p[2].y(), 1, 1, 1;
  const Eigen::Matrix3d fromPoint = toBary.inverse();
  std::map<LatticePoint, Eigen::Vector2d> nodes;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i + j <= n; ++i) {
      const double l[3] = {static_cast<double>(n - i - j) / n, static_cast<double>(i) / n,
                           static_cast<double>(j) / n};
      const Eigen::Vector2d x =
          l[0] * p[0] + l[1] * p[1] + l[2] * p[2] + triangleWarp<2>(n, alpha2d(n), l, p);
      const Eigen::Vector3d bary = fromPoint * Eigen::Vector3d(x.x(), x.y(), 1.0);
      nodes[{i, j, 0}] = {bary[1], bary[2]};
    }
  return nodes;
}

// Warp & blend nodes of the unit tetrahedron, by lattice point (i, j, k). Each face carries the
// triangle's warp (with the triangle's exponent, so that faces match triangles), blended into
// the interior with the 3D exponent.
std::map<LatticePoint, Eigen::Vector3d> warpBlendTetrahedron(int n) {
  const double s3 = std::sqrt(3.0), s6 = std::sqrt(6.0);
  const Eigen::Vector3d v[4] = {{-1.0, -1.0 / s3, -1.0 / s6},
                                {1.0, -1.0 / s3, -1.0 / s6},
                                {0.0, 2.0 / s3, -1.0 / s6},
                                {0.0, 0.0, 3.0 / s6}};
  Eigen::Matrix4d toBary;
  for (int c = 0; c < 4; ++c) toBary.col(c) << v[c], 1.0;
  const Eigen::Matrix4d fromPoint = toBary.inverse();
  const double a3 = alpha3d(n), a2 = alpha2d(n), tol = 1e-10;
  std::map<LatticePoint, Eigen::Vector3d> nodes;
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j + k <= n; ++j)
      for (int i = 0; i + j + k <= n; ++i) {
        const double l[4] = {static_cast<double>(n - i - j - k) / n, static_cast<double>(i) / n,
                             static_cast<double>(j) / n, static_cast<double>(k) / n};
        Eigen::Vector3d x = Eigen::Vector3d::Zero();
        for (int c = 0; c < 4; ++c) x += l[c] * v[c];
        Eigen::Vector3d shift = Eigen::Vector3d::Zero();
        for (int opposite = 0; opposite < 4; ++opposite) {
          int f[3], m = 0;
          for (int c = 0; c < 4; ++c)
            if (c != opposite) f[m++] = c;
          const double la = l[opposite];
          const double lf[3] = {l[f[0]], l[f[1]], l[f[2]]};
          const Eigen::Vector3d pf[3] = {v[f[0]], v[f[1]], v[f[2]]};
          const Eigen::Vector3d warp = triangleWarp<3>(n, a2, lf, pf);
          if (la < tol) {
            // On the face: exactly the triangle's warp (on an edge, both faces give the same).
            shift = warp;
            continue;
          }
          const double denom = (lf[0] + 0.5 * la) * (lf[1] + 0.5 * la) * (lf[2] + 0.5 * la);
          if (denom < tol) continue;
          shift += (1.0 + (a3 * la) * (a3 * la)) * lf[0] * lf[1] * lf[2] / denom * warp;
        }
        x += shift;
        const Eigen::Vector4d bary = fromPoint * Eigen::Vector4d(x.x(), x.y(), x.z(), 1.0);
        nodes[{i, j, k}] = {bary[1], bary[2], bary[3]};
      }
  return nodes;
}

}  // namespace

Eigen::MatrixXd nodeCoordinates(CellType type, int order, NodeSet set,
                                const std::vector<LatticePoint>& lattice) {
  const int dim = cellDimension(type);
  const int n = order;
  Eigen::MatrixXd xi(static_cast<Eigen::Index>(lattice.size()), dim);
  if (set == NodeSet::Equispaced) {
    for (std::size_t r = 0; r < lattice.size(); ++r)
      for (int k = 0; k < dim; ++k) xi(static_cast<Eigen::Index>(r), k) = double(lattice[r][k]) / n;
    return xi;
  }
  const std::vector<double> gll = gllPoints(n);
  std::map<LatticePoint, Eigen::Vector2d> tri;
  std::map<LatticePoint, Eigen::Vector3d> tet;
  if (type == CellType::Triangle || type == CellType::Prism) tri = warpBlendTriangle(n);
  if (type == CellType::Tetrahedron) tet = warpBlendTetrahedron(n);
  for (std::size_t r = 0; r < lattice.size(); ++r) {
    const LatticePoint& c = lattice[r];
    const auto row = static_cast<Eigen::Index>(r);
    switch (type) {
      case CellType::Line:
      case CellType::Quadrilateral:
      case CellType::Hexahedron:
        for (int k = 0; k < dim; ++k) xi(row, k) = gll[c[k]];
        break;
      case CellType::Triangle:
        xi.row(row) = tri.at({c[0], c[1], 0}).transpose();
        break;
      case CellType::Prism:
        xi.row(row) << tri.at({c[0], c[1], 0}).transpose(), gll[c[2]];
        break;
      case CellType::Tetrahedron:
        xi.row(row) = tet.at(c).transpose();
        break;
      default:
        throw ParameterError("no node set for " + cellShortName(type));
    }
  }
  return xi;
}

}  // namespace homesh
