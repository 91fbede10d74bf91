// A node's CAD curve or surface near its parameters, as the optimiser's line search sees it:
// the second-order Taylor model x(p0 + dp) = x0 + X dp + 1/2 dp^T X'' dp built from one
// evaluation of the CAD's first and second derivatives. The search tries its points on the
// model and asks the CAD only for the point it accepts, so a visit of a sliding node costs two
// CAD evaluations instead of one per trial point; the accepted point is the CAD's own, so the
// node never leaves the CAD (the model only chooses the step).
//
// The model's error is O(|dp|^3) (the third derivatives' size): tests/cpp/optimise checks the
// factor 8 per halving of dp on surfaces with known derivatives.
#pragma once

#include <Eigen/Core>
#include <array>

#include "cad/cad_model.hpp"

namespace homesh {

template <int D>
struct LocalCadModel {
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;
  using Frame = Eigen::Matrix<double, D, 3>;  // rows: the optimiser's axes (of the plane in 2D)

  int parameters = 0;  // 1 on a curve (t), 2 on a surface (u, v); 0: no model yet
  std::array<double, 2> at0 = {0.0, 0.0};  // the parameters p0 it was built at (set by its user)
  Vec point = Vec::Zero();
  std::array<Vec, 2> d = {Vec::Zero(), Vec::Zero()};                // dx/dt, or dx/du and dx/dv
  std::array<Vec, 3> dd = {Vec::Zero(), Vec::Zero(), Vec::Zero()};  // x_tt, or x_uu, x_uv, x_vv

  static LocalCadModel curve(const CurveDerivatives& c, const Frame& frame) {
    LocalCadModel m;
    m.parameters = 1;
    m.point = frame * c.point;
    m.d[0] = frame * c.d1;
    m.dd[0] = frame * c.d2;
    return m;
  }

  static LocalCadModel surface(const SurfaceDerivatives& s, const Frame& frame) {
    LocalCadModel m;
    m.parameters = 2;
    m.point = frame * s.point;
    m.d[0] = frame * s.du;
    m.d[1] = frame * s.dv;
    m.dd[0] = frame * s.duu;
    m.dd[1] = frame * s.duv;
    m.dd[2] = frame * s.dvv;
    return m;
  }

  // The model's point at parameters p0 + dp (dp[1] unused on a curve).
  Vec at(const double* dp) const {
    if (parameters == 1) return point + dp[0] * d[0] + (0.5 * dp[0] * dp[0]) * dd[0];
    return point + dp[0] * d[0] + dp[1] * d[1] + (0.5 * dp[0] * dp[0]) * dd[0] +
           (dp[0] * dp[1]) * dd[1] + (0.5 * dp[1] * dp[1]) * dd[2];
  }

  // The chain rule from the node's coordinates to its parameters, exact at p0: g = X^T grad and
  // h = X^T hess X + grad . X'' (the second term is the curve's or surface's curvature).
  template <class G, class H>
  void chainRule(const Vec& grad, const Mat& hess, G& g, H& h) const {
    const int n = parameters;
    g.resize(n);
    h.resize(n, n);
    for (int i = 0; i < n; ++i) {
      g(i) = d[i].dot(grad);
      for (int j = 0; j <= i; ++j) {
        h(i, j) = d[i].dot(hess * d[j]) + grad.dot(dd[i + j]);
        h(j, i) = h(i, j);
      }
    }
  }
};

}  // namespace homesh
