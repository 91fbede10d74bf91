// Derivative checks of the optimiser whose verdicts cannot flip on rounding.
//
// 1. The energy density kernel (optimise/functional.hpp) against forward-mode automatic
//    differentiation of the same templated code: AD of W gives the gradient, AD of the gradient
//    gives the Hessian. AD is exact up to rounding, so the tolerance is the rounding of both
//    sides, measured by evaluating both again in long double (unit roundoff 5.4e-20, so the
//    difference from double is the double result's own rounding error to three digits).
// 2. The optimiser's own assembly around a node (NodeEnergyProbe: the patch, the weights, the
//    regularisation and, for nodes sliding on the CAD, the chain rule through the curve's or
//    surface's derivatives) against finite differences whose error is bounded from the data:
//    truncation by Richardson's estimate and rounding by the scatter of difference quotients at
//    steps where truncation is negligible; the step is the one with the smallest bound.
// Both checks are shown to resolve an error of 1e-4 relative (the tests below plant one).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <unsupported/Eigen/AutoDiff>
#include <vector>

#include "core/error.hpp"
#include "element/reference_element.hpp"
#include "optimise/facet_energy.hpp"
#include "optimise/functional.hpp"
#include "optimise/optimiser.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;  // unit roundoff

const Functional kAll[] = {Functional::LinearElastic, Functional::Hyperelastic, Functional::Winslow,
                           Functional::Distortion};

// ---- 1. The kernel against automatic differentiation ------------------------------------------

// The kernel's value, gradient and Hessian, and their AD counterparts, at scalar type T.
template <int D, class T>
struct KernelResult {
  Eigen::Matrix<T, D, 1> gradient, adGradient;  // analytic; AD of the value
  Eigen::Matrix<T, D, D> hessian, adHessian;    // analytic; AD of the analytic gradient
};

template <int D, class T>
KernelResult<D, T> kernel(Functional f, const Eigen::Matrix<double, D, D>& F0,
                          const Eigen::Matrix<double, D, 1>& a0, double eps) {
  using AD = Eigen::AutoDiffScalar<Eigen::Matrix<T, D, 1>>;
  const Eigen::Matrix<T, D, D> F = F0.template cast<T>();
  const Eigen::Matrix<T, D, 1> a = a0.template cast<T>();
  KernelResult<D, T> r;
  energyDensityDerivatives<D>(f, F, a, eps, r.gradient, r.hessian);
  // F(delta) = F + delta a^T with delta the AD variables.
  Eigen::Matrix<AD, D, D> Fd;
  Eigen::Matrix<AD, D, 1> ad;
  for (int i = 0; i < D; ++i) {
    ad[i] = AD(a[i], Eigen::Matrix<T, D, 1>::Zero());
    for (int j = 0; j < D; ++j) {
      Fd(i, j) = AD(F(i, j), Eigen::Matrix<T, D, 1>::Zero());
      Fd(i, j).derivatives()[i] = a[j];
    }
  }
  r.adGradient = energyDensity<D>(f, Fd, eps).derivatives();
  Eigen::Matrix<AD, D, 1> g;
  Eigen::Matrix<AD, D, D> h;
  energyDensityDerivatives<D>(f, Fd, ad, eps, g, h);
  for (int l = 0; l < D; ++l) r.adHessian.row(l) = g[l].derivatives().transpose();
  return r;
}

// |analytic - AD| and the rounding bound it must stay within: 4 x the measured rounding of each
// side (the long double difference) plus 16 u of the value, entry by entry.
struct Mismatch {
  double worstRatio = 0.0;  // max |analytic - AD| / bound
  double worstBound = 0.0;  // max bound / |entry| over entries that are not tiny
};

template <class M, class L>
void compare(const M& analytic, const M& ad, const L& analyticLong, const L& adLong, double scale,
             Mismatch& m) {
  for (int i = 0; i < analytic.size(); ++i) {
    const double x = analytic(i), y = ad(i);
    const double rounding = std::abs(x - static_cast<double>(analyticLong(i))) +
                            std::abs(y - static_cast<double>(adLong(i)));
    const double bound = 4.0 * rounding + 16.0 * kU * std::max(std::abs(x), std::abs(y));
    m.worstRatio = std::max(m.worstRatio, std::abs(x - y) / std::max(bound, 1e-300));
    // Entries far below the largest are not what a relative error test is about.
    if (std::abs(x) > 1e-6 * scale) m.worstBound = std::max(m.worstBound, bound / std::abs(x));
  }
}

template <int D>
Mismatch checkKernel(Functional f, double eps, bool inverted, std::mt19937& rng,
                     double plantGradient = 0.0, double plantHessian = 0.0) {
  using Mat = Eigen::Matrix<double, D, D>;
  using Vec = Eigen::Matrix<double, D, 1>;
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  Mat F = Mat::Identity();
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) F(i, j) += u(rng);
  if (inverted) F.row(0) *= -1.0;
  Vec a;
  for (int i = 0; i < D; ++i) a[i] = 1.0 + u(rng);
  KernelResult<D, double> r = kernel<D, double>(f, F, a, eps);
  KernelResult<D, long double> l = kernel<D, long double>(f, F, a, eps);
  // A planted error is a wrong formula: wrong at every precision.
  r.gradient *= 1.0 + plantGradient;
  r.hessian *= 1.0 + plantHessian;
  l.gradient *= 1.0L + plantGradient;
  l.hessian *= 1.0L + plantHessian;
  Mismatch m;
  compare(r.gradient, r.adGradient, l.gradient, l.adGradient, r.gradient.cwiseAbs().maxCoeff(), m);
  compare(r.hessian, r.adHessian, l.hessian, l.adHessian, r.hessian.cwiseAbs().maxCoeff(), m);
  return m;
}

template <class Check>
void forEveryKernelCase(Check check) {
  std::mt19937 rng(7);
  for (const Functional f : kAll)
    for (int trial = 0; trial < 20; ++trial) {
      check(f, "D=2", checkKernel<2>(f, 1e-10, false, rng));
      check(f, "D=3", checkKernel<3>(f, 1e-10, false, rng));
      // Regularised on an inverted point: the untangling regime.
      check(f, "D=2 inverted", checkKernel<2>(f, 0.3, true, rng));
      check(f, "D=3 inverted", checkKernel<3>(f, 0.3, true, rng));
    }
}

TEST(Functional, DensityDerivativesMatchAutomaticDifferentiation) {
  double resolution = 0.0;
  forEveryKernelCase([&](Functional f, const char* what, const Mismatch& m) {
    EXPECT_LE(m.worstRatio, 1.0) << functionalName(f) << " " << what;
    resolution = std::max(resolution, m.worstBound);
  });
  // The check resolves relative errors far below 1e-4 in every entry that matters.
  EXPECT_LT(resolution, 1e-8);
  std::printf("kernel vs AD: largest rounding bound %.2e relative\n", resolution);
}

TEST(Functional, KernelCheckCatchesAPlantedRelativeErrorOf1e4) {
  std::mt19937 rng(7);
  for (const Functional f : kAll) {
    EXPECT_GT(checkKernel<3>(f, 1e-10, false, rng, 1e-4, 0.0).worstRatio, 1.0)
        << functionalName(f) << " gradient";
    EXPECT_GT(checkKernel<3>(f, 1e-10, false, rng, 0.0, 1e-4).worstRatio, 1.0)
        << functionalName(f) << " Hessian";
    EXPECT_GT(checkKernel<2>(f, 0.3, true, rng, 1e-4, 0.0).worstRatio, 1.0)
        << functionalName(f) << " 2D inverted gradient";
  }
}

TEST(Functional, ValueMatchesTheDensityAlone) {
  // energyDensityDerivatives and energyDensity compute W by the same formula: bit-identical.
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (const Functional f : kAll) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int i = 0; i < 9; ++i) F(i) += u(rng);
    Eigen::Vector3d g, a(1.0, 0.5, -0.2);
    Eigen::Matrix3d h;
    EXPECT_EQ(energyDensityDerivatives<3>(f, F, a, 1e-10, g, h), energyDensity<3>(f, F, 1e-10));
  }
}

// The boundary facets' density (optimise/facet_energy.hpp): its analytic gradient and Hessian in
// the displacement d of a node, M(d) = [m1 + a1 d, m2 + a2 d], against AD as above.
template <class T>
struct FacetResult {
  Eigen::Matrix<T, 3, 1> gradient, adGradient;
  Eigen::Matrix<T, 3, 3> hessian, adHessian;
};

template <class T>
FacetResult<T> facetKernel(const Eigen::Vector3d& m1d, const Eigen::Vector3d& m2d, double a1d,
                           double a2d) {
  using AD = Eigen::AutoDiffScalar<Eigen::Matrix<T, 3, 1>>;
  using V = Eigen::Matrix<T, 3, 1>;
  using VA = Eigen::Matrix<AD, 3, 1>;
  V m1 = m1d.cast<T>(), m2 = m2d.cast<T>();  // (a copy for T = double as well)
  const T a1 = a1d, a2 = a2d;
  FacetResult<T> r;
  T value = 0;
  EXPECT_TRUE(facet_detail::derivatives<T>(m1, m2, a1, a2, value, r.gradient, r.hessian));
  VA n1, n2;  // M(d) with d the AD variables
  for (int i = 0; i < 3; ++i) {
    n1[i] = AD(m1[i], V::Zero());
    n1[i].derivatives()[i] = a1;
    n2[i] = AD(m2[i], V::Zero());
    n2[i].derivatives()[i] = a2;
  }
  r.adGradient = facet_detail::density<AD>(n1, n2).derivatives();
  AD v;
  VA g;
  Eigen::Matrix<AD, 3, 3> h;
  EXPECT_TRUE(facet_detail::derivatives<AD>(n1, n2, AD(a1, V::Zero()), AD(a2, V::Zero()), v, g, h));
  for (int l = 0; l < 3; ++l) r.adHessian.row(l) = g[l].derivatives().transpose();
  return r;
}

Mismatch checkFacetKernel(std::mt19937& rng, double plant = 0.0) {
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  // Columns near an orthonormal pair (a facet near its ideal), stretched and sheared.
  Eigen::Vector3d m1(1.0 + u(rng), u(rng), u(rng)), m2(u(rng), 1.0 + u(rng), u(rng));
  const double a1 = 1.0 + u(rng), a2 = -0.5 + u(rng);
  FacetResult<double> r = facetKernel<double>(m1, m2, a1, a2);
  FacetResult<long double> l = facetKernel<long double>(m1, m2, a1, a2);
  r.gradient *= 1.0 + plant;
  l.gradient *= 1.0L + plant;
  r.hessian *= 1.0 + plant;
  l.hessian *= 1.0L + plant;
  Mismatch m;
  compare(r.gradient, r.adGradient, l.gradient, l.adGradient, r.gradient.cwiseAbs().maxCoeff(), m);
  compare(r.hessian, r.adHessian, l.hessian, l.adHessian, r.hessian.cwiseAbs().maxCoeff(), m);
  return m;
}

TEST(FacetEnergy, DensityDerivativesMatchAutomaticDifferentiation) {
  std::mt19937 rng(17);
  double resolution = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const Mismatch m = checkFacetKernel(rng);
    EXPECT_LE(m.worstRatio, 1.0) << "trial " << trial;
    resolution = std::max(resolution, m.worstBound);
  }
  EXPECT_LT(resolution, 1e-8);
  // And the check sees a relative error of 1e-4.
  EXPECT_GT(checkFacetKernel(rng, 1e-4).worstRatio, 1.0);
}

// ---- 2. The optimiser's assembly against finite differences -----------------------------------

// A derivative of phi at 0 by fourth-order central differences, with a bound on its error.
struct Difference {
  double value = 0.0, bound = 0.0;
};

// `rounding`: a bound on the rounding error of one evaluation of phi (from an error model); the
// scatter of difference quotients at steps near 1e-9 of the spacing, where truncation is below
// 1e-30, measures it too, and the larger is used.
template <class Phi>
Difference centralDifference(Phi phi, double spacing, double rounding) {
  auto d4 = [&](double h) {
    return (8.0 * (phi(h) - phi(-h)) - (phi(2 * h) - phi(-2 * h))) / (12.0 * h);
  };
  // A quotient's rounding error is at most 1.5 delta / h for an evaluation rounding delta.
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  const double tiny = spacing * std::ldexp(1.0, -30);
  for (int i = 0; i < 6; ++i) {
    const double h = tiny * (1.0 + 0.37 * i);
    lo = std::min(lo, d4(h) * h);
    hi = std::max(hi, d4(h) * h);
  }
  const double delta = std::max(hi - lo, rounding);
  // Truncation: D(2h) - D(h) is about 15 times D(h)'s error once h^4 dominates; twice that, plus
  // ten times the rounding bound, for the steps h = spacing 2^-k; the smallest bound wins. The
  // h^4 regime is checked on three steps, not two: D(4h) - D(2h) must then be about 16 times
  // D(2h) - D(h), so the larger of D(2h) - D(h) and (D(4h) - D(2h)) / 16 is used. Two steps
  // alone can agree by chance where larger ones still feel a kink nearby (a sliding node's
  // patch at the box with a hole: D agreed to 5e-9 at h = spacing / 8 and / 16 while 4e-5 off;
  // the smaller steps converge to the analytic value).
  Difference best;
  best.bound = std::numeric_limits<double>::infinity();
  double before = d4(spacing), previous = d4(spacing * 0.5);
  for (int k = 2; k <= 16; ++k) {
    const double h = std::ldexp(spacing, -k);
    const double d = d4(h);
    const double change = std::max(std::abs(previous - d), std::abs(before - previous) / 16.0);
    const double bound = 2.0 * change + 10.0 * 1.5 * delta / h;
    if (bound < best.bound) best = {d, bound};
    before = previous;
    previous = d;
  }
  return best;
}

struct ProbeStats {
  int checks = 0, sensitive = 0;  // sensitive: the bound resolves 1e-4 of the derivative
  double worstRatio = 0.0;        // max |analytic - difference| / bound
};

// Gradient against differences of the value, Hessian against differences of the gradient, at
// `node`, along each of its coordinates. `plant` scales the analytic derivatives by 1 + plant.
void checkNode(const NodeEnergyProbe& probe, std::int64_t node, double spacing, ProbeStats& stats,
               const std::string& what, double plant = 0.0) {
  const Eigen::VectorXd x0 = probe.coordinates(node);
  const double eps = probe.regularisation(node);
  const NodeEnergy at = probe.evaluate(node, x0, eps);
  const Eigen::VectorXd gradient = at.gradient * (1.0 + plant);
  const Eigen::MatrixXd hessian = at.hessian * (1.0 + plant);
  const auto n = static_cast<int>(x0.size());
  const double gscale = gradient.cwiseAbs().maxCoeff(), hscale = hessian.cwiseAbs().maxCoeff();
  // Error model: the energy adds up terms of total size `magnitude` (NodeEnergy), each with a
  // relative rounding of at most a few hundred u over the patch's operations and sums, so one
  // evaluation is within 1e3 u magnitude; its derivatives, taken over the coordinate spacing,
  // within 1e3 u magnitude / spacing (gradient) and / spacing^2 (Hessian). That is also the
  // rounding the analytic side can carry.
  const double valueRounding = 1e3 * kU * at.magnitude;
  const double gradientRounding = valueRounding / spacing;
  auto record = [&](double analytic, const Difference& d, double floor, double scale,
                    const std::string& label) {
    const double bound = d.bound + floor;
    const double ratio = std::abs(analytic - d.value) / bound;
    stats.worstRatio = std::max(stats.worstRatio, ratio);
    ++stats.checks;
    // Only derivatives that matter: entries near zero are not where a relative error shows.
    if (std::abs(analytic) > 1e-3 * scale && bound < 1e-4 * std::abs(analytic)) ++stats.sensitive;
    if (plant == 0.0) {
      EXPECT_LE(ratio, 1.0) << what << " node " << node << " " << label << ": analytic " << analytic
                            << ", difference " << d.value << " +- " << bound;
    }
  };
  for (int m = 0; m < n; ++m) {
    auto moved = [&](double s) {
      Eigen::VectorXd x = x0;
      x[m] += s;
      return probe.evaluate(node, x, eps);
    };
    record(gradient[m],
           centralDifference([&](double s) { return moved(s).value; }, spacing, valueRounding),
           gradientRounding, gscale, "gradient " + std::to_string(m));
    for (int l = 0; l < n; ++l)
      record(hessian(l, m),
             centralDifference([&](double s) { return moved(s).gradient[l]; }, spacing,
                               gradientRounding),
             gradientRounding / spacing, hscale,
             "Hessian " + std::to_string(l) + "," + std::to_string(m));
  }
}

// One element of `type` and `order`: the reference element's equispaced nodes mapped by
// x -> x + t, perturbed by up to `noise` (a tenth of the node spacing: well inside validity,
// where W is smooth).
Mesh oneElement(CellType type, int order, double noise, std::mt19937& rng) {
  const ReferenceElement& ref = ReferenceElement::get(type, order);
  const int d = ref.dim();
  std::uniform_real_distribution<double> u(-noise, noise);
  Mesh m;
  m.dim = d;
  m.order = order;
  m.planeNormal = {0.0, 0.0, 1.0};
  for (int i = 0; i < ref.numNodes(); ++i) {
    double p[3] = {0.2, -0.1, d == 3 ? 0.3 : 0.0};
    for (int c = 0; c < d; ++c) p[c] += ref.nodes()(i, c) + u(rng);
    m.addNode(p, d, 1, NAN, NAN);
  }
  ElementBlock b;
  b.type = type;
  b.order = order;
  for (int i = 0; i < ref.numNodes(); ++i) b.nodes.push_back(i);
  b.entity = {1};
  m.blocks.push_back(b);
  return m;
}

TEST(Optimiser, NodeDerivativesMatchFiniteDifferencesOnEveryElementType) {
  std::mt19937 rng(11);
  ProbeStats stats;
  for (const CellType type : {CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron,
                              CellType::Prism, CellType::Pyramid, CellType::Hexahedron})
    for (const int order : {1, 2, 4, 6})
      for (const Functional f : kAll) {
        const Mesh mesh = oneElement(type, order, 0.1 / order, rng);
        OptimiserOptions options;
        options.functional = f;
        const NodeEnergyProbe probe(mesh, options);
        const auto n = static_cast<std::int64_t>(mesh.numNodes());
        for (const std::int64_t node : {std::int64_t{0}, n / 2, n - 1})
          checkNode(probe, node, 1.0 / order, stats,
                    cellShortName(type) + " P" + std::to_string(order) + " " + functionalName(f));
      }
  EXPECT_LE(stats.worstRatio, 1.0);
  // Most derivatives are resolved to 1e-4 (the rest are near-stationary: small against the
  // rounding of the energy they are differences of).
  EXPECT_GT(stats.sensitive, stats.checks / 2);
  std::printf("element nodes: %d checks, %d resolve 1e-4, worst |error| / bound %.3f\n",
              stats.checks, stats.sensitive, stats.worstRatio);
}

// A curved CAD mesh whose boundary nodes slide: the box with a cylindrical hole (nodes on its
// circles slide in t, on the cylinder and the planes in (u, v)), at order 3, not optimised.
MeshResult holeMesh() {
  MeshingOptions options;
  options.order = 3;
  options.size = 1.0;
  return runMeshPipeline(CadSource::brepText(test::brepText(test::boxWithHole())), options);
}

TEST(Optimiser, SlidingNodeDerivativesMatchFiniteDifferencesThroughTheCad) {
  const MeshResult r = holeMesh();
  for (const Functional f : kAll) {
    OptimiserOptions options;
    options.functional = f;
    const NodeEnergyProbe probe(r.mesh, options, r.cad.get());
    ProbeStats curve, face, inside;
    int curves = 0, faces = 0, interior = 0;
    for (std::int64_t node = 0; node < static_cast<std::int64_t>(r.mesh.numNodes()); ++node) {
      if (!probe.isFree(node)) continue;
      const int params = static_cast<int>(probe.coordinates(node).size());
      const int entity = r.mesh.nodeCadIndex[node];
      // Parameters: t on a circle of radius 1 and u on the cylinder are angles (spacing about
      // 1 / 3 of an element of size 1 over radius 1); plane parameters are lengths.
      const double spacing = 1.0 / 3.0;
      const std::string what =
          functionalName(f) + " " + cadEntityName(r.mesh.nodeCadDim[node], entity);
      if (params == 1 && curves < 6) {
        checkNode(probe, node, spacing, curve, what);
        ++curves;
      } else if (params == 2 && faces < 12) {
        checkNode(probe, node, spacing, face, what);
        ++faces;
      } else if (params == 3 && interior < 6) {
        checkNode(probe, node, spacing, inside, what);
        ++interior;
      }
    }
    EXPECT_EQ(curves, 6) << "no sliding curve nodes to check";
    EXPECT_EQ(faces, 12) << "no sliding face nodes to check";
    EXPECT_EQ(interior, 6);
    for (const ProbeStats* s : {&curve, &face, &inside}) {
      EXPECT_LE(s->worstRatio, 1.0);
      EXPECT_GT(s->sensitive, 0);
    }
    std::printf("%s: curve %d/%d, face %d/%d, interior %d/%d checks resolve 1e-4\n",
                functionalName(f).c_str(), curve.sensitive, curve.checks, face.sensitive,
                face.checks, inside.sensitive, inside.checks);
  }
}

// The same with the boundary facets' terms: the distortion (OptimiserOptions::facetWeight) and
// the fidelity to the CAD (fidelityWeight, its targets refreshed once as a sweep has them):
// the probe adds them to every sliding node's patch, before the chain rule through the CAD.
void checkFacetTerm(const MeshResult& r, const OptimiserOptions& options, const char* name) {
  const NodeEnergyProbe probe(r.mesh, options, r.cad.get());
  const OptimiserOptions plainOptions;
  const NodeEnergyProbe plain(r.mesh, plainOptions, r.cad.get());
  ProbeStats curve, face;
  int curves = 0, faces = 0;
  for (std::int64_t node = 0; node < static_cast<std::int64_t>(r.mesh.numNodes()); ++node) {
    if (!probe.isFree(node) || r.mesh.nodeCadDim[node] == 3) continue;
    const Eigen::VectorXd x = probe.coordinates(node);
    const double eps = probe.regularisation(node);
    // Nodes whose facets are off their ideal (on the cylinder and its circles): there the term
    // has a gradient of its own (on a plane a facet can be at its ideal, where it has none).
    const double with = probe.evaluate(node, x, eps).value;
    const double without = plain.evaluate(node, x, eps).value;
    if (!(with - without > 1e-6 * std::abs(with))) continue;
    const std::string what =
        std::string(name) + " " + cadEntityName(r.mesh.nodeCadDim[node], r.mesh.nodeCadIndex[node]);
    if (x.size() == 1 && curves < 6) {
      checkNode(probe, node, 1.0 / 3.0, curve, what);
      ++curves;
    } else if (x.size() == 2 && faces < 6) {
      checkNode(probe, node, 1.0 / 3.0, face, what);
      ++faces;
    }
  }
  EXPECT_EQ(curves, 6) << name;
  EXPECT_EQ(faces, 6) << name;
  for (const ProbeStats* s : {&curve, &face}) {
    EXPECT_LE(s->worstRatio, 1.0) << name;
    EXPECT_GT(s->sensitive, 0) << name;
  }
}

TEST(Optimiser, SlidingNodeDerivativesWithTheFacetTermMatchFiniteDifferences) {
  const MeshResult r = holeMesh();
  OptimiserOptions distortion;
  distortion.facetWeight = 1.0;
  checkFacetTerm(r, distortion, "facet term");
  // Weighted up so that the order-3 cylinder's small deviations (the term is their square)
  // show against the volume energy.
  OptimiserOptions fidelity;
  fidelity.fidelityWeight = 1000.0;
  checkFacetTerm(r, fidelity, "fidelity term");
}

TEST(Optimiser, NodeCheckCatchesAPlantedRelativeErrorOf1e4) {
  const MeshResult r = holeMesh();
  OptimiserOptions options;
  const NodeEnergyProbe probe(r.mesh, options, r.cad.get());
  int caught[4] = {0, 0, 0, 0};  // by coordinate count
  for (std::int64_t node = 0; node < static_cast<std::int64_t>(r.mesh.numNodes()); ++node) {
    if (!probe.isFree(node)) continue;
    const auto params = probe.coordinates(node).size();
    if (caught[params] > 0) continue;
    ProbeStats planted;
    checkNode(probe, node, 1.0 / 3.0, planted, "planted", 1e-4);
    if (planted.worstRatio > 1.0) ++caught[params];
  }
  EXPECT_GT(caught[1], 0) << "curve nodes";
  EXPECT_GT(caught[2], 0) << "face nodes";
  EXPECT_GT(caught[3], 0) << "interior nodes";
}

TEST(Optimiser, ProbeRefusesBadNodesAndCoordinates) {
  std::mt19937 rng(1);
  const Mesh mesh = oneElement(CellType::Tetrahedron, 2, 0.0, rng);
  const NodeEnergyProbe probe(mesh, OptimiserOptions{});
  EXPECT_THROW(probe.coordinates(-1), ParameterError);
  EXPECT_THROW(probe.coordinates(static_cast<std::int64_t>(mesh.numNodes())), ParameterError);
  EXPECT_THROW(probe.evaluate(0, Eigen::VectorXd::Zero(2), 1e-10), ParameterError);
}

// ---- Stationarity at the ideal -----------------------------------------------------------------

// The ideal element itself moved rigidly: F is a rotation at every point.
Mesh rotatedIdeal(CellType type, int order, const Eigen::Matrix3d& R) {
  std::mt19937 rng(0);
  Mesh m = oneElement(type, order, 0.0, rng);
  for (std::size_t i = 0; i < m.numNodes(); ++i) {
    const Eigen::Vector3d x = R * test::nodePoint(m, static_cast<std::int64_t>(i)) +
                              Eigen::Vector3d(5.0, -3.0, cellDimension(type) == 3 ? 2.0 : 0.0);
    for (int c = 0; c < 3; ++c) m.xyz[3 * i + c] = x[c];
  }
  return m;
}

// |gradient| of the patch energy at the node as it is, and a scale of its rounding: the
// gradient is a sum of terms of size about |H| times the element size (1), so its rounding is a
// few hundred u |H|; 1e-10 max(1, |H|) leaves a margin of 1e3 and more.
double stationarityRatio(const NodeEnergyProbe& probe, std::int64_t node) {
  const NodeEnergy at = probe.evaluate(node, probe.coordinates(node), 1e-10);
  return at.gradient.norm() / (1e-10 * std::max(1.0, at.hessian.norm()));
}

TEST(Optimiser, RotatedOrTranslatedIdealElementHasZeroGradient) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const Eigen::Matrix3d R2 = Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (const CellType type : {CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron,
                              CellType::Prism, CellType::Pyramid, CellType::Hexahedron})
    for (const int order : {1, 3, 5}) {
      const Mesh mesh = rotatedIdeal(type, order, cellDimension(type) == 2 ? R2 : R);
      // dW/dF = 0 at a rotation for these three functionals.
      for (const Functional f :
           {Functional::LinearElastic, Functional::Hyperelastic, Functional::Distortion}) {
        OptimiserOptions options;
        options.functional = f;
        const NodeEnergyProbe probe(mesh, options);
        for (std::int64_t node = 0; node < static_cast<std::int64_t>(mesh.numNodes()); ++node)
          EXPECT_LT(stationarityRatio(probe, node), 1.0)
              << cellShortName(type) << " P" << order << " " << functionalName(f) << " node "
              << node;
      }
    }
}

// Winslow's W = |F|^2 / J: in 2D dW/dF = 2R - |R|^2 R = 0 at a rotation R; in 3D it is -R, so a
// rotated ideal element is stationary only for moves that vanish on its boundary (the integral
// of -R a is zero exactly for interior nodes): check interior nodes everywhere, and that a 3D
// corner node is not stationary.
TEST(Optimiser, WinslowIsStationaryAtTheIdealForInteriorNodes) {
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1.0, -1.0, 2.0).normalized()).toRotationMatrix();
  const Eigen::Matrix3d R2 = Eigen::AngleAxisd(0.9, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  OptimiserOptions options;
  options.functional = Functional::Winslow;
  // Gmsh order lists interior nodes last.
  for (const auto& [type, order] : {std::pair{CellType::Triangle, 3},
                                    {CellType::Quadrilateral, 2},
                                    {CellType::Tetrahedron, 4},
                                    {CellType::Hexahedron, 2}}) {
    const bool planar = cellDimension(type) == 2;
    const Mesh mesh = rotatedIdeal(type, order, planar ? R2 : R);
    const NodeEnergyProbe probe(mesh, options);
    const auto last = static_cast<std::int64_t>(mesh.numNodes()) - 1;
    EXPECT_LT(stationarityRatio(probe, last), 1.0) << cellShortName(type);
    if (planar) {
      EXPECT_LT(stationarityRatio(probe, 0), 1.0) << cellShortName(type);
    } else {
      EXPECT_GT(probe.evaluate(0, probe.coordinates(0), 1e-10).gradient.norm(), 1e-3);
    }
  }
}

}  // namespace
}  // namespace homesh
