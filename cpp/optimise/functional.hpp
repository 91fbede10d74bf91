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

// The per-point derivatives run hundreds of times per node update; GCC otherwise leaves the
// cofactor and the regularisation out of line (a call per quadrature point).
#define HOMESH_POINT_KERNEL [[gnu::always_inline]] inline

namespace homesh {

// In the order of the parameter table's "functional" choices (core/parameters.hpp), which
// holds their names and the default.
enum class Functional { Hyperelastic, LinearElastic, Winslow, Distortion };

// The functional a name stands for, as the table's "functional" reads it ("hyperelastic",
// "linearelastic", "winslow", "distortion"; any case, '-' and '_' ignored). Throws
// ParameterError naming the accepted values.
Functional parseFunctional(const std::string& name);
std::string functionalName(Functional f);

namespace functional_detail {

constexpr double kPoisson = 0.4;
constexpr double kMu = 1.0 / (2.0 * (1.0 + kPoisson));
constexpr double kBulk = 1.0 / (3.0 * (1.0 - 2.0 * kPoisson));

// The scalar type T is double in the optimiser; the derivative tests instantiate the same code
// with Eigen's forward-mode AutoDiffScalar, so every function below is written once for both.
inline double cubeRoot(double x) {
  return std::cbrt(x);
}
template <class T>
T cubeRoot(const T& x) {
  using std::pow;
  return pow(x, 1.0 / 3.0);  // AutoDiffScalar has no cbrt
}

// psi and its partial derivatives in S and r = J_r (every psi here is linear in S: psi_SS = 0).
template <class T>
struct Psi {
  T v = T(0), s = T(0), r = T(0), sr = T(0), rr = T(0);
};

// The transcendental of r each psi needs: ln r (the elastic energies), r^(2/d) (distortion),
// none (Winslow: r itself). node_patch.hpp computes it in a loop of its own.
template <int D, Functional F, class T>
HOMESH_POINT_KERNEL T transcendentalOf(const T& r) {
  using std::log;
  if constexpr (F == Functional::Hyperelastic || F == Functional::LinearElastic) {
    return log(r);
  } else if constexpr (F == Functional::Distortion && D == 3) {
    return cubeRoot(T(r * r));
  } else {
    return r;
  }
}

// psi from S, r > 0 and t = transcendentalOf(r), without a branch (node_patch.hpp evaluates it in
// vectorised loops). Compile-time functional: the optimiser's inner loops are instantiated per
// functional, so this inlines without a branch per point.
template <int D, Functional F, class T>
HOMESH_POINT_KERNEL Psi<T> psiOf(const T& S, const T& r, const T& t) {
  Psi<T> p;
  const T ir = 1.0 / r;  // one division for every derivative
  if constexpr (F == Functional::Hyperelastic) {
    p.v = 0.5 * kMu * (S - double(D)) - kMu * t + 0.5 * kBulk * t * t;
    p.s = T(0.5 * kMu);
    p.r = (-kMu + kBulk * t) * ir;
    p.rr = (kMu + kBulk * (1.0 - t)) * (ir * ir);
  } else if constexpr (F == Functional::LinearElastic) {
    p.v = 0.5 * kBulk * t * t + kMu * S;
    p.s = T(kMu);
    p.r = kBulk * t * ir;
    p.rr = kBulk * (1.0 - t) * (ir * ir);
  } else if constexpr (F == Functional::Winslow) {
    p.v = S * ir;
    p.s = ir;
    p.sr = -ir * ir;
    p.r = -S * ir * ir;
    p.rr = 2.0 * S * ir * ir * ir;
  } else {
    constexpr double e = 2.0 / D;
    const T c = 1.0 / (double(D) * t);  // t = r^(2/d)
    p.v = S * c;
    p.s = c;
    p.sr = -e * c * ir;
    p.r = -e * S * c * ir;
    p.rr = e * (e + 1.0) * S * c * ir * ir;
  }
  return p;
}

template <int D, Functional F, class T>
HOMESH_POINT_KERNEL Psi<T> psi(const T& S, const T& r) {
  if (!(r > 0.0)) {
    Psi<T> p;
    p.v = T(std::numeric_limits<double>::infinity());  // inverted, unregularised: a barrier
    return p;
  }
  return psiOf<D, F>(S, r, transcendentalOf<D, F>(r));
}

template <int D, class T>
HOMESH_POINT_KERNEL T determinant(const Eigen::Matrix<T, D, D>& F) {
  if constexpr (D == 2) {
    return F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0);
  } else {
    return F(0, 0) * (F(1, 1) * F(2, 2) - F(1, 2) * F(2, 1)) -
           F(0, 1) * (F(1, 0) * F(2, 2) - F(1, 2) * F(2, 0)) +
           F(0, 2) * (F(1, 0) * F(2, 1) - F(1, 1) * F(2, 0));
  }
}

// The cofactor matrix dJ/dF.
template <int D, class T>
HOMESH_POINT_KERNEL Eigen::Matrix<T, D, D> cofactor(const Eigen::Matrix<T, D, D>& F) {
  Eigen::Matrix<T, D, D> c;
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

// Green's strain E = (F^T F - I) / 2.
template <int D, class T>
Eigen::Matrix<T, D, D> greenStrain(const Eigen::Matrix<T, D, D>& F) {
  Eigen::Matrix<T, D, D> E = 0.5 * (F.transpose() * F);
  for (int i = 0; i < D; ++i) E(i, i) -= 0.5;
  return E;
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
template <class T>
struct Regularised {
  T r = T(0), dr = T(0), ddr = T(0);
};
// Far from inversion (J > 1e9 eps: eps^2 / J^2 below 1e-18, under the unit roundoff): J_r = J
// and dJ_r/dJ = 1 to rounding; the common case of a valid patch, without the square root.
template <class T>
HOMESH_POINT_KERNEL Regularised<T> regulariseFar(const T& J, double eps) {
  Regularised<T> out;
  out.r = J;
  out.dr = T(1.0);
  out.ddr = 2.0 * eps * eps / (J * J * J);
  return out;
}
// The general formula. Every candidate is computed first and then selected, with no branch, so
// a loop over points that calls it vectorises (node_patch.hpp): GCC does not if-convert a
// division it would have to move out of a branch.
template <class T>
HOMESH_POINT_KERNEL Regularised<T> regulariseNear(const T& J, double eps) {
  using std::sqrt;
  const double e2 = eps * eps;
  const T root = sqrt(J * J + 4.0 * e2);
  const T above = 0.5 * (J + root);
  const T below = 2.0 * e2 / (root - J);  // (J + root) / 2 cancels badly for J << 0
  const bool rooted = root > 0.0;         // false only for eps = 0 and J = 0
  Regularised<T> out;
  out.r = J >= 0.0 ? above : below;
  const T ratio = out.r / root;
  const T curvature = 2.0 * e2 / (root * root * root);
  out.dr = rooted ? ratio : T(J > 0.0 ? 1.0 : 0.0);
  out.ddr = rooted ? curvature : T(0.0);
  return out;
}
template <class T>
HOMESH_POINT_KERNEL Regularised<T> regularise(const T& J, double eps) {
  if (J > 1e9 * eps) return regulariseFar(J, eps);
  return regulariseNear(J, eps);
}

// W(F).
template <int D, Functional Fn, class T>
T energyDensity(const Eigen::Matrix<T, D, D>& F, double eps) {
  using namespace functional_detail;
  const T J = determinant<D>(F);
  T S;
  if constexpr (Fn == Functional::LinearElastic) {
    S = greenStrain<D>(F).squaredNorm();
  } else {
    S = F.squaredNorm();
  }
  return psi<D, Fn>(S, regularise(J, eps).r).v;
}

template <int D, class T>
T energyDensity(Functional f, const Eigen::Matrix<T, D, D>& F, double eps) {
  return functional_detail::dispatch(
      f, [&](auto fn) { return energyDensity<D, decltype(fn)::value>(F, eps); });
}

// What W(F + delta a^T) needs of F, for every delta: |F + delta a^T|^2 = SF + 2 delta . fa +
// |delta|^2 aa and det(F + delta a^T) = J + g . delta (matrix determinant lemma, g = cof(F) a).
// A trial move then costs two dot products and psi instead of a 3x3 update and determinant
// (optimise/node_patch.hpp keeps these terms per point, for every point of a node's patch).
template <int D, class T>
struct RankOneTerms {
  T SF = T(0), J = T(0), aa = T(0);
  Eigen::Matrix<T, D, 1> fa = Eigen::Matrix<T, D, 1>::Zero(), g = Eigen::Matrix<T, D, 1>::Zero();
};

// W(F) and its gradient and Hessian with respect to delta, where F(delta) = F + delta a^T;
// with `terms`, also F's rank-one terms.
template <int D, Functional Fn, class T>
HOMESH_POINT_KERNEL T energyDensityDerivatives(const Eigen::Matrix<T, D, D>& F,
                                               const Eigen::Matrix<T, D, 1>& a, double eps,
                                               Eigen::Matrix<T, D, 1>& gradient,
                                               Eigen::Matrix<T, D, D>& hessian,
                                               RankOneTerms<D, T>* terms = nullptr) {
  using namespace functional_detail;
  using Vec = Eigen::Matrix<T, D, 1>;
  using Mat = Eigen::Matrix<T, D, D>;
  const Mat cof = cofactor<D>(F);
  // Laplace expansion along the first row: the same products and sums as determinant().
  T J = F(0, 0) * cof(0, 0);
  for (int j = 1; j < D; ++j) J += F(0, j) * cof(0, j);
  const Vec g = cof * a;  // dJ/ddelta
  const Vec fa = F * a;
  const T aa = a.squaredNorm();
  const T SF = F.squaredNorm();
  // Every psi is linear in S (psi_SS = 0), so S's second derivative enters only through psi_S;
  // ddS = ddS0 + ddSI I, with ddSI the multiple of the identity.
  T S;
  Vec dS;
  Mat ddS0;
  T ddSI;
  if constexpr (Fn == Functional::LinearElastic) {
    const Mat E = greenStrain<D>(F);
    S = E.squaredNorm();
    dS = 2.0 * F * (E * a);
    ddS0 = aa * (F * F.transpose()) + fa * fa.transpose();
    ddSI = 2.0 * a.dot(E * a);
  } else {
    S = SF;
    dS = 2.0 * fa;
    ddSI = 2.0 * aa;
  }
  const Regularised<T> reg = regularise(J, eps);
  const Psi<T> p = psi<D, Fn>(S, reg.r);
  const T pj = p.r * reg.dr;
  const T pjj = p.rr * reg.dr * reg.dr + p.r * reg.ddr;
  gradient = p.s * dS + pj * g;
  hessian.noalias() = pjj * (g * g.transpose());
  if constexpr (Fn == Functional::Winslow || Fn == Functional::Distortion) {
    const T psj = p.sr * reg.dr;  // zero for the elastic energies, whose psi_S is constant
    hessian.noalias() += psj * (dS * g.transpose() + g * dS.transpose());
  }
  if constexpr (Fn == Functional::LinearElastic) hessian.noalias() += p.s * ddS0;
  hessian.diagonal().array() += p.s * ddSI;
  if (terms != nullptr) {
    terms->SF = SF;
    terms->J = J;
    terms->aa = aa;
    terms->fa = fa;
    terms->g = g;
  }
  return p.v;
}

template <int D, class T>
T energyDensityDerivatives(Functional f, const Eigen::Matrix<T, D, D>& F,
                           const Eigen::Matrix<T, D, 1>& a, double eps,
                           Eigen::Matrix<T, D, 1>& gradient, Eigen::Matrix<T, D, D>& hessian) {
  return functional_detail::dispatch(f, [&](auto fn) {
    return energyDensityDerivatives<D, decltype(fn)::value>(F, a, eps, gradient, hessian);
  });
}

}  // namespace homesh
