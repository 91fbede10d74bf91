// The pyramid in the element library, orders 1 to 10: Gmsh's node order, reference nodes and MSH
// type codes (to order 9, the highest Gmsh 4.8 has), a nodal basis that reproduces Bergot, Cohen
// and Durufle's space (its rational functions included) with their derivatives, interpolates at its
// nodes (the apex included), conforms to triangles and quadrilaterals on its faces, and a
// quadrature exact for that space to its degree.
#include <gmsh.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "element/quadrature.hpp"
#include "element/reference_element.hpp"
#include "io/gmsh_element_types.hpp"

namespace homesh {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// x^a y^b (1 - z)^(max(a, b) - a - b) z^c: with max(a, b) + c <= p these span the pyramid's
// space of order p (xi^a eta^b s^max(a,b) z^c, xi = x / s and eta = y / s, s = 1 - z; an
// affine image of Bergot's P_i(xi) P_j(eta) s^max(i,j) P_k(z) family), polynomials where a or b
// is 0, rational otherwise.
struct Term {
  int a, b, c;
  int shift() const { return std::max(a, b) - a - b; }
  double value(const double* x) const {
    return std::pow(x[0], a) * std::pow(x[1], b) * std::pow(1.0 - x[2], shift()) *
           std::pow(x[2], c);
  }
  // d/dx_k.
  double derivative(const double* x, int k) const {
    const double s = 1.0 - x[2];
    const double xa = std::pow(x[0], a), yb = std::pow(x[1], b);
    const double se = std::pow(s, shift()), zc = std::pow(x[2], c);
    if (k == 0) return a == 0 ? 0.0 : a * std::pow(x[0], a - 1) * yb * se * zc;
    if (k == 1) return b == 0 ? 0.0 : b * xa * std::pow(x[1], b - 1) * se * zc;
    const double dse = shift() == 0 ? 0.0 : -shift() * std::pow(s, shift() - 1);
    const double dzc = c == 0 ? 0.0 : c * std::pow(x[2], c - 1);
    return xa * yb * (dse * zc + se * dzc);
  }
  // The integral over the pyramid: x^a y^b over the square of side s gives
  // s^(a+b+2) / ((a+1)(b+1)), leaving z^c s^(max(a,b)+2), a Beta integral.
  double integral() const {
    const int m = std::max(a, b);
    return std::tgamma(c + 1.0) * std::tgamma(m + 3.0) / std::tgamma(m + c + 4.0) /
           ((a + 1.0) * (b + 1.0));
  }
};

std::vector<Term> space(int p) {
  std::vector<Term> out;
  for (int c = 0; c <= p; ++c)
    for (int b = 0; b <= p; ++b)
      for (int a = 0; a <= p; ++a)
        if (std::max(a, b) + c <= p) out.push_back({a, b, c});
  return out;
}

// A random point strictly inside the pyramid.
Eigen::Vector3d randomPoint(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.02, 0.98);
  const double z = u(rng);
  return {u(rng) * (1.0 - z), u(rng) * (1.0 - z), z};
}

TEST(Pyramid, NodesAreGmshsInGmshsOrder) {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  for (int p = 1; p <= 9; ++p) {
    std::string name;
    int dim = 0, order = 0, numNodes = 0, numPrimary = 0;
    std::vector<double> coord;
    gmsh::model::mesh::getElementProperties(gmsh::model::mesh::getElementType("Pyramid", p), name,
                                            dim, order, numNodes, coord, numPrimary);
    ASSERT_EQ(order, p);
    EXPECT_EQ(gmshElementType(CellType::Pyramid, p),
              gmsh::model::mesh::getElementType("Pyramid", p));  // MSH's type codes
    const ReferenceElement& ref = ReferenceElement::get(CellType::Pyramid, p);
    ASSERT_EQ(numNodes, ref.numNodes()) << name;
    ASSERT_EQ(ref.numNodes(), cellNumNodes(CellType::Pyramid, p));
    for (int i = 0; i < numNodes; ++i) {
      // Gmsh's pyramid has its base on [-1, 1]^2 and its apex above the base's centre: X = 2x +
      // z - 1, Y = 2y + z - 1 from ours (apex above the corner at the origin).
      const double x = ref.nodes()(i, 0), y = ref.nodes()(i, 1), z = ref.nodes()(i, 2);
      const double* g = &coord[3 * static_cast<std::size_t>(i)];
      // Coordinates are k / p and Gmsh's the same through a few operations: 1e-12 is slack; a
      // wrong node is off by 1 / p or more.
      ASSERT_NEAR(2.0 * x + z - 1.0, g[0], 1e-12) << name << " node " << i;
      ASSERT_NEAR(2.0 * y + z - 1.0, g[1], 1e-12) << name << " node " << i;
      ASSERT_NEAR(z, g[2], 1e-12) << name << " node " << i;
    }
  }
  gmsh::finalize();
}

TEST(Pyramid, BasisReproducesItsSpaceAndItsDerivatives) {
  std::mt19937 rng(5);
  for (int p = 1; p <= 10; ++p) {
    const ReferenceElement& ref = ReferenceElement::get(CellType::Pyramid, p);
    const std::vector<Term> terms = space(p);
    ASSERT_EQ(terms.size(), static_cast<std::size_t>(ref.numNodes()));
    Eigen::MatrixXd nodal(ref.numNodes(), static_cast<Eigen::Index>(terms.size()));
    for (int n = 0; n < ref.numNodes(); ++n) {
      const Eigen::Vector3d x = ref.nodes().row(n).transpose();
      const bool apex = x.z() == 1.0;
      for (std::size_t m = 0; m < terms.size(); ++m)  // at the apex: the limit, 0 or 1
        nodal(n, static_cast<Eigen::Index>(m)) =
            apex ? (terms[m].a + terms[m].b == 0 ? 1.0 : 0.0) : terms[m].value(x.data());
    }
    Eigen::VectorXd values;
    Eigen::MatrixXd gradients;
    for (int trial = 0; trial < 4; ++trial) {
      const Eigen::Vector3d xi = randomPoint(rng);
      ref.evaluate(xi.data(), values, gradients);
      const Eigen::VectorXd f = nodal.transpose() * values;
      const Eigen::MatrixXd df = nodal.transpose() * gradients;
      // Rounding as for the other shapes (test_basis_quadrature.cpp): N eps times the Lebesgue
      // function of the values or of the derivatives; the terms are at most 1 at the nodes.
      // Measured: at most 0.10 of it for values and 0.29 for derivatives on every order; the
      // tolerance is 8 times it.
      const auto n = static_cast<double>(ref.numNodes());
      for (std::size_t m = 0; m < terms.size(); ++m) {
        const auto row = static_cast<Eigen::Index>(m);
        ASSERT_NEAR(f(row), terms[m].value(xi.data()), 8.0 * n * kEps * values.cwiseAbs().sum())
            << "order " << p << " term " << terms[m].a << terms[m].b << terms[m].c;
        for (int k = 0; k < 3; ++k)
          ASSERT_NEAR(df(row, k), terms[m].derivative(xi.data(), k),
                      8.0 * n * kEps * gradients.col(k).cwiseAbs().sum())
              << "order " << p << " term " << terms[m].a << terms[m].b << terms[m].c << " d" << k;
      }
    }
  }
}

TEST(Pyramid, BasisIsOneAtItsNodeAndZeroAtTheOthersApexIncluded) {
  for (int p = 1; p <= 10; ++p) {
    const ReferenceElement& ref = ReferenceElement::get(CellType::Pyramid, p);
    const Eigen::MatrixXd at = ref.valuesAt(ref.nodes());
    // V^-1 applied to V's own rows: its error grows with N eps and V's conditioning; 1e-9 holds
    // it at order 10 (measured 3e-14) and is far below the 1 a wrong apex value gives.
    ASSERT_LT(
        (at - Eigen::MatrixXd::Identity(ref.numNodes(), ref.numNodes())).cwiseAbs().maxCoeff(),
        1e-9)
        << "order " << p;
  }
}

// On a face, every basis function of a node off that face vanishes: the trace is the
// triangle's (P_p) or the quadrilateral's (Q_p) interpolant of the face's own nodes, so
// pyramids conform to tetrahedra, prisms and hexahedra.
TEST(Pyramid, FunctionsOfNodesOffAFaceVanishOnIt) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Each face as a test of a point's lattice position and a random point on it.
  struct Face {
    const char* name;
    bool (*on)(const Eigen::Vector3d&);
    Eigen::Vector3d (*sample)(double, double);
  };
  const Face faces[] = {
      {"base", [](const Eigen::Vector3d& x) { return std::abs(x.z()) < 1e-12; },
       [](double s, double t) { return Eigen::Vector3d(s, t, 0.0); }},
      {"y = 0", [](const Eigen::Vector3d& x) { return std::abs(x.y()) < 1e-12; },
       [](double s, double t) { return Eigen::Vector3d(s * (1.0 - t), 0.0, t); }},
      {"x = 0", [](const Eigen::Vector3d& x) { return std::abs(x.x()) < 1e-12; },
       [](double s, double t) { return Eigen::Vector3d(0.0, s * (1.0 - t), t); }},
      {"x = 1 - z", [](const Eigen::Vector3d& x) { return std::abs(x.x() + x.z() - 1.0) < 1e-12; },
       [](double s, double t) { return Eigen::Vector3d(1.0 - t, s * (1.0 - t), t); }},
      {"y = 1 - z", [](const Eigen::Vector3d& x) { return std::abs(x.y() + x.z() - 1.0) < 1e-12; },
       [](double s, double t) { return Eigen::Vector3d(s * (1.0 - t), 1.0 - t, t); }},
  };
  for (int p = 1; p <= 10; ++p) {
    const ReferenceElement& ref = ReferenceElement::get(CellType::Pyramid, p);
    Eigen::VectorXd values;
    Eigen::MatrixXd gradients;
    for (const Face& face : faces)
      for (int trial = 0; trial < 3; ++trial) {
        const Eigen::Vector3d x = face.sample(u(rng), 0.95 * u(rng));
        ref.evaluate(x.data(), values, gradients);
        double off = 0.0;
        for (int n = 0; n < ref.numNodes(); ++n)
          if (!face.on(ref.nodes().row(n).transpose())) off += std::abs(values(n));
        // The same rounding bound as the reproduction test, N eps times the Lebesgue function
        // (measured: at most 1.5 of it), 8 times.
        EXPECT_LT(off, 8.0 * ref.numNodes() * kEps * values.cwiseAbs().sum())
            << "order " << p << " face " << face.name;
      }
  }
}

TEST(Pyramid, QuadratureIsExactForItsSpaceToItsDegree) {
  for (int degree = 0; degree <= 22; ++degree) {
    const QuadratureRule rule = quadratureRule(CellType::Pyramid, degree);
    ASSERT_EQ(rule.dim, 3);
    for (const Term& t : space(degree)) {
      double sum = 0.0, magnitude = 0.0;
      for (int q = 0; q < rule.size(); ++q) {
        const double term = rule.weights[static_cast<std::size_t>(q)] *
                            t.value(&rule.points[static_cast<std::size_t>(q) * 3]);
        sum += term;
        magnitude += std::abs(term);
      }
      // As for the other shapes (test_basis_quadrature.cpp): n eps of the sum's magnitude for
      // the sum, (5 degree + 5) eps for each term; 8 times that.
      const double tol = 8.0 * (rule.size() + 5.0 * degree + 5.0) * kEps * magnitude;
      ASSERT_NEAR(sum, t.integral(), tol) << "degree " << degree << " term " << t.a << t.b << t.c;
    }
    // And every polynomial of the degree, whose terms leave the space's where a and b are both
    // positive: x^a y^b z^c with a + b + c <= degree.
    for (int c = 0; c <= degree; ++c)
      for (int b = 0; b + c <= degree; ++b)
        for (int a = 0; a + b + c <= degree; ++a) {
          double sum = 0.0, magnitude = 0.0;
          for (int q = 0; q < rule.size(); ++q) {
            const double* x = &rule.points[static_cast<std::size_t>(q) * 3];
            const double term = rule.weights[static_cast<std::size_t>(q)] * std::pow(x[0], a) *
                                std::pow(x[1], b) * std::pow(x[2], c);
            sum += term;
            magnitude += std::abs(term);
          }
          const double exact = std::tgamma(c + 1.0) * std::tgamma(a + b + 3.0) /
                               std::tgamma(a + b + c + 4.0) / ((a + 1.0) * (b + 1.0));
          const double tol = 8.0 * (rule.size() + 5.0 * degree + 5.0) * kEps * magnitude;
          ASSERT_NEAR(sum, exact, tol)
              << "degree " << degree << " x^" << a << " y^" << b << " z^" << c;
        }
  }
}

TEST(Pyramid, SamplingLatticeIsTheNodeLattice) {
  for (int n = 1; n <= 10; ++n) {
    std::vector<LatticePoint> sampled = samplingLattice(CellType::Pyramid, n);
    std::vector<LatticePoint> nodes = ReferenceElement::get(CellType::Pyramid, n).lattice();
    std::sort(sampled.begin(), sampled.end());
    std::sort(nodes.begin(), nodes.end());
    ASSERT_EQ(sampled, nodes) << "n = " << n;
  }
}

}  // namespace
}  // namespace homesh
