// The energy densities W(F) the variational optimiser minimises, with exact derivatives with
// respect to the displacement of one node.
//
// F = (dx/dxi)(dx_I/dxi)^-1 is the deformation gradient from the straight-sided (ideal) element
// to the curved one, J = det F, and J_r = (J + sqrt(J^2 + 4 eps^2)) / 2 the regularised
// determinant that stays positive on tangled elements (eps sizeable only where a patch is
// inverted, 1e-10 otherwise).
// With mu = 1 / (2 (1 + nu)), K = 1 / (3 (1 - 2 nu)), nu = 0.4 and d the dimension:
//   linear elastic  W = (K/2) (ln J_r)^2 + mu |E|^2,   E = (F^T F - I) / 2
//   hyperelastic    W = (mu/2) (|F|^2 - d) - mu ln J_r + (K/2) (ln J_r)^2   (DESIGN.md writes 3
//                   for d; a constant, it changes nothing)
//   Winslow         W = |F|^2 / J_r
//   distortion      W = |F|^2 / (d J_r^(2/d))
// Every W is psi(S, J_r) with S = |F|^2 or |E|^2, so one chain rule serves all four.
//
// Moving node n by delta changes F by delta a^T, with a = (dx_I/dxi)^-T grad_xi l_n. Along such
// a rank-one change J is linear (matrix determinant lemma: J' = J + (cof F a) . delta), so the
// per-node Hessian below is exact, not a Gauss-Newton approximation.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

namespace homesh {

enum class Functional { LinearElastic, Hyperelastic, Winslow, Distortion };

// "linearelastic" (also "linear-elastic", "linear_elastic"), "hyperelastic", "winslow",
// "distortion" (also "roca"). Throws ParameterError naming the accepted values.
Functional parseFunctional(const std::string& name);
std::string functionalName(Functional f);

namespace functional_detail {

constexpr double kPoisson = 0.4;
constexpr double kMu = 1.0 / (2.0 * (1.0 + kPoisson));
constexpr double kBulk = 1.0 / (3.0 * (1.0 - 2.0 * kPoisson));

// psi and its partial derivatives in S and r = J_r.
struct Psi {
  double v = 0, s = 0, r = 0, ss = 0, sr = 0, rr = 0;
};

// Compile-time functional: the optimiser's inner loops are instantiated per functional, so
// this inlines without a branch per point.
template <int D, Functional F>
Psi psi(double S, double r) {
  Psi p;
  if (!(r > 0.0)) {
    p.v = std::numeric_limits<double>::infinity();  // inverted, unregularised: a barrier
    return p;
  }
  if constexpr (F == Functional::Hyperelastic) {
    const double l = std::log(r);
    p.v = 0.5 * kMu * (S - D) - kMu * l + 0.5 * kBulk * l * l;
    p.s = 0.5 * kMu;
    p.r = (-kMu + kBulk * l) / r;
    p.rr = (kMu + kBulk * (1.0 - l)) / (r * r);
  } else if constexpr (F == Functional::LinearElastic) {
    const double l = std::log(r);
    p.v = 0.5 * kBulk * l * l + kMu * S;
    p.s = kMu;
    p.r = kBulk * l / r;
    p.rr = kBulk * (1.0 - l) / (r * r);
  } else if constexpr (F == Functional::Winslow) {
    p.v = S / r;
    p.s = 1.0 / r;
    p.sr = -1.0 / (r * r);
    p.r = -S / (r * r);
    p.rr = 2.0 * S / (r * r * r);
  } else {
    constexpr double e = 2.0 / D;
    const double rp = D == 2 ? r : std::cbrt(r * r);  // r^(2/d)
    p.v = S / (D * rp);
    p.s = 1.0 / (D * rp);
    p.sr = -e / (D * rp * r);
    p.r = -e * S / (D * rp * r);
    p.rr = e * (e + 1.0) * S / (D * rp * r * r);
  }
  return p;
}

template <int D>
double determinant(const Eigen::Matrix<double, D, D>& F) {
  if constexpr (D == 2) {
    return F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0);
  } else {
    return F(0, 0) * (F(1, 1) * F(2, 2) - F(1, 2) * F(2, 1)) -
           F(0, 1) * (F(1, 0) * F(2, 2) - F(1, 2) * F(2, 0)) +
           F(0, 2) * (F(1, 0) * F(2, 1) - F(1, 1) * F(2, 0));
  }
}

// The cofactor matrix dJ/dF.
template <int D>
Eigen::Matrix<double, D, D> cofactor(const Eigen::Matrix<double, D, D>& F) {
  Eigen::Matrix<double, D, D> c;
  if constexpr (D == 2) {
    c << F(1, 1), -F(1, 0), -F(0, 1), F(0, 0);
  } else {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        c(i, j) = F(i1, j1) * F(i2, j2) - F(i1, j2) * F(i2, j1);
      }
  }
  return c;
}

// Calls fn(std::integral_constant<Functional, f>()) for the runtime value f.
template <class Fn>
decltype(auto) dispatch(Functional f, Fn&& fn) {
  switch (f) {
    case Functional::LinearElastic:
      return fn(std::integral_constant<Functional, Functional::LinearElastic>());
    case Functional::Hyperelastic:
      return fn(std::integral_constant<Functional, Functional::Hyperelastic>());
    case Functional::Winslow:
      return fn(std::integral_constant<Functional, Functional::Winslow>());
    case Functional::Distortion:
      break;
  }
  return fn(std::integral_constant<Functional, Functional::Distortion>());
}

}  // namespace functional_detail

// J_r and its first two derivatives in J.
struct Regularised {
  double r = 0, dr = 0, ddr = 0;
};
inline Regularised regularise(double J, double eps) {
  const double root = std::sqrt(J * J + 4.0 * eps * eps);
  Regularised out;
  // (J + root) / 2 cancels badly for J << 0: use the equivalent 2 eps^2 / (root - J).
  out.r = J >= 0.0 ? 0.5 * (J + root) : 2.0 * eps * eps / (root - J);
  out.dr = root > 0.0 ? out.r / root : (J > 0.0 ? 1.0 : 0.0);
  out.ddr = root > 0.0 ? 2.0 * eps * eps / (root * root * root) : 0.0;
  return out;
}

// W(F).
template <int D, Functional Fn>
double energyDensity(const Eigen::Matrix<double, D, D>& F, double eps) {
  using namespace functional_detail;
  const double J = determinant<D>(F);
  double S = 0;
  if constexpr (Fn == Functional::LinearElastic) {
    Eigen::Matrix<double, D, D> E = 0.5 * (F.transpose() * F);
    E.diagonal().array() -= 0.5;
    S = E.squaredNorm();
  } else {
    S = F.squaredNorm();
  }
  return psi<D, Fn>(S, regularise(J, eps).r).v;
}

template <int D>
double energyDensity(Functional f, const Eigen::Matrix<double, D, D>& F, double eps) {
  return functional_detail::dispatch(
      f, [&](auto fn) { return energyDensity<D, decltype(fn)::value>(F, eps); });
}

// W(F) and its gradient and Hessian with respect to delta, where F(delta) = F + delta a^T.
template <int D, Functional Fn>
double energyDensityDerivatives(const Eigen::Matrix<double, D, D>& F,
                                const Eigen::Matrix<double, D, 1>& a, double eps,
                                Eigen::Matrix<double, D, 1>& gradient,
                                Eigen::Matrix<double, D, D>& hessian) {
  using namespace functional_detail;
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;
  const double J = determinant<D>(F);
  const Vec g = cofactor<D>(F) * a;  // dJ/ddelta
  const Vec fa = F * a;
  const double aa = a.squaredNorm();
  double S = 0;
  Vec dS;
  Mat ddS;
  if constexpr (Fn == Functional::LinearElastic) {
    Mat E = 0.5 * (F.transpose() * F);
    E.diagonal().array() -= 0.5;
    S = E.squaredNorm();
    dS = 2.0 * F * (E * a);
    ddS = aa * (F * F.transpose()) + fa * fa.transpose();
    ddS.diagonal().array() += 2.0 * a.dot(E * a);
  } else {
    S = F.squaredNorm();
    dS = 2.0 * fa;
    ddS = Mat::Identity() * (2.0 * aa);
  }
  const Regularised reg = regularise(J, eps);
  const Psi p = psi<D, Fn>(S, reg.r);
  const double pj = p.r * reg.dr;
  const double pjj = p.rr * reg.dr * reg.dr + p.r * reg.ddr;
  const double psj = p.sr * reg.dr;
  gradient = p.s * dS + pj * g;
  hessian = p.ss * (dS * dS.transpose()) + psj * (dS * g.transpose() + g * dS.transpose()) +
            pjj * (g * g.transpose()) + p.s * ddS;
  return p.v;
}

template <int D>
double energyDensityDerivatives(Functional f, const Eigen::Matrix<double, D, D>& F,
                                const Eigen::Matrix<double, D, 1>& a, double eps,
                                Eigen::Matrix<double, D, 1>& gradient,
                                Eigen::Matrix<double, D, D>& hessian) {
  return functional_detail::dispatch(f, [&](auto fn) {
    return energyDensityDerivatives<D, decltype(fn)::value>(F, a, eps, gradient, hessian);
  });
}

}  // namespace homesh
