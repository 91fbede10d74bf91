// Apexes of CAD faces: a cone's tip (its normals around it span 90 degrees for a half-angle of
// 45), the poles of a sphere (degenerate parameters, but the normal converges) and the corners
// of a box (regular points).
#include <gtest/gtest.h>

#include <BRepPrimAPI_MakeCone.hxx>

#include "cad/face_apexes.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

// The face that holds vertex `v` and is not planar (the cone's or sphere's side).
int curvedFaceAt(const CadModel& cad, int v) {
  for (int f = 1; f <= cad.numFaces(); ++f) {
    if (cad.isPlanar(f)) continue;
    for (const int w : cad.subShapeIndices(2, f, 0))
      if (w == v) return f;
  }
  return 0;
}

TEST(FaceApexes, TheTipOfAConeIsAnApex) {
  // Base radius 1 at z = 0, tip at (0, 0, 1): a half-angle of 45 degrees.
  const CadModel cad = test::toModel(BRepPrimAPI_MakeCone(1.0, 0.0, 1.0).Shape());
  const int tip = test::vertexAt(cad, {0, 0, 1});
  ASSERT_GT(tip, 0);
  const int side = curvedFaceAt(cad, tip);
  ASSERT_GT(side, 0);
  EXPECT_TRUE(isFaceApex(cad, side, tip));
  // The base circle's vertex is a regular point of the side.
  for (const int v : cad.subShapeIndices(2, side, 0)) {
    if (v != tip) {
      EXPECT_FALSE(isFaceApex(cad, side, v));
    }
  }
}

TEST(FaceApexes, ASpheresPolesAreNoApexes) {
  const CadModel cad = test::toModel(test::sphere(1.0));
  int poles = 0;
  for (const double z : {-1.0, 1.0}) {
    const int pole = test::vertexAt(cad, {0, 0, z});
    if (pole == 0) continue;
    ++poles;
    EXPECT_FALSE(isFaceApex(cad, curvedFaceAt(cad, pole), pole)) << "pole at z = " << z;
  }
  EXPECT_GT(poles, 0);
}

TEST(FaceApexes, ABoxHasNone) {
  const CadModel cad = test::toModel(test::box(1, 2, 3));
  for (int f = 1; f <= cad.numFaces(); ++f)
    for (const int v : cad.subShapeIndices(2, f, 0)) EXPECT_FALSE(isFaceApex(cad, f, v));
  // A vertex off the face: a face without the origin's vertex.
  const int origin = test::vertexAt(cad, {0, 0, 0});
  ASSERT_GT(origin, 0);
  for (int f = 1; f <= cad.numFaces(); ++f) EXPECT_FALSE(isFaceApex(cad, f, origin));
}

}  // namespace
}  // namespace homesh
