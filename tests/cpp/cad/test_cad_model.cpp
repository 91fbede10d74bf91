// CadModel against analytic shapes: loading, FreeCAD numbering, evaluation, projection and
// curvature on a sphere, a cylinder and a torus.
#include <gtest/gtest.h>

#include <BRep_Tool.hxx>
#include <Geom_Surface.hxx>
#include <STEPControl_Writer.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <cmath>
#include <fstream>
#include <limits>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

using test::toModel;

// The first face of the given kind (OCCT's primitive makers put the lateral face first).
int lateralFace(const CadModel& cad) {
  for (int f = 1; f <= cad.numFaces(); ++f)
    if (!cad.isPlanar(f)) return f;
  return 0;
}

TEST(CadModel, LoadsStepIgesAndBrepFilesWithTheSameTopology) {
  const auto dir = test::tempDir();
  const TopoDS_Shape shape = test::boxWithHole();
  const std::string brep = (dir / "part.brep").string();
  ASSERT_TRUE(BRepTools::Write(shape, brep.c_str()));
  STEPControl_Writer writer;
  writer.Transfer(shape, STEPControl_AsIs);
  const std::string step = (dir / "part.STEP").string();  // upper-case extension on purpose
  ASSERT_EQ(writer.Write(step.c_str()), IFSelect_RetDone);

  for (const std::string& path : {brep, step}) {
    const CadModel cad = CadModel::fromFile(path);
    EXPECT_EQ(cad.numSolids(), 1) << path;
    EXPECT_EQ(cad.numFaces(), 7) << path;
    EXPECT_EQ(cad.numEdges(), 15) << path;
    EXPECT_EQ(cad.numVertices(), 10) << path;
  }
}

TEST(CadModel, NumberingIsTopExpMapShapes) {
  const TopoDS_Shape shape = test::boxWithHole();
  const CadModel cad = toModel(shape);
  // BRep text keeps sub-shape order, so the model's FaceN is the N-th MapShapes entry of the
  // original shape: compare by geometry (the vertices' coordinates are small integers, which
  // the BRep text keeps exactly; 1e-12 is slack).
  TopTools_IndexedMapOfShape vertices;
  TopExp::MapShapes(shape, TopAbs_VERTEX, vertices);
  ASSERT_EQ(vertices.Extent(), cad.numVertices());
  for (int v = 1; v <= vertices.Extent(); ++v) {
    const gp_Pnt p = BRep_Tool::Pnt(TopoDS::Vertex(vertices(v)));
    EXPECT_NEAR((cad.vertexPoint(v) - Eigen::Vector3d(p.X(), p.Y(), p.Z())).norm(), 0.0, 1e-12);
  }
  const std::vector<int> faceEdges = cad.subShapeIndices(2, 1, 1);
  EXPECT_FALSE(faceEdges.empty());
  EXPECT_EQ(cad.subShapeIndices(3, 1, 2).size(), 7u);
}

TEST(CadModel, SphereEvaluationProjectionAndCurvature) {
  const double r = 2.0;
  const CadModel cad = toModel(test::sphere(r));
  ASSERT_EQ(cad.numFaces(), 1);
  const SurfaceBounds b = cad.faceBounds(1);
  EXPECT_NEAR(b.uMax - b.uMin, 2 * M_PI, 1e-9);
  // OCCT's sphere: P(u, v) = r (cos v cos u, cos v sin u, sin v).
  const double u = 0.7, v = 0.3;
  const SurfaceDerivatives d = cad.evaluateSurface(1, u, v);
  // OCCT evaluates the same closed form: a few roundings of |P| = r apart.
  EXPECT_NEAR((d.point - r * Eigen::Vector3d(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u),
                                             std::sin(v)))
                  .norm(),
              0.0, 1e-12);
  // First and second derivatives against central differences. Every derivative of P has norm
  // <= r, and each evaluation of P is off by a few ulps of r (at most 4 eps r, say), so per
  // component: first differences err by <= h^2 r / 6 (truncation) + 4 eps r / h (rounding),
  // second differences by <= h^2 r / 12 + 16 eps r / h^2, the mixed one by <= h^2 r / 3 +
  // 4 eps r / h^2. The tolerance is 10x that bound (sqrt 3 for the norm, and margin); h is
  // chosen near the minimum of each bound.
  const double eps = std::numeric_limits<double>::epsilon();
  const auto p = [&](double uu, double vv) { return cad.evaluateSurface(1, uu, vv).point; };
  const double h1 = 1e-5, h2 = 1e-4;
  const double tol1 = 10 * (h1 * h1 * r / 6 + 4 * eps * r / h1);             // 2.1e-9
  const double tol2 = 10 * (h2 * h2 * r / 12 + 16 * eps * r / (h2 * h2));    // 7e-6
  const double tolMixed = 10 * (h2 * h2 * r / 3 + 4 * eps * r / (h2 * h2));  // 1.9e-6
  EXPECT_NEAR((d.du - (p(u + h1, v) - p(u - h1, v)) / (2 * h1)).norm(), 0.0, tol1);
  EXPECT_NEAR((d.dv - (p(u, v + h1) - p(u, v - h1)) / (2 * h1)).norm(), 0.0, tol1);
  EXPECT_NEAR((d.duu - (p(u + h2, v) - 2 * d.point + p(u - h2, v)) / (h2 * h2)).norm(), 0.0, tol2);
  EXPECT_NEAR((d.dvv - (p(u, v + h2) - 2 * d.point + p(u, v - h2)) / (h2 * h2)).norm(), 0.0, tol2);
  EXPECT_NEAR(
      (d.duv - (p(u + h2, v + h2) - p(u + h2, v - h2) - p(u - h2, v + h2) + p(u - h2, v - h2)) /
                   (4 * h2 * h2))
          .norm(),
      0.0, tolMixed);

  // Projection is OCCT's iterative search to 1e-9 of the bounding diagonal (CadModel's
  // promise); the projected point is then evaluated on the surface, so it lies on it to rounding.
  const double projection = 1e-9 * cad.boundingDiagonal();
  for (const Eigen::Vector3d& q :
       {Eigen::Vector3d(3, 1, -2), Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(-1, 4, 0.5)}) {
    const SurfaceProjection proj = cad.projectOnSurface(1, q);
    EXPECT_NEAR(proj.distance, std::abs(q.norm() - r), projection);
    EXPECT_NEAR((proj.point - r * q.normalized()).norm(), 0.0, projection);
    EXPECT_NEAR((cad.evaluateSurface(1, proj.u, proj.v).point - proj.point).norm(), 0.0, 1e-12);
  }

  // Convex: both principal curvatures are -1/r against the outward normal. Curvatures come from
  // the exact derivatives through a few products and one 2 x 2 eigenproblem: rounding ~1e-15/r,
  // so 1e-9 is slack (the same holds for every curvature below; zero curvatures come from
  // second derivatives that are exactly zero).
  const PrincipalCurvatures k = cad.curvature(1, u, v);
  ASSERT_TRUE(k.defined);
  EXPECT_NEAR(k.kMin, -1.0 / r, 1e-9);
  EXPECT_NEAR(k.kMax, -1.0 / r, 1e-9);
}

// A projection onto an edge stays on the edge: the sphere's seam is half of a circle (x >= 0 in
// the plane y = 0), and a point on the circle's other half is not on it. OCCT projects onto the
// whole circle there (distance 0, at a parameter beyond the edge); the nearest point of the edge
// is then the nearer pole, and node classification must not put the point on the seam.
TEST(CadModel, ProjectionOntoASeamStaysOnTheSeam) {
  const double r = 0.5;
  const CadModel cad = toModel(test::sphere(r));
  int seam = 0;
  for (int e = 1; e <= cad.numEdges(); ++e)
    if (!cad.isDegenerated(e)) seam = e;
  ASSERT_GT(seam, 0);
  const ParameterRange range = cad.edgeRange(seam);
  const double projection = 1e-9 * cad.boundingDiagonal();
  const double a = 22.5 * M_PI / 180.0;  // from the north pole, on the far half
  const Eigen::Vector3d q(-r * std::sin(a), 0.0, r * std::cos(a));
  const CurveProjection proj = cad.projectOnCurve(seam, q);
  EXPECT_GE(proj.t, range.first);
  EXPECT_LE(proj.t, range.last);
  EXPECT_NEAR((proj.point - Eigen::Vector3d(0, 0, r)).norm(), 0.0, projection);
  EXPECT_NEAR(proj.distance, 2 * r * std::sin(a / 2), projection);
  // On the seam's own half the projection is the point itself.
  const Eigen::Vector3d onSeam(r * std::sin(a), 0.0, r * std::cos(a));
  EXPECT_NEAR(cad.projectOnCurve(seam, onSeam).distance, 0.0, projection);
}

TEST(CadModel, CurvatureSignFollowsTheOutwardNormal) {
  // The wall of a hole bends towards the solid's outward normal (+1/r); a cylinder's side
  // bends away from it (-1/r). Both have a zero curvature along the axis.
  const CadModel holed = toModel(test::boxWithHole());
  const CadModel solid = toModel(test::cylinder(1.0, 2.0));
  for (const auto* model : {&holed, &solid}) {
    const int f = lateralFace(*model);
    ASSERT_GT(f, 0);
    const SurfaceBounds b = model->faceBounds(f);
    const PrincipalCurvatures k =
        model->curvature(f, 0.5 * (b.uMin + b.uMax), 0.5 * (b.vMin + b.vMax));
    ASSERT_TRUE(k.defined);
    if (model == &holed) {
      EXPECT_NEAR(k.kMin, 0.0, 1e-12);
      EXPECT_NEAR(k.kMax, 1.0, 1e-9);
    } else {
      EXPECT_NEAR(k.kMin, -1.0, 1e-9);
      EXPECT_NEAR(k.kMax, 0.0, 1e-12);
    }
  }
}

TEST(CadModel, CylinderCurvesAndCurvature) {
  const double r = 1.5, height = 3.0;
  const CadModel cad = toModel(test::cylinder(r, height));
  const int lateral = lateralFace(cad);
  ASSERT_GT(lateral, 0);
  const SurfaceBounds b = cad.faceBounds(lateral);
  const PrincipalCurvatures k =
      cad.curvature(lateral, 0.5 * (b.uMin + b.uMax), 0.5 * (b.vMin + b.vMax));
  ASSERT_TRUE(k.defined);
  const double small = std::min(std::abs(k.kMin), std::abs(k.kMax));
  const double large = std::max(std::abs(k.kMin), std::abs(k.kMax));
  EXPECT_NEAR(small, 0.0, 1e-12);
  EXPECT_NEAR(large, 1.0 / r, 1e-9);

  // The circular edges: radius r around the axis, |c'| = r, c'' points to the axis with |c''| = r.
  int circles = 0;
  for (int e = 1; e <= cad.numEdges(); ++e) {
    if (cad.isDegenerated(e)) continue;
    const ParameterRange range = cad.edgeRange(e);
    const double t = 0.3 * range.first + 0.7 * range.last;
    const CurveDerivatives c = cad.evaluateCurve(e, t);
    const Eigen::Vector2d radial(c.point.x(), c.point.y());
    if (std::abs(radial.norm() - r) > 1e-9 || std::abs(c.d1.z()) > 1e-12) continue;  // the seam
    ++circles;
    EXPECT_NEAR(c.d1.norm(), r, 1e-9);
    EXPECT_NEAR(c.d2.norm(), r, 1e-9);
    EXPECT_NEAR(c.d2.head<2>().normalized().dot(-radial.normalized()), 1.0, 1e-9);
    // Projection of a point off the circle.
    const Eigen::Vector3d q(3.0, -1.0, c.point.z() + 0.5);
    const CurveProjection proj = cad.projectOnCurve(e, q);
    const Eigen::Vector3d expected = Eigen::Vector3d(
        r * q.x() / std::hypot(q.x(), q.y()), r * q.y() / std::hypot(q.x(), q.y()), c.point.z());
    // OCCT's projection precision: 1e-9 of the bounding diagonal.
    EXPECT_NEAR((proj.point - expected).norm(), 0.0, 1e-9 * cad.boundingDiagonal());
    EXPECT_NEAR((cad.evaluateCurve(e, proj.t).point - proj.point).norm(), 0.0, 1e-12);
    // Each circle is closed at one vertex: both parameters are valid, `near` picks one (OCCT
    // stores them exactly: 0 and 2 pi as the edge's range).
    const std::vector<int> ends = cad.subShapeIndices(1, e, 0);
    ASSERT_EQ(ends.size(), 1u);
    EXPECT_NEAR(cad.vertexParameter(ends[0], e, range.last - 0.1), range.last, 1e-12);
    EXPECT_NEAR(cad.vertexParameter(ends[0], e, range.first + 0.1), range.first, 1e-12);
  }
  EXPECT_EQ(circles, 2);
}

TEST(CadModel, TorusPrincipalCurvatures) {
  const double major = 3.0, minor = 1.0;
  const CadModel cad = toModel(test::torus(major, minor));
  ASSERT_EQ(cad.numFaces(), 1);
  // OCCT's torus: P(u, v) = ((R + r cos v) cos u, (R + r cos v) sin u, r sin v).
  for (const double v : {0.0, M_PI}) {
    const PrincipalCurvatures k = cad.curvature(1, 0.4, v);
    ASSERT_TRUE(k.defined);
    const double distance = major + minor * std::cos(v);  // from the axis
    double expected[2] = {1.0 / minor, std::cos(v) / distance};
    double got[2] = {k.kMin, k.kMax};
    // Compare magnitudes and the product's sign (Gaussian curvature: + outside, - inside).
    std::sort(expected, expected + 2, [](double a, double b) { return std::abs(a) < std::abs(b); });
    std::sort(got, got + 2, [](double a, double b) { return std::abs(a) < std::abs(b); });
    EXPECT_NEAR(std::abs(got[0]), std::abs(expected[0]), 1e-9) << "v = " << v;
    EXPECT_NEAR(std::abs(got[1]), std::abs(expected[1]), 1e-9) << "v = " << v;
    EXPECT_GT(got[0] * got[1] * expected[0] * expected[1], 0.0) << "v = " << v;
  }
}

TEST(CadModel, PeriodsTrimmingAndTolerances) {
  const CadModel sphere = test::toModel(test::sphere(1.0));
  const auto ps = sphere.facePeriods(1);
  EXPECT_DOUBLE_EQ(ps[0], 2.0 * M_PI);
  EXPECT_EQ(ps[1], 0.0);
  const CadModel torus = test::toModel(test::torus(1.0, 0.3));
  EXPECT_DOUBLE_EQ(torus.facePeriods(1)[0], 2.0 * M_PI);
  EXPECT_DOUBLE_EQ(torus.facePeriods(1)[1], 2.0 * M_PI);
  // The box with a hole: the face whose plane is z = 2 is trimmed by the hole's circle around
  // (2, 2); its (u, v) are found by projection.
  const CadModel holed = test::toModel(test::boxWithHole());
  int top = 0;
  for (int f = 1; f <= holed.numFaces(); ++f)
    if (holed.isPlanar(f) && std::abs(holed.plane(f).first.z() - 2.0) < 1e-12) top = f;
  ASSERT_GT(top, 0);
  EXPECT_EQ(holed.facePeriods(top)[0], 0.0);
  const auto uvOf = [&](double x, double y) {
    const SurfaceProjection p = holed.projectOnSurface(top, Eigen::Vector3d(x, y, 2.0));
    return std::array<double, 2>{p.u, p.v};
  };
  const auto material = uvOf(0.5, 0.5), hole = uvOf(2.2, 2.1), outside = uvOf(5.0, 1.0);
  EXPECT_TRUE(holed.faceContains(top, material[0], material[1]));
  EXPECT_FALSE(holed.faceContains(top, hole[0], hole[1]));
  EXPECT_FALSE(holed.faceContains(top, outside[0], outside[1]));
  for (int d = 0; d <= 2; ++d) EXPECT_GT(holed.tolerance(d, 1), 0.0);
  EXPECT_THROW(holed.tolerance(3, 1), Error);
}

// A B-spline surface closed in a direction without being periodic there evaluates beyond its
// range by extrapolation: CadModel gives such a direction its range as a period and wraps
// (u, v) into the range, so a chart unwrapped across the seam still lands on the surface.
TEST(CadModel, AClosedNonPeriodicSeamWrapsLikeAPeriodicOne) {
  const TopoDS_Shape shape = test::nurbsTorus(2.0, 0.5);
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  ASSERT_EQ(faces.Extent(), 1);
  const Handle(Geom_Surface) surface = BRep_Tool::Surface(TopoDS::Face(faces(1)));
  // The case under test: closed in both directions, periodic in neither.
  ASSERT_FALSE(surface->IsUPeriodic());
  ASSERT_FALSE(surface->IsVPeriodic());
  double u0, u1, v0, v1;
  surface->Bounds(u0, u1, v0, v1);
  const CadModel cad = test::toModel(shape);
  const auto periods = cad.facePeriods(1);
  EXPECT_DOUBLE_EQ(periods[0], u1 - u0);
  EXPECT_DOUBLE_EQ(periods[1], v1 - v0);
  // The same point one period (or a fraction more) away, in either direction: the B-spline's
  // own evaluation agrees to rounding (1e-12 of the torus's size 5, ample for a few dozen
  // operations of double precision); extrapolated, it would be off by about the tube's radius.
  const double u = u0 + 0.1 * (u1 - u0), v = v0 + 0.85 * (v1 - v0);
  const SurfaceDerivatives at = cad.evaluateSurface(1, u, v);
  for (const auto& shift :
       {std::array<double, 2>{periods[0], 0.0}, std::array<double, 2>{-periods[0], periods[1]},
        std::array<double, 2>{0.0, 2.0 * periods[1]}}) {
    const SurfaceDerivatives moved = cad.evaluateSurface(1, u + shift[0], v + shift[1]);
    EXPECT_LT((moved.point - at.point).norm(), 1e-12 * 5.0);
    EXPECT_LT((moved.du - at.du).norm(), 1e-9 * at.du.norm());
  }
  // A guess outside the range starts the projection at its wrapped copy.
  const Eigen::Vector3d target = at.point + 0.01 * at.du.cross(at.dv).normalized();
  const SurfaceProjection p =
      cad.projectOnSurface(1, target, std::array<double, 2>{u - periods[0], v + periods[1]});
  EXPECT_NEAR(p.distance, 0.01, 1e-9);
  EXPECT_NEAR(p.u, u, 1e-6 * periods[0]);
  EXPECT_NEAR(p.v, v, 1e-6 * periods[1]);
}

TEST(CadModel, ClearErrorsNameTheProblem) {
  const auto dir = test::tempDir();
  try {
    CadModel::fromFile((dir / "missing.step").string());
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.step"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos);
  }
  const std::string fake = (dir / "notes.step").string();
  std::ofstream(fake) << "this is not a STEP file\n";
  EXPECT_THROW(CadModel::fromFile(fake), IoError);
  const std::string odd = (dir / "part.obj").string();
  std::ofstream(odd) << "v 0 0 0\n";
  try {
    CadModel::fromFile(odd);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("unsupported CAD format"), std::string::npos);
  }
  EXPECT_THROW(CadModel::fromFile(dir.string()), IoError);
  EXPECT_THROW(CadModel::fromBrepText("garbage"), CadError);
  EXPECT_THROW(CadModel::fromBrepText(""), CadError);

  const CadModel cad = toModel(test::box(1, 1, 1));
  try {
    cad.faceBounds(9);
    FAIL();
  } catch (const CadError& e) {
    EXPECT_NE(std::string(e.what()).find("Face9"), std::string::npos);
  }
}

}  // namespace
}  // namespace homesh
