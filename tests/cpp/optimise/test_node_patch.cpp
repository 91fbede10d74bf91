// The optimiser's batched per-node kernels (optimise/node_patch.hpp) against the point-by-point
// reference of optimise/functional.hpp, whose derivatives test_derivatives.cpp checks against
// automatic differentiation.
//
// Both sides sum the same terms w_i x (value, gradient, Hessian of W at point i) in different
// orders, each term computed by different but equally rounded formulas: the difference is
// bounded by (n + c) u times the sum of the terms' absolute values (Higham's bound for a
// recursive or pairwise sum, n terms, c a few roundings per term), u the unit roundoff. The
// tests use (n + 64) u of the absolute sum, which a wrong formula exceeds by many orders of
// magnitude (one test plants a 1e-9 relative error and sees it).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "optimise/functional.hpp"
#include "optimise/node_patch.hpp"

namespace homesh {
namespace {

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;

// Points of one node's patch: two element runs, F stored [component][point] with a stride
// larger than the run (as the optimiser's blocks store it), a and the weights in the patch.
template <int D>
struct Fixture {
  using Mat = Eigen::Matrix<double, D, D>;
  using Vec = Eigen::Matrix<double, D, 1>;
  std::vector<Mat> F;
  std::vector<Vec> a;
  std::vector<double> w;
  std::vector<std::vector<double>> storage;  // per run: [component][stride]
  NodePatch<D> patch;

  // `inverted`: a share of the points with det F < 0 (a tangled patch, regularised).
  Fixture(unsigned seed, double inverted) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const std::size_t counts[2] = {37, 23};  // odd sizes: the vector loops' remainders run too
    const std::size_t strides[2] = {41, 23};
    patch.reset(counts[0] + counts[1]);
    for (int r = 0; r < 2; ++r) {
      storage.emplace_back(static_cast<std::size_t>(D * D) * strides[r], 0.0);
      const std::size_t first = patch.append(counts[r], storage.back().data(), strides[r]);
      for (std::size_t j = 0; j < counts[r]; ++j) {
        Mat m = Mat::Identity() + 0.4 * Mat::NullaryExpr([&] { return u(rng); });
        if (u(rng) < 2.0 * inverted - 1.0) m.col(0) *= -1.0;
        Vec v = Vec::NullaryExpr([&] { return u(rng); });
        const double weight = 0.5 + 0.5 * std::abs(u(rng));
        for (int k = 0; k < D * D; ++k)
          storage.back()[static_cast<std::size_t>(k) * strides[r] + j] = m(k % D, k / D);
        for (int c = 0; c < D; ++c) patch.a(c)[first + j] = v[c];
        patch.weight()[first + j] = weight;
        F.push_back(m);
        a.push_back(v);
        w.push_back(weight);
      }
    }
  }
};

template <int D>
struct Sums {
  double value = 0.0, valueAbs = 0.0, magnitude = 0.0;
  Eigen::Matrix<double, D, 1> gradient = Eigen::Matrix<double, D, 1>::Zero();
  Eigen::Matrix<double, D, D> hessian = Eigen::Matrix<double, D, D>::Zero();
  double gradientAbs = 0.0, hessianAbs = 0.0;
};

template <int D, Functional Fn>
Sums<D> reference(const Fixture<D>& fx, const Eigen::Matrix<double, D, 1>& shift, double eps) {
  Sums<D> s;
  for (std::size_t i = 0; i < fx.F.size(); ++i) {
    const Eigen::Matrix<double, D, D> F = fx.F[i] + shift * fx.a[i].transpose();
    Eigen::Matrix<double, D, 1> g;
    Eigen::Matrix<double, D, D> h;
    const double v = energyDensityDerivatives<D, Fn>(F, fx.a[i], eps, g, h);
    s.value += fx.w[i] * v;
    s.valueAbs += fx.w[i] * std::abs(v);
    s.magnitude += fx.w[i] * (std::abs(v) + F.squaredNorm());
    s.gradient += fx.w[i] * g;
    s.hessian += fx.w[i] * h;
    s.gradientAbs += fx.w[i] * g.cwiseAbs().maxCoeff();
    s.hessianAbs += fx.w[i] * h.cwiseAbs().maxCoeff();
  }
  return s;
}

double bound(std::size_t n, double absSum) {
  return (static_cast<double>(n) + 64.0) * kU * absSum;
}

template <int D, Functional Fn>
void checkAssembly(unsigned seed, double inverted, double eps) {
  SCOPED_TRACE("D = " + std::to_string(D) + ", " + functionalName(Fn) +
               ", eps = " + std::to_string(eps));
  Fixture<D> fx(seed, inverted);
  const std::size_t n = fx.F.size();
  const Eigen::Matrix<double, D, 1> none = Eigen::Matrix<double, D, 1>::Zero();
  const Sums<D> ref = reference<D, Fn>(fx, none, eps);
  Eigen::Matrix<double, D, 1> grad;
  Eigen::Matrix<double, D, D> hess;
  double magnitude = 0.0;
  const double value = assemblePatch<D, Fn>(fx.patch, eps, grad, hess, &magnitude);
  EXPECT_NEAR(value, ref.value, bound(n, ref.valueAbs));
  EXPECT_NEAR(magnitude, ref.magnitude, bound(n, ref.magnitude));
  for (int r = 0; r < D; ++r) {
    EXPECT_NEAR(grad[r], ref.gradient[r], bound(n, ref.gradientAbs)) << "gradient " << r;
    for (int c = 0; c < D; ++c)
      EXPECT_NEAR(hess(r, c), ref.hessian(r, c), bound(n, ref.hessianAbs)) << r << "," << c;
  }
  // The terms the move's update reads: det F and cof(F) a at every point.
  for (std::size_t i = 0; i < n; ++i) {
    const double J = functional_detail::determinant<D>(fx.F[i]);
    const Eigen::Matrix<double, D, 1> g = functional_detail::cofactor<D>(fx.F[i]) * fx.a[i];
    const double scale = fx.F[i].cwiseAbs().maxCoeff();
    EXPECT_NEAR(fx.patch.J()[i], J, 16 * kU * std::pow(scale, D) * D * D);
    for (int c = 0; c < D; ++c)
      EXPECT_NEAR(fx.patch.g(c)[i], g[c],
                  16 * kU * std::pow(scale, D - 1) * fx.a[i].cwiseAbs().maxCoeff() * D * D);
  }
  // The line search's trial energies, from those terms, against W of the updated matrices.
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int t = 0; t < 4; ++t) {
    const Eigen::Matrix<double, D, 1> d =
        Eigen::Matrix<double, D, 1>::NullaryExpr([&] { return u(rng); });
    // Reference: W of the updated matrix. The rank-one form evaluates S = |F + d a^T|^2 and
    // J = det(F + d a^T) from expanded terms instead, so each side's S and J carry a rounding of
    // a few u times the sum of the absolute values of their terms (S_abs, J_abs), which reaches
    // W through psi_S and psi_J: a first-order bound per point, summed.
    double e = 0.0, eAbs = 0.0, termError = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Matrix<double, D, D> F = fx.F[i] + d * fx.a[i].transpose();
      const double v = energyDensity<D, Fn>(F, eps);
      e += fx.w[i] * v;
      eAbs += fx.w[i] * std::abs(v);
      const double na = fx.a[i].norm(), nd = d.norm(), nF = fx.F[i].norm();
      const double SAbs = (nF + nd * na) * (nF + nd * na);
      const double JAbs = std::pow(nF + nd * na, D) * 6.0;  // D! products of D entries
      double S = F.squaredNorm();
      if constexpr (Fn == Functional::LinearElastic)
        S = functional_detail::greenStrain<D>(F).squaredNorm();
      const Regularised<double> reg = regularise(functional_detail::determinant<D>(F), eps);
      const auto ps = functional_detail::psi<D, Fn>(S, reg.r);
      termError += fx.w[i] * 32.0 * kU *
                   (std::abs(ps.s) * SAbs * (Fn == Functional::LinearElastic ? 2.0 * SAbs : 1.0) +
                    std::abs(ps.r * reg.dr) * JAbs);
    }
    const double after = patchEnergyAfter<D, Fn>(fx.patch, d, eps);
    if (std::isfinite(e)) {
      EXPECT_NEAR(after, e, termError + bound(n, eAbs)) << "trial " << t;
    } else {
      EXPECT_FALSE(std::isfinite(after)) << "trial " << t;
    }
  }
  // The probe's shifted patch: F + s a^T in the patch's own copy, the optimiser's F untouched.
  const Eigen::Matrix<double, D, 1> s = 0.05 * Eigen::Matrix<double, D, 1>::Ones();
  const std::vector<std::vector<double>> before = fx.storage;
  const Sums<D> shifted = reference<D, Fn>(fx, s, eps);
  fx.patch.shift(s);
  const double shiftedValue = assemblePatch<D, Fn>(fx.patch, eps, grad, hess, &magnitude);
  EXPECT_NEAR(shiftedValue, shifted.value, bound(n, shifted.valueAbs));
  for (int r = 0; r < D; ++r)
    EXPECT_NEAR(grad[r], shifted.gradient[r], bound(n, shifted.gradientAbs));
  EXPECT_EQ(fx.storage, before);
}

template <int D>
void checkEveryFunctional(unsigned seed, double inverted, double eps) {
  checkAssembly<D, Functional::Hyperelastic>(seed, inverted, eps);
  checkAssembly<D, Functional::Winslow>(seed, inverted, eps);
  checkAssembly<D, Functional::Distortion>(seed, inverted, eps);
  checkAssembly<D, Functional::LinearElastic>(seed, inverted, eps);
}

TEST(NodePatch, ValidPatchMatchesThePointByPointKernel) {
  checkEveryFunctional<3>(11, 0.0, 1e-10);
  checkEveryFunctional<2>(12, 0.0, 1e-10);
}

TEST(NodePatch, TangledRegularisedPatchMatchesThePointByPointKernel) {
  // A quarter of the points inverted, eps as the optimiser sets it for a tangled patch.
  checkEveryFunctional<3>(21, 0.25, 0.2);
  checkEveryFunctional<2>(22, 0.25, 0.2);
}

TEST(NodePatch, UnregularisedInvertedPointIsABarrier) {
  Fixture<3> fx(31, 0.5);
  Eigen::Vector3d grad;
  Eigen::Matrix3d hess;
  // eps 0: J_r = J, so an inverted point has no finite energy (functional.hpp's barrier).
  EXPECT_FALSE(
      std::isfinite(assemblePatch<3, Functional::Hyperelastic>(fx.patch, 0.0, grad, hess)));
}

TEST(NodePatch, ComparisonResolvesAPlantedRelativeErrorOf1e9) {
  // The bound above is far below the size of any formula error: a weight off by 1e-9 relative
  // moves the value by more than the tolerance.
  Fixture<3> fx(41, 0.0);
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  const Sums<3> ref = reference<3, Functional::Hyperelastic>(fx, none, 1e-10);
  fx.patch.weight()[5] *= 1.0 + 1e-9;
  Eigen::Vector3d grad;
  Eigen::Matrix3d hess;
  const double value = assemblePatch<3, Functional::Hyperelastic>(fx.patch, 1e-10, grad, hess);
  const double moved = std::abs(value - ref.value);
  EXPECT_GT(moved, bound(fx.F.size(), ref.valueAbs))
      << "tolerance " << bound(fx.F.size(), ref.valueAbs);
}

}  // namespace
}  // namespace homesh
