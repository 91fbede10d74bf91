// Touching solids imprinted on each other (cad/solid_imprint.hpp): the faces where they touch
// become one face of both, wholly or where they partly overlap; every solid stays a solid; the
// numbering map takes each original number to the final ones; solids that share volume are cut
// where they overlap; solids that stand apart are left as they are.

#include <gtest/gtest.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepGProp.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRep_Builder.hxx>
#include <GProp_GProps.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Iterator.hxx>
#include <gp_Ax2.hxx>
#include <gp_Pnt.hxx>

#include <algorithm>
#include <iterator>
#include <string>
#include <vector>

#include "cad/occt_access.hpp"
#include "cad/solid_imprint.hpp"
#include "core/error.hpp"
#include "linear/linear_mesher.hpp"

namespace homesh {
namespace {

CadModel compoundOf(const std::vector<TopoDS_Shape>& solids, const std::string& name) {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  for (const TopoDS_Shape& s : solids) b.Add(c, s);
  return cadModelFromShape(c, name);
}

TopoDS_Shape box(double x, double y, double z) {
  return BRepPrimAPI_MakeBox(gp_Pnt(x, y, z), 1.0, 1.0, 1.0).Shape();
}

double area(const CadModel& cad, int face) {
  GProp_GProps props;
  BRepGProp::SurfaceProperties(occtFace(cad, face), props);
  return props.Mass();
}

double volume(const CadModel& cad, int solid) {
  GProp_GProps props;
  BRepGProp::VolumeProperties(occtSolid(cad, solid), props);
  return props.Mass();
}

constexpr double kTolerance = 1e-7;

// Two unit boxes side by side: OpenCASCADE's box numbers its faces x = 0, x = 1, y = 0, y = 1,
// z = 0, z = 1, so the faces at x = 1 are Face2 (left) and Face7 (right).
TEST(SolidImprint, BoxesSideBySideShareTheirFace) {
  ImprintRecord record;
  const CadModel cad =
      imprintSolids(compoundOf({box(0, 0, 0), box(1, 0, 0)}, "two boxes"), kTolerance, record);
  EXPECT_TRUE(record.imprinted);
  EXPECT_TRUE(record.warning.empty()) << record.warning;
  EXPECT_EQ(record.solids, 2);
  EXPECT_EQ(record.touching, 2);
  ASSERT_EQ(cad.numSolids(), 2);
  EXPECT_EQ(cad.numFaces(), 11);
  EXPECT_EQ(cad.numEdges(), 20);
  EXPECT_EQ(cad.numVertices(), 12);
  ASSERT_EQ(record.interfaces.size(), 1U);
  const SolidInterface shared = record.interfaces[0];
  EXPECT_EQ(shared.solidA, 1);
  EXPECT_EQ(shared.solidB, 2);
  EXPECT_NEAR(area(cad, shared.face), 1.0, 1e-12);
  // Both original faces at x = 1 are that face; each solid still has six faces and its volume.
  EXPECT_EQ(record.numbering.finalNumbers(2, 2), std::vector<int>{shared.face});
  EXPECT_EQ(record.numbering.finalNumbers(2, 7), std::vector<int>{shared.face});
  for (int s = 1; s <= 2; ++s) {
    EXPECT_EQ(cad.subShapeIndices(3, s, 2).size(), 6U);
    EXPECT_NEAR(volume(cad, s), 1.0, 1e-12);
  }
  // The right box's face at x = 2 keeps its place among the faces: after the shared one.
  const std::vector<int> far = record.numbering.finalNumbers(2, 8);
  ASSERT_EQ(far.size(), 1U);
  const auto [point, normal] = cad.plane(far[0]);
  EXPECT_NEAR(point.x(), 2.0, 1e-12);
  EXPECT_TRUE(record.numbering.changed());
  EXPECT_FALSE(record.numbering.changes(2).empty());
}

// The right box moved up by half: the faces at x = 1 overlap on half their area, which becomes
// a face of both; each original face at x = 1 is split into that face and the rest of it.
TEST(SolidImprint, FacesThatPartlyOverlapAreImprintedWhereTheyOverlap) {
  ImprintRecord record;
  const CadModel cad =
      imprintSolids(compoundOf({box(0, 0, 0), box(1, 0.5, 0)}, "offset boxes"), kTolerance, record);
  ASSERT_TRUE(record.imprinted) << record.warning;
  ASSERT_EQ(cad.numSolids(), 2);
  ASSERT_EQ(record.interfaces.size(), 1U);
  EXPECT_NEAR(area(cad, record.interfaces[0].face), 0.5, 1e-12);
  for (const int original : {2, 7}) {
    const std::vector<int> pieces = record.numbering.finalNumbers(2, original);
    ASSERT_EQ(pieces.size(), 2U) << "Face" << original;
    EXPECT_NE(std::find(pieces.begin(), pieces.end(), record.interfaces[0].face), pieces.end());
    EXPECT_NEAR(area(cad, pieces[0]) + area(cad, pieces[1]), 1.0, 1e-12);
  }
  for (int s = 1; s <= 2; ++s) EXPECT_NEAR(volume(cad, s), 1.0, 1e-12);
}

// A sphere inside a box with that sphere cut out, each with its own sphere face (a copy: the
// cut shares the sphere's own face with the cavity, a STEP file does not): the sphere's face,
// its seam and its pole edges (degenerated, which the fuse's history records as removed) map
// to the cavity's.
TEST(SolidImprint, ASphereInItsCavityIsOneFaceOfBoth) {
  const TopoDS_Shape ball = BRepPrimAPI_MakeSphere(gp_Pnt(0.5, 0.5, 0.5), 0.3).Shape();
  const TopoDS_Shape cavity = BRepAlgoAPI_Cut(box(0, 0, 0), ball).Shape();
  const TopoDS_Shape sphere = BRepBuilderAPI_Copy(ball).Shape();
  ImprintRecord record;
  const CadModel original = compoundOf({cavity, sphere}, "sphere in a box");
  const int edgesBefore = original.numEdges();
  const CadModel cad =
      imprintSolids(compoundOf({cavity, sphere}, "sphere in a box"), kTolerance, record);
  ASSERT_TRUE(record.imprinted) << record.warning;
  EXPECT_EQ(cad.numFaces(), 7);
  EXPECT_EQ(cad.numEdges(), edgesBefore - 3);
  ASSERT_EQ(record.interfaces.size(), 1U);
  EXPECT_EQ(record.numbering.finalNumbers(2, 8), std::vector<int>{record.interfaces[0].face});
  for (int e = 1; e <= edgesBefore; ++e)
    EXPECT_EQ(record.numbering.finalNumbers(1, e).size(), 1U) << "Edge" << e;
  EXPECT_EQ(record.numbering.map(1, {13, 14, 15, 16, 17, 18}, "curve", "imprinting").size(), 3U);
}

// Internal edges of `cad`'s faces (a wire's edge oriented INTERNAL).
int internalEdges(const CadModel& cad) {
  int n = 0;
  for (TopExp_Explorer f(occtShape(cad), TopAbs_FACE); f.More(); f.Next())
    for (TopoDS_Iterator w(f.Current()); w.More(); w.Next())
      for (TopoDS_Iterator e(w.Value()); e.More(); e.Next())
        n += e.Value().Orientation() == TopAbs_INTERNAL ? 1 : 0;
  return n;
}

// A cylinder lying on a box touches it along a line and a ball resting on it at a point: the
// fuse leaves edges inside their faces there (the balls of OpenCASCADE's Axis_of_bearing left
// 332, too short for Gmsh, which aborted). They bound no face and are taken out: no internal
// edge is left, no face but the roller's side changes, and Gmsh meshes the model.
TEST(SolidImprint, EdgesWhereSolidsTouchAlongALineOrAtAPointAreTakenOut) {
  const TopoDS_Shape base = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 2.0, 1.0, 1.0).Shape();
  const TopoDS_Shape roller =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0.2, 0.5, 1.25), gp_Dir(1, 0, 0)), 0.25, 0.6).Shape();
  const TopoDS_Shape ball = BRepPrimAPI_MakeSphere(gp_Pnt(1.5, 0.5, 1.3), 0.3).Shape();
  const CadModel original = compoundOf({base, roller, ball}, "a roller and a ball on a box");
  ImprintRecord record;
  const CadModel cad = imprintSolids(
      compoundOf({base, roller, ball}, "a roller and a ball on a box"), kTolerance, record);
  EXPECT_TRUE(record.warning.empty()) << record.warning;
  EXPECT_GT(record.contactEdges, 0);
  EXPECT_EQ(internalEdges(cad), 0);
  EXPECT_TRUE(record.interfaces.empty());  // no face is shared
  // The box's faces and the ball's keep one number each; the roller's side (Face7), whose
  // contact line runs from end to end, is split along it in two.
  for (int f = 1; f <= original.numFaces(); ++f)
    EXPECT_EQ(record.numbering.finalNumbers(2, f).size(), f == 7 ? 2U : 1U) << "Face" << f;
  const Mesh mesh = generateLinearMesh(cad, LinearMeshOptions::uniform(0.2));
  EXPECT_GT(mesh.blocks.at(0).count(), 0U);
}

// Boxes that overlap by half their width share volume: cut where they overlap, into three
// solids (each box's own half and the overlap, a solid of both, meshed once), every piece of
// volume 0.5, and the map gives each box its two pieces. A box and its copy become one solid.
TEST(SolidImprint, SolidsThatShareVolumeAreCutWhereTheyOverlap) {
  ImprintRecord record;
  const CadModel cad = imprintSolids(
      compoundOf({box(0, 0, 0), box(0.5, 0, 0)}, "overlapping boxes"), kTolerance, record);
  EXPECT_TRUE(record.imprinted);
  EXPECT_TRUE(record.warning.empty()) << record.warning;
  ASSERT_EQ(cad.numSolids(), 3);
  for (int s = 1; s <= 3; ++s) {
    GProp_GProps props;
    BRepGProp::VolumeProperties(occtSolid(cad, s), props);
    EXPECT_NEAR(props.Mass(), 0.5, 1e-9) << "Solid" << s;
  }
  const std::vector<int>& one = record.numbering.finalNumbers(3, 1);
  const std::vector<int>& two = record.numbering.finalNumbers(3, 2);
  ASSERT_EQ(one.size(), 2U);
  ASSERT_EQ(two.size(), 2U);
  std::vector<int> shared;
  std::set_intersection(one.begin(), one.end(), two.begin(), two.end(), std::back_inserter(shared));
  ASSERT_EQ(shared.size(), 1U);  // the overlap, x in [0.5, 1]
  GProp_GProps overlap;
  BRepGProp::VolumeProperties(occtSolid(cad, shared[0]), overlap);
  EXPECT_NEAR(overlap.CentreOfMass().X(), 0.75, 1e-9);
  EXPECT_EQ(record.interfaces.size(), 2U);  // at x = 0.5 and x = 1
  EXPECT_NE(record.overlap.find("Solid1 and Solid2 share volume"), std::string::npos)
      << record.overlap;
  ImprintRecord copy;
  const CadModel twice =
      imprintSolids(compoundOf({box(0, 0, 0), box(0, 0, 0)}, "a box twice"), kTolerance, copy);
  EXPECT_EQ(twice.numSolids(), 1);
  EXPECT_EQ(copy.numbering.finalNumbers(3, 1), std::vector<int>{1});
  EXPECT_EQ(copy.numbering.finalNumbers(3, 2), std::vector<int>{1});
}

// Boxes a gap apart, and a single box: nothing to imprint, nothing to say, numbering as it was.
TEST(SolidImprint, SolidsApartAndASingleSolidAreLeftAsTheyAre) {
  for (const auto& [solids, touching] : std::vector<std::pair<std::vector<TopoDS_Shape>, int>>{
           {{box(0, 0, 0), box(3, 0, 0)}, 0}, {{box(0, 0, 0)}, 0}}) {
    ImprintRecord record;
    const CadModel cad = imprintSolids(compoundOf(solids, "apart"), kTolerance, record);
    EXPECT_FALSE(record.imprinted);
    EXPECT_TRUE(record.warning.empty()) << record.warning;
    EXPECT_EQ(record.touching, touching);
    EXPECT_EQ(cad.numFaces(), 6 * static_cast<int>(solids.size()));
    EXPECT_FALSE(record.numbering.changed());
    EXPECT_EQ(record.numbering.finalNumbers(2, 6), std::vector<int>{6});
  }
  // Imprinting off: two touching boxes stay apart.
  ImprintRecord off;
  off.enabled = false;
  const CadModel cad =
      imprintSolids(compoundOf({box(0, 0, 0), box(1, 0, 0)}, "off"), kTolerance, off);
  EXPECT_FALSE(off.imprinted);
  EXPECT_EQ(cad.numFaces(), 12);
}

// What a user named by a number the model does not have, or one the imprint removed, is
// refused naming the number, the entity and the operation.
TEST(SolidImprint, TheNumberingMapRefusesNumbersItCannotMap) {
  ImprintRecord record;
  imprintSolids(compoundOf({box(0, 0, 0), box(1, 0, 0)}, "two boxes"), kTolerance, record);
  try {
    record.numbering.map(2, {3, 13}, "boundary-layer face", "imprinting the touching solids");
    FAIL() << "face 13 of 12 was mapped";
  } catch (const ParameterError& e) {
    EXPECT_EQ(std::string(e.what()), "boundary-layer face 13: the model has 12 (Face1 to Face12)");
  }
  // The two faces at x = 1 and the right box's at x = 2 map to two faces.
  EXPECT_EQ(record.numbering.map(2, {2, 7, 8}, "group", "imprinting").size(), 2U);
}

// Kept beside a mesh saved without its CAD: the map read back from its text maps every number
// as the original does, says what removed one, and text that is not a map is refused by line.
TEST(SolidImprint, TheNumberingMapReadsBackFromItsText) {
  ImprintRecord record;
  imprintSolids(compoundOf({box(0, 0, 0), box(1, 0, 0)}, "two boxes"), kTolerance, record);
  const NumberingMap& map = record.numbering;
  const NumberingMap back = NumberingMap::fromText(map.toText());
  EXPECT_EQ(back.toText(), map.toText());
  for (int dim = 0; dim < 4; ++dim) {
    ASSERT_EQ(back.originalCount(dim), map.originalCount(dim));
    EXPECT_EQ(back.finalCount(dim), map.finalCount(dim));
    for (int i = 1; i <= map.originalCount(dim); ++i)
      EXPECT_EQ(back.finalNumbers(dim, i), map.finalNumbers(dim, i)) << dim << " " << i;
  }
  const NumberingMap removed =
      NumberingMap::fromText("0 0 0\n1 0 0\n2 2 1\n1|\n|healing (x)\n3 0 0\n");
  EXPECT_EQ(removed.finalNumbers(2, 1), std::vector<int>{1});
  EXPECT_EQ(removed.removedBy(2, 2), "healing (x)");
  for (const auto& [text, why] : std::vector<std::pair<std::string, std::string>>{
           {"0 0 0\n1 0 0\n2 1 1\n2|\n3 0 0\n", "line 4: 2 is not a final number"},
           {"0 0 0\n1 0 0\n2 1 1\nx|\n3 0 0\n", "line 4: not a number"},
           {"0 0 0\n1 0 0\n2 2 1\n1|\n", "line 5: the map ends early"},
           {"0 0 0\n2 0 0\n", "line 2: expected \"1 ORIGINAL FINAL\""},
           {"0 0 0\n1 0 0\n2 1 2\n2 1|\n3 0 0\n", "line 4: final numbers not ascending"},
           {"0 0 0\n1 0 0\n2 1 2\n1 99999999999999999999|\n3 0 0\n", "line 4: not a number"}}) {
    try {
      NumberingMap::fromText(text);
      FAIL() << "read: " << text;
    } catch (const ParameterError& e) {
      EXPECT_EQ(std::string(e.what()), "numbering map: " + why);
    }
  }
}

}  // namespace
}  // namespace homesh
