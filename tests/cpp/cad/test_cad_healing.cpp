// The CAD check and healing: a sound model is left exactly as it is; an empty solid is removed
// without touching the faces' numbering; faces that close are sewn into a solid; what cannot be
// closed is refused naming a free edge, or left out by name when only solids are asked for, or
// kept as faces (sewn where they meet) for a surface mesh.
#include <gtest/gtest.h>

#include <BRepAlgoAPI_BuilderAlgo.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepGProp.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRep_Builder.hxx>
#include <GProp_GProps.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <gp.hxx>
#include <gp_Ax2.hxx>
#include <gp_Trsf.hxx>
#include <string>
#include <vector>

#include "cad/cad_healing.hpp"
#include "cad/occt_access.hpp"
#include "core/error.hpp"

namespace homesh {
namespace {

TopoDS_Shape box() {
  return BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape();
}

// The box's faces as loose faces (no shell, no solid), all or all but the last.
TopoDS_Shape looseFaces(bool all) {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  int n = 0;
  for (TopExp_Explorer f(box(), TopAbs_FACE); f.More(); f.Next())
    if (all || ++n < 6) b.Add(c, f.Current());
  return c;
}

// The faces of two shapes, loose (no shell, no solid).
TopoDS_Shape looseFacesOf(const TopoDS_Shape& one, const TopoDS_Shape& two) {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  for (const TopoDS_Shape& s : {one, two})
    for (TopExp_Explorer f(s, TopAbs_FACE); f.More(); f.Next()) b.Add(c, f.Current());
  return c;
}

TEST(CadHealing, ASoundModelIsLeftAsItIs) {
  const TopoDS_Shape shape = box();
  HealingRecord record;
  const CadModel cad = healModel(cadModelFromShape(shape, "box"), {}, record);
  EXPECT_TRUE(record.problems.empty());
  EXPECT_FALSE(record.changed());
  EXPECT_FALSE(record.renumbered);
  EXPECT_TRUE(occtShape(cad).IsSame(shape));  // the very shape: nothing rebuilt
}

TEST(CadHealing, AnEmptySolidIsRemovedAndTheFacesKeepTheirNumbers) {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  b.Add(c, box());
  TopoDS_Solid empty;
  b.MakeSolid(empty);
  b.Add(c, empty);
  HealingRecord record;
  const CadModel cad = healModel(cadModelFromShape(c, "model"), {}, record);
  ASSERT_EQ(record.problems.size(), 1U);
  EXPECT_NE(record.problems[0].find("Solid2 has no face"), std::string::npos);
  EXPECT_EQ(record.solidsBefore, 2);
  EXPECT_EQ(record.solidsAfter, 1);
  EXPECT_EQ(cad.numSolids(), 1);
  EXPECT_FALSE(record.renumbered);  // the faces and edges are where they were
}

TEST(CadHealing, FacesThatCloseAreSewnIntoASolid) {
  HealingRecord record;
  const CadModel cad = healModel(cadModelFromShape(looseFaces(true), "faces"), {}, record);
  EXPECT_EQ(record.solidsBefore, 0);
  EXPECT_EQ(cad.numSolids(), 1);
  EXPECT_EQ(cad.numFaces(), 6);
  ASSERT_FALSE(record.actions.empty());
  EXPECT_NE(record.actions[0].find("sewed"), std::string::npos);
}

gp_Pnt centreOf(const TopoDS_Shape& shape, TopAbs_ShapeEnum type) {
  GProp_GProps props;
  if (type == TopAbs_FACE)
    BRepGProp::SurfaceProperties(shape, props);
  else
    BRepGProp::LinearProperties(shape, props);
  return props.CentreOfMass();
}

// A block with a round hole, its faces each copied on its own (no edge shared, as a STEP of
// loose faces reads back) and listed last first: sewing makes a solid of them and numbers the
// faces and edges afresh. The healing record maps each of the file's numbers to the one face
// or edge made of it, at the same place; the two copies of an edge to the same edge.
TEST(CadHealing, SewingNumbersAfreshAndTheRecordMapsTheFilesNumbers) {
  const TopoDS_Shape block = BRepAlgoAPI_Cut(
      BRepPrimAPI_MakeBox(4.0, 2.0, 2.0).Shape(),
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1.5, 1.0, 0.0), gp::DZ()), 0.4, 2.0).Shape());
  std::vector<TopoDS_Shape> faces;
  for (TopExp_Explorer f(block, TopAbs_FACE); f.More(); f.Next())
    faces.push_back(BRepBuilderAPI_Copy(f.Current()).Shape());
  TopoDS_Compound file;
  BRep_Builder b;
  b.MakeCompound(file);
  for (auto f = faces.rbegin(); f != faces.rend(); ++f) b.Add(file, *f);
  HealingRecord record;
  const CadModel cad = healModel(cadModelFromShape(file, "faces"), {}, record);
  ASSERT_EQ(cad.numSolids(), 1);
  EXPECT_TRUE(record.renumbered);
  const NumberingMap& map = record.numbering;
  EXPECT_TRUE(map.changed(2));
  for (const TopAbs_ShapeEnum type : {TopAbs_FACE, TopAbs_EDGE}) {
    const int dim = type == TopAbs_FACE ? 2 : 1;
    TopTools_IndexedMapOfShape before, after;
    TopExp::MapShapes(file, type, before);
    TopExp::MapShapes(occtShape(cad), type, after);
    ASSERT_EQ(map.originalCount(dim), before.Extent());
    ASSERT_EQ(map.finalCount(dim), after.Extent());
    std::vector<int> uses(static_cast<std::size_t>(after.Extent()) + 1, 0);
    for (int i = 1; i <= before.Extent(); ++i) {
      const std::vector<int>& finals = map.finalNumbers(dim, i);
      ASSERT_EQ(finals.size(), 1U) << dim << " " << i;
      // Sewing moves nothing by more than its tolerance.
      EXPECT_LT(centreOf(before(i), type).Distance(centreOf(after(finals[0]), type)),
                10.0 * record.tolerance)
          << dim << " " << i;
      ++uses[static_cast<std::size_t>(finals[0])];
    }
    // Each face of the solid is one of the file's; each edge as many copies as faces use it
    // (two, a seam one).
    TopTools_IndexedDataMapOfShapeListOfShape faceOf;
    TopExp::MapShapesAndUniqueAncestors(occtShape(cad), type, TopAbs_FACE, faceOf);
    for (int k = 1; k <= after.Extent(); ++k)
      EXPECT_EQ(uses[static_cast<std::size_t>(k)],
                dim == 2 ? 1 : faceOf.FindFromKey(after(k)).Extent())
          << dim << " " << k;
  }
  // A message about a sub-shape of the model meshed names it as the file does: a face by its
  // one original, an edge two faces shared by the two copies sewn into it (the hole's seam,
  // which one face uses twice, by its one).
  for (int i = 1; i <= map.originalCount(2); ++i)
    EXPECT_EQ(map.givenNames(2, map.finalNumbers(2, i)[0]), "Face" + std::to_string(i));
  int sewn = 0;
  for (int k = 1; k <= map.finalCount(1); ++k) {
    const std::vector<int> copies = map.originals(1, k);
    ASSERT_FALSE(copies.empty()) << k;
    ASSERT_LE(copies.size(), 2U) << k;
    const std::string first = "Edge" + std::to_string(copies[0]);
    EXPECT_EQ(map.givenNames(1, k),
              copies.size() == 1 ? first : first + " and Edge" + std::to_string(copies[1]));
    sewn += copies.size() == 2 ? 1 : 0;
  }
  EXPECT_GT(sewn, 0);
  // The solid sewing made is none of the file's; a number the model lacks is named so too.
  EXPECT_EQ(map.givenNames(3, 1), "no numbered solid");
  EXPECT_EQ(map.givenNames(2, map.finalCount(2) + 1), "no numbered face");
}

// Two closed shells whose bounding boxes nest: one inside the other's material is a void and
// the model is refused (which side is material is not known); a post standing in a frame's
// hole is no void, the two are solids.
TEST(CadHealing, AShellInsideAnotherIsRefusedOneInAHoleIsASolid) {
  const TopoDS_Shape big = BRepPrimAPI_MakeBox(4.0, 4.0, 4.0).Shape();
  const TopoDS_Shape small = BRepPrimAPI_MakeBox(gp_Pnt(1, 1, 1), 1.0, 1.0, 1.0).Shape();
  HealingRecord voided;
  try {
    healModel(cadModelFromShape(looseFacesOf(big, small), "a box with a void"), {}, voided);
    FAIL() << "a box with a void was accepted";
  } catch (const CadError& e) {
    EXPECT_NE(std::string(e.what()).find("closed shells one inside the other"), std::string::npos)
        << e.what();
  }
  const TopoDS_Shape frame =
      BRepAlgoAPI_Cut(big, BRepPrimAPI_MakeBox(gp_Pnt(1, 1, -1), 2.0, 2.0, 6.0).Shape()).Shape();
  const TopoDS_Shape post = BRepPrimAPI_MakeBox(gp_Pnt(1.5, 1.5, 1), 1.0, 1.0, 2.0).Shape();
  HealingRecord record;
  const CadModel cad =
      healModel(cadModelFromShape(looseFacesOf(frame, post), "a frame and a post"), {}, record);
  EXPECT_EQ(cad.numSolids(), 2);
}

TEST(CadHealing, WhatCannotBeClosedIsRefusedNamingAFreeEdge) {
  for (const bool heal : {true, false}) {
    HealingRecord record;
    try {
      healModel(cadModelFromShape(looseFaces(false), "five faces"), HealingOptions{heal, false},
                record);
      FAIL() << "five faces of a box were accepted";
    } catch (const CadError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("five faces is not a closed solid"), std::string::npos) << message;
      EXPECT_NE(message.find("bounds only one face"), std::string::npos) << message;
      EXPECT_NE(message.find(heal ? "healing could not close it" : "healing is off"),
                std::string::npos)
          << message;
      EXPECT_NE(message.find("as a surface mesh: --surface"), std::string::npos) << message;
    }
  }
}

// Five faces of a box, each copied on its own (no edge shared): a surface mesh keeps them as
// faces, no solid, and sewing joins them along the 8 edges they meet at, leaving the open
// top's 4 edges free. Asked of a model with a solid, it is refused naming the solid.
TEST(CadHealing, ASurfaceMeshKeepsTheFacesSewnWhereTheyMeet) {
  TopoDS_Compound apart;
  BRep_Builder builder;
  builder.MakeCompound(apart);
  int n = 0;
  for (TopExp_Explorer f(box(), TopAbs_FACE); f.More() && n < 5; f.Next(), ++n)
    builder.Add(apart, BRepBuilderAPI_Copy(f.Current()).Shape());
  HealingOptions surface;
  surface.surface = true;
  HealingRecord record;
  const CadModel cad = healModel(cadModelFromShape(apart, "five faces"), surface, record);
  EXPECT_EQ(cad.numSolids(), 0);
  EXPECT_EQ(cad.numFaces(), 5);
  ASSERT_EQ(record.actions.size(), 1U);
  EXPECT_NE(record.actions[0].find("20 -> 4 edges bounding one face"), std::string::npos)
      << record.actions[0];
  EXPECT_NE(record.surface.find("a surface mesh of its 5 faces"), std::string::npos)
      << record.surface;
  EXPECT_NE(record.surface.find("4 edges bound only one face"), std::string::npos)
      << record.surface;
  ASSERT_FALSE(record.notes().empty());
  EXPECT_EQ(record.notes().front(), record.surface);
  // Without healing the faces stay apart: 20 free edges, nothing sewn.
  surface.enabled = false;
  const CadModel unsewn = healModel(cadModelFromShape(apart, "five faces"), surface, record);
  EXPECT_EQ(unsewn.numFaces(), 5);
  EXPECT_TRUE(record.actions.empty());
  EXPECT_NE(record.surface.find("20 edges bound only one face"), std::string::npos)
      << record.surface;
  // All six faces close, yet stay faces: no solid is made when a surface mesh is asked for.
  surface.enabled = true;
  const CadModel closed =
      healModel(cadModelFromShape(looseFaces(true), "six faces"), surface, record);
  EXPECT_EQ(closed.numSolids(), 0);
  EXPECT_NE(record.surface.find("the faces close"), std::string::npos) << record.surface;
  // A solid without a face beside them is removed by healing, not counted as a solid.
  TopoDS_Solid empty;
  builder.MakeSolid(empty);
  builder.Add(apart, empty);
  const CadModel withEmpty = healModel(cadModelFromShape(apart, "five faces"), surface, record);
  EXPECT_EQ(withEmpty.numSolids(), 0);
  EXPECT_EQ(withEmpty.numFaces(), 5);
  EXPECT_NE(record.actions.front().find("removed 1 empty solid"), std::string::npos)
      << record.actions.front();
  try {
    healModel(cadModelFromShape(box(), "a box"), surface, record);
    FAIL() << "a surface mesh of a solid was accepted";
  } catch (const CadError& e) {
    EXPECT_NE(std::string(e.what()).find("a box has 1 solid: a surface mesh (--surface"),
              std::string::npos)
        << e.what();
  }
}

// A solid and, beside it, the faces of a second box (all six, or the first five: open).
TopoDS_Shape solidAndFaces(bool all) {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  b.Add(c, box());
  int n = 0;
  const TopoDS_Shape other = BRepPrimAPI_MakeBox(gp_Pnt(5, 0, 0), 1.0, 2.0, 3.0).Shape();
  for (TopExp_Explorer f(other, TopAbs_FACE); f.More(); f.Next())
    if (all || ++n < 6) b.Add(c, f.Current());
  return c;
}

// Faces beside a solid are not dropped in silence: sewn into a solid of their own when they
// close, else the model is refused naming them, or (solids only) left out and recorded.
TEST(CadHealing, FacesBesideASolidAreSewnRefusedOrLeftOutByName) {
  HealingRecord closed;
  const CadModel two = healModel(cadModelFromShape(solidAndFaces(true), "two"), {}, closed);
  EXPECT_EQ(two.numSolids(), 2);
  EXPECT_EQ(two.numFaces(), 12);
  EXPECT_TRUE(closed.leftOut.empty()) << closed.leftOut;

  for (const bool heal : {true, false}) {
    HealingRecord record;
    try {
      healModel(cadModelFromShape(solidAndFaces(false), "open"), HealingOptions{heal, false},
                record);
      FAIL() << "a solid beside an open shell was accepted";
    } catch (const CadError& e) {
      const std::string message = e.what();
      // The box's six faces come first: the loose ones are Face7 to Face11, at x 5..6.
      EXPECT_NE(message.find("5 faces (Face7-Face11) in no solid, within x [5, 6]"),
                std::string::npos)
          << message;
      EXPECT_NE(message.find("bounds only one face"), std::string::npos) << message;
      EXPECT_NE(message.find("--solids-only"), std::string::npos) << message;
    }
  }

  HealingRecord record;
  const CadModel solid = healModel(cadModelFromShape(solidAndFaces(false), "open"),
                                   HealingOptions{true, true}, record);
  EXPECT_EQ(solid.numSolids(), 1);
  EXPECT_EQ(solid.numFaces(), 6);
  EXPECT_NE(record.leftOut.find("5 faces (Face7-Face11)"), std::string::npos) << record.leftOut;
  // The solid's faces keep their numbers: only faces after them were left out.
  EXPECT_FALSE(record.renumbered);
  EXPECT_EQ(record.facesBefore, 11);
  EXPECT_EQ(record.facesAfter, 6);
}

// The faces of `shape`, moved by (dx, 0, 0), all or all but the last, added to `c` loose.
void addFaces(TopoDS_Compound& c, const TopoDS_Shape& shape, double dx, bool all) {
  BRep_Builder b;
  gp_Trsf shift;
  shift.SetTranslation(gp_Vec(dx, 0, 0));
  int k = 0, total = 0;
  for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next()) ++total;
  for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next())
    if (all || ++k < total) b.Add(c, f.Current().Moved(TopLoc_Location(shift)));
}

// The faces of a box, loose, and beside them at x 5..6 those of another but its last: one
// shell that sewing closes and one that it cannot.
TopoDS_Shape closedAndOpenFaces() {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  addFaces(c, box(), 0.0, true);
  addFaces(c, box(), 5.0, false);
  return c;
}

// healModel with healing on and without solids only refuses `shape`, saying `why`.
void expectRefused(const TopoDS_Shape& shape, const std::string& name, const std::string& why) {
  HealingRecord record;
  try {
    healModel(cadModelFromShape(shape, name), {}, record);
    ADD_FAILURE() << name << " was accepted";
  } catch (const CadError& e) {
    EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
  }
}

// Loose faces of which only some close: refused with the option named; solids only meshes the
// closed shell and records the rest.
TEST(CadHealing, SolidsOnlyKeepsTheShellsThatCloseAndRecordsTheRest) {
  const TopoDS_Shape c = closedAndOpenFaces();
  HealingRecord refused;
  try {
    healModel(cadModelFromShape(c, "some close"), {}, refused);
    FAIL() << "a model whose faces do not all close was accepted";
  } catch (const CadError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("sewing closed 1 of 2 shells"), std::string::npos) << message;
    EXPECT_NE(message.find("--solids-only"), std::string::npos) << message;
  }
  HealingRecord record;
  const CadModel cad =
      healModel(cadModelFromShape(c, "some close"), HealingOptions{true, true}, record);
  EXPECT_EQ(cad.numSolids(), 1);
  EXPECT_EQ(cad.numFaces(), 6);
  // Named by the file's numbers, though sewing numbered the faces afresh.
  EXPECT_NE(record.leftOut.find("5 faces (Face7-Face11) in no solid, within x [5, 6]"),
            std::string::npos)
      << record.leftOut;
}

// A solid, a loose shell that closes and one that does not: the closed one becomes a solid,
// the open one is refused, or left out (solids only) with where it is.
TEST(CadHealing, SolidsOnlySewsWhatClosesBesideSolidsAndLeavesOutTheRest) {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  b.Add(c, box());
  addFaces(c, box(), 5.0, true);    // closes
  addFaces(c, box(), 10.0, false);  // open
  expectRefused(c, "three", "sewing closed 1 of 2 shells");
  HealingRecord record;
  const CadModel cad = healModel(cadModelFromShape(c, "three"), HealingOptions{true, true}, record);
  EXPECT_EQ(cad.numSolids(), 2);
  EXPECT_EQ(cad.numFaces(), 12);
  EXPECT_NE(record.leftOut.find("5 faces (Face13-Face17) in no solid, within x [10, 11]"),
            std::string::npos)
      << record.leftOut;
}

// Automatic mode picks, per model, what the refusals above name: a model with no solid (five
// faces of a box, or loose faces of which only some close) becomes a surface of all its faces,
// faces that all close become a solid as without it, a solid beside an open shell keeps the
// solid (solids only), and a sound solid is left as it is with nothing said. With --surface or
// --solids-only it is refused.
TEST(CadHealing, AutomaticModeChoosesSurfaceOrSolidsOnlyAndSaysWhich) {
  HealingOptions automatic;
  automatic.automatic = true;

  HealingRecord open;
  const CadModel faces =
      healModel(cadModelFromShape(looseFaces(false), "five faces"), automatic, open);
  EXPECT_EQ(faces.numSolids(), 0);
  EXPECT_EQ(faces.numFaces(), 5);
  EXPECT_FALSE(open.surface.empty());
  EXPECT_NE(open.automatic.find("five faces has no solid (its 5 faces do not close"),
            std::string::npos)
      << open.automatic;
  EXPECT_NE(open.automatic.find("as --surface does"), std::string::npos) << open.automatic;
  EXPECT_EQ(open.notes().front(), open.automatic);

  HealingRecord some;
  const CadModel kept =
      healModel(cadModelFromShape(closedAndOpenFaces(), "some close"), automatic, some);
  EXPECT_EQ(kept.numSolids(), 0);
  EXPECT_EQ(kept.numFaces(), 11);
  EXPECT_TRUE(some.leftOut.empty()) << some.leftOut;
  EXPECT_NE(some.automatic.find("sewing closed 1 of 2 shells"), std::string::npos)
      << some.automatic;
  EXPECT_NE(some.automatic.find("as --surface does"), std::string::npos) << some.automatic;

  HealingRecord all;
  const CadModel sewn = healModel(cadModelFromShape(looseFaces(true), "six"), automatic, all);
  EXPECT_EQ(sewn.numSolids(), 1);
  EXPECT_TRUE(all.surface.empty()) << all.surface;
  EXPECT_TRUE(all.automatic.empty()) << all.automatic;

  HealingRecord beside;
  const CadModel solid =
      healModel(cadModelFromShape(solidAndFaces(false), "open"), automatic, beside);
  EXPECT_EQ(solid.numSolids(), 1);
  EXPECT_NE(beside.leftOut.find("5 faces (Face7-Face11)"), std::string::npos) << beside.leftOut;
  EXPECT_NE(beside.automatic.find("as --solids-only does"), std::string::npos) << beside.automatic;

  HealingRecord sound;
  const TopoDS_Shape shape = box();
  const CadModel same = healModel(cadModelFromShape(shape, "box"), automatic, sound);
  EXPECT_TRUE(occtShape(same).IsSame(shape));
  EXPECT_TRUE(sound.automatic.empty()) << sound.automatic;
  EXPECT_TRUE(sound.notes().empty());

  for (const bool surface : {true, false}) {
    HealingOptions both = automatic;
    (surface ? both.surface : both.solidsOnly) = true;
    HealingRecord record;
    EXPECT_THROW(healModel(cadModelFromShape(box(), "box"), both, record), ParameterError);
  }
}

// A loose shell that closes inside a solid (a void exported on its own) is no second solid:
// the model is refused, not meshed as two solids; solids only meshes the solid and leaves the
// shell out, saying why. (A shell on it, a surface copy of the body: the test below.)
TEST(CadHealing, AClosedLooseShellInsideASolidIsRefused) {
  const TopoDS_Shape big = BRepPrimAPI_MakeBox(4.0, 4.0, 4.0).Shape();
  const TopoDS_Shape small = BRepPrimAPI_MakeBox(gp_Pnt(1, 1, 1), 1.0, 1.0, 1.0).Shape();
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  b.Add(c, big);
  addFaces(c, small, 0.0, true);
  const std::string why = "a closed shell and Solid1 one inside the other";
  expectRefused(c, "body", why);
  HealingRecord record;
  const CadModel cad = healModel(cadModelFromShape(c, "body"), HealingOptions{true, true}, record);
  EXPECT_EQ(cad.numSolids(), 1);
  EXPECT_EQ(cad.numFaces(), 6);
  EXPECT_NE(record.leftOut.find(why), std::string::npos) << record.leftOut;
  EXPECT_FALSE(record.leftOutCopies);
}

// Loose faces that all copy faces of a solid (a surface model written beside its body, as
// Gmsh's shell_sewing demo does) are left out without solids only: nothing is lost, and the
// record says so. One loose face that copies nothing is enough to refuse the model as before.
TEST(CadHealing, LooseCopiesOfASolidsFacesAreLeftOutAndSaidSo) {
  const TopoDS_Shape big = BRepPrimAPI_MakeBox(4.0, 4.0, 4.0).Shape();
  // The box, then copies of its first `faces` faces, loose.
  const auto withCopies = [&big](int faces) {
    TopoDS_Compound c;
    BRep_Builder b;
    b.MakeCompound(c);
    b.Add(c, big);
    int n = 0;
    for (TopExp_Explorer f(big, TopAbs_FACE); f.More(); f.Next())
      if (++n <= faces) b.Add(c, f.Current().Moved(TopLoc_Location(gp_Trsf())));
    return c;
  };
  for (const bool shell : {true, false}) {  // a closed copy, or two faces of it
    const TopoDS_Compound c = withCopies(shell ? 6 : 2);
    HealingRecord record;
    const CadModel cad = healModel(cadModelFromShape(c, "copies"), {}, record);
    EXPECT_EQ(cad.numSolids(), 1);
    EXPECT_EQ(cad.numFaces(), 6);
    EXPECT_TRUE(record.leftOutCopies);
    const std::string names = shell ? "6 faces (Face7-Face12)" : "2 faces (Face7-Face8)";
    EXPECT_EQ(record.leftOut.rfind(names + " in no solid", 0), 0u) << record.leftOut;
    EXPECT_NE(
        record.leftOut.find(std::string("copies of ") + (shell ? "Face1-Face6" : "Face1-Face2") +
                            " of the solids; nothing of the model is lost"),
        std::string::npos)
        << record.leftOut;
    ASSERT_EQ(record.notes().size(), 1u);
    EXPECT_EQ(record.notes()[0].rfind("left out " + names, 0), 0u) << record.notes()[0];
  }
  // Two copies and faces elsewhere: refused, naming all seven.
  TopoDS_Compound c = withCopies(2);
  addFaces(c, box(), 10.0, false);  // 5 faces of another box, apart
  expectRefused(c, "mixed", "7 faces (Face7-Face13) in no solid");
}

// Healing off: nothing is sewn, and solids only still leaves the faces out by name; faces
// before the solid in the file's order renumber the solid's faces, which the record says.
TEST(CadHealing, SolidsOnlyWithoutHealingAndTheNumberingItChanges) {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  addFaces(c, box(), 5.0, true);  // would close, but healing is off
  b.Add(c, box());
  HealingRecord record;
  const CadModel cad = healModel(cadModelFromShape(c, "off"), HealingOptions{false, true}, record);
  EXPECT_TRUE(record.actions.empty());
  EXPECT_EQ(cad.numSolids(), 1);
  EXPECT_EQ(cad.numFaces(), 6);
  EXPECT_NE(record.leftOut.find("6 faces (Face1-Face6) in no solid, within x [5, 6]"),
            std::string::npos)
      << record.leftOut;
  EXPECT_TRUE(record.renumbered);
  // The solid's faces keep their own through the map; a face left out is refused saying why.
  EXPECT_EQ(record.numbering.map(2, {7, 12}, "boundary-layer face", "healing"),
            (std::vector<int>{1, 6}));
  try {
    record.numbering.map(2, {8, 3}, "boundary-layer face", "healing");
    FAIL() << "a face left out was mapped";
  } catch (const ParameterError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("boundary-layer face 3: Face3 was removed by leaving "
                                          "out the faces in no solid (6 faces",
                                          0),
              0U)
        << e.what();
  }
}

// Two boxes side by side, each with its own face at x = 1 (as Gmsh's STEP export writes
// fragments, and a STEP file of FreeCAD's Boolean fragments reads back): imprinted on each
// other by default, so that they share that face (cad/solid_imprint.hpp); with imprinting off,
// the mesh would not conform there, and the record says which solids and faces. Fused before
// (OpenCASCADE's general fuse, FreeCAD's Boolean fragments kept in BRep): nothing to do or say.
TEST(CadHealing, SolidsOnFacesTheyDoNotShareAreImprintedOrNamed) {
  const TopoDS_Shape left = BRepPrimAPI_MakeBox(1.0, 1.0, 1.0).Shape();
  const TopoDS_Shape right = BRepPrimAPI_MakeBox(gp_Pnt(1, 0, 0), 1.0, 1.0, 1.0).Shape();
  TopoDS_Compound apart;
  BRep_Builder b;
  b.MakeCompound(apart);
  b.Add(apart, left);
  b.Add(apart, right);
  HealingRecord imprinted;
  const CadModel joined = healModel(cadModelFromShape(apart, "apart"), {}, imprinted);
  EXPECT_EQ(joined.numSolids(), 2);
  EXPECT_EQ(joined.numFaces(), 11);
  EXPECT_TRUE(imprinted.imprint.imprinted);
  EXPECT_EQ(imprinted.imprint.interfaces.size(), 1U);
  EXPECT_TRUE(imprinted.warnings.empty()) << imprinted.warnings[0];
  EXPECT_FALSE(imprinted.renumbered);  // (healing's fixes did not; the imprint's map did)

  HealingOptions off;
  off.imprint = false;
  HealingRecord record;
  const CadModel cad = healModel(cadModelFromShape(apart, "apart"), off, record);
  EXPECT_EQ(cad.numSolids(), 2);
  EXPECT_EQ(cad.numFaces(), 12);
  ASSERT_EQ(record.warnings.size(), 1U);
  // The left box's face at x = 1 is its second (OpenCASCADE's box: x = 0, x = 1, ...), the
  // right box's at x = 1 its first: Face2 and Face7.
  EXPECT_NE(record.warnings[0].find("Solid1 and Solid2 (Face2 on Face7)"), std::string::npos)
      << record.warnings[0];
  EXPECT_NE(record.warnings[0].find("imprinting is off"), std::string::npos) << record.warnings[0];

  TopTools_ListOfShape arguments;
  arguments.Append(left);
  arguments.Append(right);
  BRepAlgoAPI_BuilderAlgo fuse;
  fuse.SetArguments(arguments);
  fuse.Build();
  ASSERT_TRUE(fuse.IsDone());
  HealingRecord shared;
  const CadModel fused = healModel(cadModelFromShape(fuse.Shape(), "fused"), {}, shared);
  EXPECT_EQ(fused.numSolids(), 2);
  EXPECT_EQ(fused.numFaces(), 11);  // the face at x = 1 is one face of both
  EXPECT_TRUE(shared.warnings.empty()) << shared.warnings[0];
  EXPECT_FALSE(shared.imprint.imprinted);  // nothing left to imprint
}

}  // namespace
}  // namespace homesh
