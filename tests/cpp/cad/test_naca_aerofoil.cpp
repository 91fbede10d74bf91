// The NACA 4-digit domain: topology and numbering (the aerofoil is Edge5 and Edge6, as NekMesh's
// .mcf expects), the B-spline surfaces against the analytic profile, cambered aerofoils, bad
// inputs, and a linear mesh of NekMesh's NACA 0012 case.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "cad/naca_aerofoil.hpp"
#include "core/error.hpp"
#include "linear/linear_mesher.hpp"

namespace homesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The analytic NACA 4-digit profile, written out independently of the code under test.
struct Profile {
  double m, p, t;
  double yt(double x) const {
    return 5 * t *
           (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x -
            0.1036 * x * x * x * x);
  }
  double yc(double x) const {
    if (m == 0) return 0;
    if (x <= p) return m / (p * p) * (2 * p * x - x * x);
    return m / ((1 - p) * (1 - p)) * ((1 - 2 * p) + 2 * p * x - x * x);
  }
  double slope(double x) const {
    if (m == 0) return 0;
    if (x <= p) return 2 * m / (p * p) * (p - x);
    return 2 * m / ((1 - p) * (1 - p)) * (p - x);
  }
  Eigen::Vector3d point(double x, bool upper) const {
    const double th = std::atan(slope(x)), s = upper ? 1.0 : -1.0;
    return {x - s * yt(x) * std::sin(th), yc(x) + s * yt(x) * std::cos(th), 0.0};
  }
};

// Rotation about the origin by `degrees` (counter-clockwise).
Eigen::Vector3d rotated(const Eigen::Vector3d& p, double degrees) {
  const double a = degrees * kPi / 180, c = std::cos(a), s = std::sin(a);
  return {c * p.x() - s * p.y(), s * p.x() + c * p.y(), p.z()};
}

const std::vector<double> kStations = {0.0005, 0.0025, 0.01, 0.03, 0.07, 0.1,  0.2,  0.2998,
                                       0.4,    0.45,   0.6,  0.8,  0.9,  0.95, 0.99, 0.999};

// Every analytic surface point (rotated by -AOA) lies within 1e-6 of its edge: the B-spline
// is promised within about 1e-7 chord of the formula (naca_aerofoil.hpp), the projection to
// 1e-9 of the bounding diagonal; 1e-6 leaves a factor 10.
void expectOnProfile(const CadModel& cad, const Profile& f, double aoa) {
  for (const double x : kStations) {
    for (const bool upper : {true, false}) {
      const Eigen::Vector3d p = rotated(f.point(x, upper), -aoa);
      const CurveProjection proj = cad.projectOnCurve(upper ? 5 : 6, p);
      EXPECT_LT(proj.distance, 1e-6) << (upper ? "upper" : "lower") << " x = " << x;
    }
  }
}

// Points of an edge, rotated back to the aerofoil's frame (AOA undone).
std::vector<Eigen::Vector3d> unrotatedSamples(const CadModel& cad, int edge, double aoa, int n) {
  const ParameterRange r = cad.edgeRange(edge);
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i <= n; ++i)
    out.push_back(
        rotated(cad.evaluateCurve(edge, r.first + (r.last - r.first) * i / n).point, aoa));
  return out;
}

TEST(NacaAerofoil, Naca0012At15DegreesInTheMcfBox) {
  const NacaDomain d{"0012", -1.0, -2.0, 3.0, 2.0, 15.0};  // 2d_bl_naca0012.mcf
  const CadModel cad = makeNacaDomain(d);
  EXPECT_EQ(cad.sourceName(), "NACA 0012");
  ASSERT_EQ(cad.numFaces(), 1);
  ASSERT_EQ(cad.numEdges(), 6);
  ASSERT_EQ(cad.numVertices(), 6);
  EXPECT_EQ(cad.numSolids(), 0);
  ASSERT_TRUE(cad.isPlanar(1));
  const auto [origin, normal] = cad.plane(1);
  EXPECT_NEAR(origin.z(), 0.0, 1e-15);
  EXPECT_NEAR(std::abs(normal.z()), 1.0, 1e-12);
  EXPECT_EQ(cad.subShapeIndices(2, 1, 1), (std::vector<int>{1, 2, 3, 4, 5, 6}));

  // Vertex1..4 the corners counter-clockwise, Vertex5 the leading and Vertex6 the trailing edge.
  const std::vector<Eigen::Vector3d> corners = {{-1, -2, 0}, {3, -2, 0}, {3, 2, 0}, {-1, 2, 0}};
  for (int v = 1; v <= 4; ++v) EXPECT_LT((cad.vertexPoint(v) - corners[v - 1]).norm(), 1e-15);
  // The corners and the leading edge are exact inputs (the origin stays the origin under the
  // rotation); the trailing edge is cos and sin of the same angle, a few roundings.
  const Eigen::Vector3d le = cad.vertexPoint(5), te = cad.vertexPoint(6);
  EXPECT_LT(le.norm(), 1e-15);
  EXPECT_LT((te - rotated({1, 0, 0}, -15)).norm(), 1e-12);
  EXPECT_GT(le.y(), te.y());  // a positive AOA raises the leading edge

  // Edge1..4 the rectangle's sides (bottom, right, top, left), straight.
  for (int e = 1; e <= 4; ++e) {
    const int a = e, b = e % 4 + 1;  // sorted indices
    EXPECT_EQ(cad.subShapeIndices(1, e, 0), (std::vector<int>{std::min(a, b), std::max(a, b)}));
    const ParameterRange r = cad.edgeRange(e);
    const Eigen::Vector3d mid = cad.evaluateCurve(e, 0.5 * (r.first + r.last)).point;
    EXPECT_LT((mid - 0.5 * (corners[e - 1] + corners[e % 4])).norm(), 1e-12) << "Edge" << e;
  }

  // Edge5 and Edge6 share both ends: the trailing edge is closed.
  EXPECT_EQ(cad.subShapeIndices(1, 5, 0), (std::vector<int>{5, 6}));
  EXPECT_EQ(cad.subShapeIndices(1, 6, 0), (std::vector<int>{5, 6}));
  for (const int e : {5, 6}) {
    const ParameterRange r = cad.edgeRange(e);
    const Eigen::Vector3d a = cad.evaluateCurve(e, r.first).point;
    const Eigen::Vector3d b = cad.evaluateCurve(e, r.last).point;
    EXPECT_LT(std::min((a - le).norm(), (a - te).norm()), 1e-12);
    EXPECT_LT(std::min((b - le).norm(), (b - te).norm()), 1e-12);
    EXPECT_GT((a - b).norm(), 0.99);
  }

  const Profile f{0.0, 0.0, 0.12};
  expectOnProfile(cad, f, 15.0);

  // Curve points, AOA undone, on y = +-yt(x): Edge5 above, Edge6 below.
  double maxUpper = 0.0, maxLower = 0.0, xAtMax = 0.0;
  for (const int e : {5, 6}) {
    for (const Eigen::Vector3d& p : unrotatedSamples(cad, e, 15.0, 400)) {
      EXPECT_GT(p.x(), -1e-12);
      EXPECT_LT(p.x(), 1.0 + 1e-12);
      const double x = std::clamp(p.x(), 0.0, 1.0);
      if (x > 0.02) {
        EXPECT_NEAR(std::abs(p.y()), f.yt(x), 1e-6) << "Edge" << e << " x = " << x;
      }
      if (e == 5) {
        EXPECT_GT(p.y(), -1e-12);
        if (p.y() > maxUpper) xAtMax = x;
        maxUpper = std::max(maxUpper, p.y());
      } else {
        EXPECT_LT(p.y(), 1e-12);
        maxLower = std::max(maxLower, -p.y());
      }
    }
  }
  // 0.1199 with the closed trailing edge; 400 samples put one within 5e-3 of x = 0.3, where
  // the thickness is flat to 4e-6.
  EXPECT_NEAR(maxUpper + maxLower, 0.12, 5e-4);
  EXPECT_NEAR(xAtMax, 0.3, 0.02);
}

TEST(NacaAerofoil, CamberedNaca2412) {
  const NacaDomain d{"2412", -0.5, -1.0, 2.0, 1.0, 5.0};
  const CadModel cad = makeNacaDomain(d);
  EXPECT_EQ(cad.sourceName(), "NACA 2412");
  ASSERT_EQ(cad.numEdges(), 6);
  const Profile f{0.02, 0.4, 0.12};
  expectOnProfile(cad, f, 5.0);
  EXPECT_LT(cad.vertexPoint(5).norm(), 1e-15);
  EXPECT_LT((cad.vertexPoint(6) - rotated({1, 0, 0}, -5)).norm(), 1e-12);

  // At the camber maximum (x = p, zero slope) the mid-point of the surfaces is the camber 0.02.
  const Eigen::Vector3d up =
      rotated(cad.projectOnCurve(5, rotated(f.point(0.4, true), -5)).point, 5);
  const Eigen::Vector3d lo =
      rotated(cad.projectOnCurve(6, rotated(f.point(0.4, false), -5)).point, 5);
  EXPECT_NEAR(0.5 * (up.y() + lo.y()), 0.02, 1e-6);
  EXPECT_NEAR(up.y() - lo.y(), 2 * f.yt(0.4), 1e-6);

  // The camber lifts the lower surface by yc(0.8) = 0.011 above the symmetric 0012's.
  const Eigen::Vector3d aft =
      rotated(cad.projectOnCurve(6, rotated(f.point(0.8, false), -5)).point, 5);
  // yc(0.8) = 0.01111; the rest is yt (1 - cos theta) and the x shift, 3e-5 and 1e-4.
  EXPECT_NEAR(aft.y() + f.yt(0.8), 0.0111, 1e-3);
}

TEST(NacaAerofoil, NegativeAngleAndSymmetry) {
  const CadModel plus = makeNacaDomain({"0015", -1, -1, 2, 1, 10});
  const CadModel minus = makeNacaDomain({"0015", -1, -1, 2, 1, -10});
  EXPECT_LT(minus.vertexPoint(5).y(), minus.vertexPoint(6).y());  // leading edge lowered
  // A symmetric aerofoil at -AOA is the mirror image (y -> -y) of the one at +AOA, upper and
  // lower swapped.
  const Profile f{0, 0, 0.15};
  for (const double x : kStations) {
    Eigen::Vector3d p = rotated(f.point(x, true), -10);
    EXPECT_LT(plus.projectOnCurve(5, p).distance, 1e-6);
    p.y() = -p.y();
    EXPECT_LT(minus.projectOnCurve(6, p).distance, 1e-6) << x;
  }
}

std::string parameterError(const NacaDomain& d) {
  try {
    makeNacaDomain(d);
  } catch (const ParameterError& e) {
    return e.what();
  }
  return "";
}

TEST(NacaAerofoil, RejectsBadInputs) {
  const auto withDigits = [](const std::string& digits) {
    return NacaDomain{digits, -1, -2, 3, 2, 15};
  };
  for (const char* digits : {"12", "00123", "00a2", "", "0 12"})
    EXPECT_NE(parameterError(withDigits(digits)).find("NACA digits must be exactly 4 digits"),
              std::string::npos)
        << digits;
  EXPECT_NE(parameterError(withDigits("0000")).find("thickness"), std::string::npos);
  EXPECT_NE(parameterError(withDigits("2012")).find("camber position"), std::string::npos);

  const auto boxError = [](double xmin, double ymin, double xmax, double ymax, double aoa) {
    return parameterError({"0012", xmin, ymin, xmax, ymax, aoa});
  };
  EXPECT_NE(boxError(-1, -2, 0.9, 2, 0).find("Xmax (0.9) must be at least"), std::string::npos);
  EXPECT_NE(boxError(0.0, -2, 3, 2, 0).find("Xmin (0) must be at most"), std::string::npos);
  EXPECT_NE(boxError(-1, -2, 3, 0.05, 0).find("Ymax (0.05)"), std::string::npos);
  // At 15 degrees the trailing edge drops to y = -0.259.
  EXPECT_NE(boxError(-1, -0.2, 3, 2, 15).find("Ymin (-0.2)"), std::string::npos);
  EXPECT_NO_THROW(makeNacaDomain({"0012", -1, -0.3, 3, 2, 15}));
  EXPECT_NE(boxError(-1, -2, 3, 2, std::nan("")).find("AOA must be a finite number"),
            std::string::npos);
  EXPECT_NE(boxError(2, -2, -1, 2, 0).find("Xmin"), std::string::npos);
}

TEST(NacaAerofoil, MeshesTheNekMeshCase) {
  const CadModel cad = makeNacaDomain({"0012", -1.0, -2.0, 3.0, 2.0, 15.0});
  LinearMeshOptions options;
  options.size = 0.1;
  const Mesh mesh = generateLinearMesh(cad, options);
  EXPECT_EQ(mesh.dim, 2);
  // 16 / (0.43 * 0.1^2) = 3700 triangles (measured 3752); 2 chords / 0.1 = 20 nodes on the
  // aerofoil (measured 20): the bounds leave 70 % and 25 % for Gmsh's choices.
  EXPECT_GT(mesh.numElements(), 1000u);
  int onAerofoil = 0;
  for (std::size_t i = 0; i < mesh.numNodes(); ++i)
    if (mesh.nodeCadDim[i] == 1 && (mesh.nodeCadIndex[i] == 5 || mesh.nodeCadIndex[i] == 6))
      ++onAerofoil;
  EXPECT_GT(onAerofoil, 15);
}

}  // namespace
}  // namespace homesh
