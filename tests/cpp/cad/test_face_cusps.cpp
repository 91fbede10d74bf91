// Cusps of CAD faces on prisms whose cross-section is known: a region between a line and a
// circular arc tangent to it at one corner (a cusp on the top and bottom faces), the same with
// the arc meeting the line at 14 degrees (no cusp within 1 degree, one within 20), and a box.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "cad/face_cusps.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

TEST(FaceCusps, TheTangentCornerOfTheTopAndBottomFacesIsACusp) {
  const CadModel cad = test::toModel(test::cuspPrism());
  const std::vector<FaceCusp> cusps = findFaceCusps(cad);
  ASSERT_EQ(cusps.size(), 2u);
  const std::set<int> corners = {test::vertexAt(cad, {0, 0, 0}), test::vertexAt(cad, {0, 0, 1})};
  std::set<int> found;
  for (const FaceCusp& c : cusps) {
    found.insert(c.vertex);
    EXPECT_TRUE(cad.isPlanar(c.face));
    // The two edges of the face at that vertex: the segment and the arc, both in the face.
    const std::vector<int> edges = cad.subShapeIndices(2, c.face, 1);
    EXPECT_TRUE(std::binary_search(edges.begin(), edges.end(), c.edgeA));
    EXPECT_TRUE(std::binary_search(edges.begin(), edges.end(), c.edgeB));
    EXPECT_LT(c.edgeA, c.edgeB);
    // The arc's tangent at the origin is exactly +x: the angle is zero up to the rounding of
    // the circle's construction and evaluation, a few units of 1e-16 in the unit tangents,
    // which atan2 of their cross product keeps as about 1e-16 rad (1e-10 degrees is ample).
    EXPECT_LT(c.angleDeg, 1e-10);
  }
  EXPECT_EQ(found, corners);
  // The side faces meet at the vertical edge through the origin tangentially too, but that is
  // a smooth edge between two faces, not a corner of one: each side face's corners are 90 deg.
}

TEST(FaceCusps, ACornerOfAFewDegreesIsACuspOnlyWithinItsAngle) {
  // The arc through (0.5, 0.2) and the corner (1, 0.6) (centre (-0.49, 1.95)) leaves the origin
  // 14.1 degrees above +x: the default 1 degree does not call that a cusp, 20 degrees does (the
  // next sharpest corner, at (2, 0), is 31 degrees).
  const CadModel cad = test::toModel(test::cuspPrism(gp_Pnt(0.5, 0.2, 0), 0.6));
  EXPECT_TRUE(findFaceCusps(cad).empty());
  const std::vector<FaceCusp> wide = findFaceCusps(cad, 20.0);
  ASSERT_EQ(wide.size(), 2u);
  for (const FaceCusp& c : wide) {
    // The centre (-0.49, 1.95) is exact, so the tangent is at atan(0.49 / 1.95); OCCT builds
    // and evaluates the circle to about 1e-15 relative, far inside 1e-9 degrees.
    EXPECT_NEAR(c.angleDeg, std::atan(0.49 / 1.95) * 180.0 / 3.14159265358979323846, 1e-9);
  }
}

TEST(FaceCusps, ABoxHasNone) {
  EXPECT_TRUE(findFaceCusps(test::toModel(test::box(1, 2, 3))).empty());
}

}  // namespace
}  // namespace homesh
