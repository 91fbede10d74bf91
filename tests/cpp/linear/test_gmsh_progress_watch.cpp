// GmshProgressWatch on Gmsh 4.8's own terminal lines: a run that refines a surface's edges while
// its invalid elements grow is a stall, named by its CAD face; a run that progresses is not.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "linear/gmsh_progress_watch.hpp"

namespace homesh {
namespace {

// Feeds `lines` to a silent watch; the first stall it reports, or "".
std::string firstStall(GmshProgressWatch& watch, const std::vector<std::string>& lines) {
  for (const std::string& line : lines) {
    std::string stall = watch(line);
    if (!stall.empty()) return stall;
  }
  return {};
}

// The rounds Gmsh 4.8 printed on a cylinder of radius 1 and length 1000 meshed with sizes from
// 2.5 to 50 (each round twice as long as the one before: 3, 5, 10, 20, 40 s).
std::vector<std::string> growingRounds(int rounds) {
  const long invalid[] = {16, 56, 234, 572, 2596};
  std::vector<std::string> lines = {
      "Info    : Meshing 1D...", "Info    : Meshing 2D...",
      "Info    : [  0%] Meshing surface 1 (Cylinder, Frontal-Delaunay)"};
  for (int r = 0; r < rounds; ++r) {
    lines.emplace_back("Info    : [100%] Meshing surface 1 (Cylinder, MeshAdapt)");
    lines.emplace_back("Warning : " + std::to_string(invalid[r]) +
                       " elements remain invalid in surface 1");
    lines.emplace_back(
        "Info    : [100%] Serializing surface 1 and refining all its bounding edges");
    lines.emplace_back("Info    : [100%] Meshing surface 2 (Plane, Frontal-Delaunay)");
    lines.emplace_back("Info    : [100%] Meshing surface 3 (Plane, Frontal-Delaunay)");
    lines.emplace_back("Info    : [100%] Meshing surface 1 (Cylinder, Frontal-Delaunay)");
    lines.emplace_back("Info    : [100%] 8-| Splitting those edges and trying again");
  }
  return lines;
}

TEST(GmshProgressWatch, InvalidElementsGrowingTwiceInARowIsAStallOnTheCadFace) {
  GmshProgressWatch watch(0);
  watch(gmshEntityLine(2, 1, 3));
  EXPECT_EQ(firstStall(watch, growingRounds(2)), "");
  GmshProgressWatch again(0);
  again(gmshEntityLine(2, 1, 3));
  EXPECT_EQ(firstStall(again, growingRounds(3)),
            "Gmsh's surface 1 (CAD face 3): its invalid elements rose from 16 to 56 to 234 as "
            "Gmsh refined its edges");
}

// Where healing or imprinting numbered the model afresh, the stall also names the face as the
// user knows it (LinearMeshOptions::givenNames).
TEST(GmshProgressWatch, AStallNamesTheFaceAsGivenToo) {
  GmshProgressWatch watch(0, [](int dim, int index) {
    return dim == 2 && index == 3 ? std::string("Face7") : std::string();
  });
  watch(gmshEntityLine(2, 1, 3));
  EXPECT_EQ(firstStall(watch, growingRounds(3)),
            "Gmsh's surface 1 (CAD face 3; as given: Face7): its invalid elements rose from 16 to "
            "56 to 234 as Gmsh refined its edges");
}

TEST(GmshProgressWatch, FewerInvalidElementsAfterARoundIsProgress) {
  GmshProgressWatch watch(0);
  const std::vector<std::string> lines = {
      "Warning : 44 elements remain invalid in surface 2",
      "Warning : 30 elements remain invalid in surface 2",
      "Warning : 234 elements remain invalid in surface 2",
      "Warning : 5 elements remain invalid in surface 7",  // another surface: its own count
      "Warning : 3 elements remain invalid in surface 2"};
  EXPECT_EQ(firstStall(watch, lines), "");
}

TEST(GmshProgressWatch, ASurfaceEnteredTwelveTimesIsAStall) {
  GmshProgressWatch watch(0);
  const std::vector<std::string> lines(
      GmshProgressWatch::kStallEntries - 1,
      "Info    : [ 50%] Meshing surface 4 (BSpline surface, Frontal-Delaunay)");
  EXPECT_EQ(firstStall(watch, lines), "");
  // Unknown to the entity lines: named by Gmsh's number only.
  EXPECT_EQ(watch("Info    : [ 50%] Meshing surface 4 (BSpline surface, MeshAdapt)"),
            "Gmsh's surface 4: Gmsh meshed it 12 times without finishing it");
}

// Gmsh says "1 element remain invalid" in the singular: counted too.
TEST(GmshProgressWatch, OneInvalidElementIsCountedToo) {
  GmshProgressWatch watch(0);
  EXPECT_EQ(
      firstStall(watch, {"Warning : 1 element remain invalid in surface 5",
                         "Warning : 2 elements remain invalid in surface 5",
                         "Warning : 3 elements remain invalid in surface 5"}),
      "Gmsh's surface 5: its invalid elements rose from 1 to 2 to 3 as Gmsh refined its edges");
}

// What a crash's message says: the entity Gmsh entered last and an error it said since; no
// entity once it finished that dimension, and no error said before the entity or dimension.
TEST(GmshProgressWatch, TheLastActivityNamesTheEntityAndItsError) {
  GmshProgressWatch watch(0);
  watch(gmshEntityLine(2, 38, 40));
  watch("Error   : an earlier error");
  watch("Info    : [ 50%] Meshing surface 38 (Torus, Frontal-Delaunay)");
  EXPECT_EQ(watch.lastActivity(), "while meshing Gmsh's surface 38 (CAD face 40)");
  watch("Error   : The 1D mesh seems not to be forming a closed loop");
  EXPECT_EQ(watch.lastActivity(),
            "while meshing Gmsh's surface 38 (CAD face 40), after its error: The 1D mesh seems "
            "not to be forming a closed loop");
  watch("Info    : Done meshing 2D (Wall 0.1s, CPU 0.1s)");
  watch("Info    : Meshing 3D...");
  EXPECT_EQ(watch.lastActivity(), "");
  watch("Error   : No tetrahedra in region 1");
  EXPECT_EQ(watch.lastActivity(), "after Gmsh's error: No tetrahedra in region 1");
}

// The lines Gmsh 4.8 printed meshing a cylinder (radius 1, height 10, size 0.5): no stall.
TEST(GmshProgressWatch, AnOrdinaryRunIsNoStall) {
  GmshProgressWatch watch(0);
  const std::vector<std::string> lines = {
      "Info    : Meshing 1D...",
      "Info    : [  0%] Meshing curve 1 (Circle)",
      "Info    : [ 40%] Meshing curve 2 (Line)",
      "Info    : [ 70%] Meshing curve 3 (Circle)",
      "Info    : Done meshing 1D (Wall 0.000240007s, CPU 0.000208s)",
      "Info    : Meshing 2D...",
      "Info    : [  0%] Meshing surface 1 (Cylinder, Frontal-Delaunay)",
      "Info    : [ 40%] Meshing surface 2 (Plane, Frontal-Delaunay)",
      "Info    : [ 70%] Meshing surface 3 (Plane, Frontal-Delaunay)",
      "Info    : Done meshing 2D (Wall 0.0184288s, CPU 0.018151s)",
      "Info    : Meshing 3D...",
      "Info    : It. 0 - 0 nodes created - worst tet radius 2.1085 (nodes removed 0 0)",
      "Info    : Done meshing 3D (Wall 0.034218s, CPU 0.014179s)",
      "some other line"};
  EXPECT_EQ(firstStall(watch, lines), "");
}

}  // namespace
}  // namespace homesh
