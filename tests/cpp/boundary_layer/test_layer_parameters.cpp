// What a boundary layer is asked to be (layer_parameters.hpp): thickness expressions, face
// lists, split coordinates and the ranges checked.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "boundary_layer/layer_parameters.hpp"
#include "core/error.hpp"
#include "core/expression.hpp"

namespace homesh {
namespace {

TEST(Expression, EvaluatesNekMeshThicknessesAndNamesWhatIsWrong) {
  const Expression t = Expression::parse("0.01+0.05*x", "BndLayerThickness");
  EXPECT_EQ(t(2.0, 7.0, 9.0), 0.01 + 0.05 * 2.0);  // the same operations: exact
  EXPECT_FALSE(t.isConstant());
  EXPECT_TRUE(Expression::parse(" 4e-2 ", "t").isConstant());
  EXPECT_EQ(Expression::parse("2^3^2", "t")(0, 0, 0), 512.0);  // right-associative
  EXPECT_EQ(Expression::parse("-2^2", "t")(0, 0, 0), -4.0);    // minus binds looser
  EXPECT_EQ(Expression::parse("max(x, y) - min(1, z) / (2)", "t")(3, 5, 4), 5.0 - 0.5);
  EXPECT_EQ(Expression::parse("sqrt(abs(-z))", "t")(0, 0, 16), 4.0);
  for (const char* bad : {"0.01+", "x*q", "sin x", "(x", "max(1)", "1 2", ""}) {
    try {
      Expression::parse(bad, "BndLayerThickness");
      ADD_FAILURE() << bad;
    } catch (const ParameterError& e) {
      EXPECT_NE(std::string(e.what()).find("BndLayerThickness"), std::string::npos) << e.what();
    }
  }
}

TEST(BoundaryLayerParameters, FaceListsSplitCoordinatesAndRanges) {
  EXPECT_EQ(parseIndexList("1,8", "f"), (std::vector<int>{1, 8}));
  EXPECT_EQ(parseIndexList("11-12", "f"), (std::vector<int>{11, 12}));
  EXPECT_EQ(parseIndexList(" 5, 1-3 ,2", "f"), (std::vector<int>{1, 2, 3, 5}));
  for (const char* bad : {"", "a", "0", "3-1", "1,,2", "-2"})
    EXPECT_THROW(parseIndexList(bad, "f"), ParameterError) << bad;

  BoundaryLayerParameters p;
  p.faces = {1};
  p.thickness = "0.04";
  p.layers = 6;
  p.progression = 1.5;
  EXPECT_NO_THROW(p.validate());
  const std::vector<double> z = p.splitCoordinates();
  ASSERT_EQ(z.size(), 7U);
  EXPECT_EQ(z.front(), 0.0);
  EXPECT_EQ(z.back(), 1.0);
  // z_1 = (1 - r) / (1 - r^n); each step r times the one before (rounding: a few ulps).
  EXPECT_NEAR(z[1], (1 - 1.5) / (1 - std::pow(1.5, 6)), 1e-15);
  for (std::size_t k = 1; k + 1 < z.size(); ++k)
    EXPECT_NEAR((z[k + 1] - z[k]) / (z[k] - z[k - 1]), 1.5, 1e-12);
  for (auto change : std::vector<void (*)(BoundaryLayerParameters&)>{
           [](BoundaryLayerParameters& q) { q.faces.clear(); },
           [](BoundaryLayerParameters& q) { q.thickness = "0.04*"; },
           [](BoundaryLayerParameters& q) { q.layers = 0; },
           [](BoundaryLayerParameters& q) { q.progression = -1; }}) {
    BoundaryLayerParameters q = p;
    change(q);
    EXPECT_THROW(q.validate(), ParameterError);
  }
}

}  // namespace
}  // namespace homesh
