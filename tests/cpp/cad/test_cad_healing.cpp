// The CAD check and healing: a sound model is left exactly as it is; an empty solid is removed
// without touching the faces' numbering; faces that close are sewn into a solid; what cannot be
// closed is refused naming a free edge.
#include <gtest/gtest.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRep_Builder.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <string>

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
  const CadModel cad = healModel(cadModelFromShape(shape, "box"), true, record);
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
  const CadModel cad = healModel(cadModelFromShape(c, "model"), true, record);
  ASSERT_EQ(record.problems.size(), 1U);
  EXPECT_NE(record.problems[0].find("Solid2 has no face"), std::string::npos);
  EXPECT_EQ(record.solidsBefore, 2);
  EXPECT_EQ(record.solidsAfter, 1);
  EXPECT_EQ(cad.numSolids(), 1);
  EXPECT_FALSE(record.renumbered);  // the faces and edges are where they were
}

TEST(CadHealing, FacesThatCloseAreSewnIntoASolid) {
  HealingRecord record;
  const CadModel cad = healModel(cadModelFromShape(looseFaces(true), "faces"), true, record);
  EXPECT_EQ(record.solidsBefore, 0);
  EXPECT_EQ(cad.numSolids(), 1);
  EXPECT_EQ(cad.numFaces(), 6);
  ASSERT_FALSE(record.actions.empty());
  EXPECT_NE(record.actions[0].find("sewed"), std::string::npos);
}

// Two closed shells whose bounding boxes nest: one inside the other's material is a void and
// the model is refused (which side is material is not known); a post standing in a frame's
// hole is no void, the two are solids.
TEST(CadHealing, AShellInsideAnotherIsRefusedOneInAHoleIsASolid) {
  const TopoDS_Shape big = BRepPrimAPI_MakeBox(4.0, 4.0, 4.0).Shape();
  const TopoDS_Shape small = BRepPrimAPI_MakeBox(gp_Pnt(1, 1, 1), 1.0, 1.0, 1.0).Shape();
  HealingRecord voided;
  try {
    healModel(cadModelFromShape(looseFacesOf(big, small), "a box with a void"), true, voided);
    FAIL() << "a box with a void was accepted";
  } catch (const CadError& e) {
    EXPECT_NE(std::string(e.what()).find("closed shells one inside another"), std::string::npos)
        << e.what();
  }
  const TopoDS_Shape frame =
      BRepAlgoAPI_Cut(big, BRepPrimAPI_MakeBox(gp_Pnt(1, 1, -1), 2.0, 2.0, 6.0).Shape()).Shape();
  const TopoDS_Shape post = BRepPrimAPI_MakeBox(gp_Pnt(1.5, 1.5, 1), 1.0, 1.0, 2.0).Shape();
  HealingRecord record;
  const CadModel cad =
      healModel(cadModelFromShape(looseFacesOf(frame, post), "a frame and a post"), true, record);
  EXPECT_EQ(cad.numSolids(), 2);
}

TEST(CadHealing, WhatCannotBeClosedIsRefusedNamingAFreeEdge) {
  for (const bool heal : {true, false}) {
    HealingRecord record;
    try {
      healModel(cadModelFromShape(looseFaces(false), "five faces"), heal, record);
      FAIL() << "five faces of a box were accepted";
    } catch (const CadError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("five faces is not a closed solid"), std::string::npos) << message;
      EXPECT_NE(message.find("bounds only one face"), std::string::npos) << message;
      EXPECT_NE(message.find(heal ? "healing could not close it" : "healing is off"),
                std::string::npos)
          << message;
    }
  }
}

}  // namespace
}  // namespace homesh
