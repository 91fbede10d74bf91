#include "io/nektar_curve_points.hpp"

#include <cstddef>
#include <vector>

#include "element/quadrature.hpp"
#include "io/nektar_expansion.hpp"
#include "io/nektar_format.hpp"

namespace homesh::nektar {
namespace {

using Point = Eigen::Vector3d;

// The n Gauss-Lobatto-Legendre points on [0, 1] (the ends and the Gauss-Jacobi(1, 1) points).
std::vector<double> lobattoPoints(int n) {
  std::vector<double> x, w;
  if (n > 2) gaussJacobi(n - 2, 1.0, 1.0, x, w);
  std::vector<double> t{0.0};
  for (const double z : x) t.push_back(0.5 * (z + 1.0));
  t.push_back(1.0);
  return t;
}

// Values at `to` of the polynomial through (from[k], v[k]) (Lagrange form).
Point interpolate(const std::vector<double>& from, const std::vector<Point>& v, double to) {
  Point sum = Point::Zero();
  for (std::size_t k = 0; k < from.size(); ++k) {
    double l = 1.0;
    for (std::size_t j = 0; j < from.size(); ++j)
      if (j != k) l *= (to - from[j]) / (from[k] - from[j]);
    sum += l * v[k];
  }
  return sum;
}

}  // namespace

void toEvenlySpaced(GeometrySections& g, int order, const std::string& path) {
  const std::size_t n = static_cast<std::size_t>(order) + 1;
  std::vector<double> even(n);
  for (std::size_t k = 0; k < n; ++k) even[k] = double(k) / order;
  const std::vector<double> lobatto = lobattoPoints(order + 1);
  // The polynomial through `v` at the GLL points, at the equispaced points.
  const auto resample = [&](const std::vector<Point>& v) {
    std::vector<Point> out;
    out.reserve(n);
    for (const double t : even) out.push_back(interpolate(lobatto, v, t));
    return out;
  };
  for (auto& [id, c] : g.edgeCurves) {
    if (c.type == kEvenlySpaced) continue;
    if (c.type != kGaussLobattoLegendre)
      failGeometry(path,
                   "edge " + std::to_string(id) + "'s curve has " + c.type + ", not supported");
    c.points = resample(c.points);
    c.type = kEvenlySpaced;
  }
  std::vector<int> dropped;
  for (auto& [id, c] : g.faceCurves) {
    if (c.type == kEvenlySpaced || c.type == kTriEvenlySpaced) continue;
    const bool quad = c.points.size() == n * n;
    if (quad && c.type == kGaussLobattoLegendre) {
      std::vector<Point> rows;  // the first direction resampled, row by row
      rows.reserve(n * n);
      for (std::size_t i = 0; i < n; ++i) {
        const auto from = c.points.begin() + static_cast<std::ptrdiff_t>(i * n);
        const std::vector<Point> row =
            resample(std::vector<Point>(from, from + static_cast<std::ptrdiff_t>(n)));
        rows.insert(rows.end(), row.begin(), row.end());
      }
      std::vector<Point> out(n * n);
      for (std::size_t j = 0; j < n; ++j) {
        std::vector<Point> column;
        column.reserve(n);
        for (std::size_t i = 0; i < n; ++i) column.push_back(rows[i * n + j]);
        const std::vector<Point> resampled = resample(column);
        for (std::size_t i = 0; i < n; ++i) out[i * n + j] = resampled[i];
      }
      c.points = std::move(out);
      c.type = kEvenlySpaced;
    } else if (!quad && c.type == "NodalTriElec" && hasTriElecPoints(order)) {
      const Eigen::MatrixXd& m = triElecToEvenlySpaced(order);
      if (c.points.size() != static_cast<std::size_t>(m.rows()))
        failGeometry(path, "face " + std::to_string(id) + "'s curve has " +
                               std::to_string(c.points.size()) + " points; a triangle of order " +
                               std::to_string(order) + " needs " + std::to_string(m.rows()));
      std::vector<Point> out(c.points.size(), Point::Zero());
      for (std::size_t r = 0; r < out.size(); ++r)
        for (std::size_t k = 0; k < out.size(); ++k)
          out[r] += m(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k)) * c.points[k];
      c.points = std::move(out);
      c.type = kTriEvenlySpaced;
    } else if (!quad && (c.type == "NodalTriElec" || c.type == "NodalTriFekete")) {
      dropped.push_back(id);
    } else {
      failGeometry(path,
                   "face " + std::to_string(id) + "'s curve has " + c.type + ", not supported");
    }
  }
  for (const int id : dropped) g.faceCurves.erase(id);
}

}  // namespace homesh::nektar
