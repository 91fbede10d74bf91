// NekMesh mesh configuration files (.mcf): the five peer cases (when NekMesh's files are here)
// and cases of each kind written here, notices for keys HOMesh does not use, and malformed files.
#include <gtest/gtest.h>

#include <STEPControl_Writer.hxx>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "io/mcf_reader.hpp"
#include "peer_data.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

namespace fs = std::filesystem;

std::string peer(const std::string& name) {
  return test::peerFile("meshgen/" + name);
}

// Writes an .mcf whose MESHING holds `body` into a fresh folder and returns its path.
std::string writeMcf(const std::string& body, const std::string& name = "case.mcf") {
  const fs::path path = test::tempDir() / name;
  std::ofstream(path) << "<NEKTAR>\n<MESHING>\n" << body << "\n</MESHING>\n</NEKTAR>\n";
  return path.string();
}

const std::string kInformation =
    "<INFORMATION><I PROPERTY=\"CADFile\" VALUE=\"part.stp\"/>"
    "<I PROPERTY=\"MeshType\" VALUE=\"3D\"/></INFORMATION>";

std::string withParameters(const std::string& parameters) {
  return kInformation + "<PARAMETERS>" + parameters + "</PARAMETERS>";
}

// The ParameterError message readMcfFile throws for this file ("" when it throws none).
std::string parameterError(const std::string& path) {
  try {
    readMcfFile(path);
  } catch (const ParameterError& e) {
    return e.what();
  }
  return "";
}

bool hasNotice(const McfCase& c, const std::string& text) {
  return std::any_of(c.notices.begin(), c.notices.end(),
                     [&](const std::string& n) { return n == text; });
}

#define EXPECT_ERROR_HAS(path, text)                            \
  EXPECT_NE(parameterError(path).find(text), std::string::npos) \
      << "message: " << parameterError(path)

// A case file laid out as NekMesh writes them (an XML declaration, a comment, indentation, tabs
// and blank lines between the sections), holding `sections`, written as dir / name.
std::string writeCase(const fs::path& dir, const std::string& name, const std::string& sections) {
  const fs::path path = dir / name;
  std::ofstream(path) << "<?xml version=\"1.0\" encoding=\"utf-8\" ?>\n"
                      << "<!-- a case written by the test -->\n<NEKTAR>\n  <MESHING>\n\n"
                      << sections << "\n  </MESHING>\n</NEKTAR>\n";
  return path.string();
}

std::string information(const std::string& cad, const std::string& type) {
  return "    <INFORMATION>\n      <I PROPERTY=\"CADFile\" VALUE=\"" + cad +
         "\" />\n      <I PROPERTY=\"MeshType\" VALUE=\"" + type + "\"\t/>\n    </INFORMATION>\n\n";
}

std::string parameters(const std::vector<std::pair<std::string, std::string>>& values) {
  std::string out = "    <PARAMETERS>\n";
  for (const auto& [key, value] : values)
    out.append("      <P PARAM=\"")
        .append(key)
        .append("\"\tVALUE=\"")
        .append(value)
        .append("\"   />\n");
  return out + "    </PARAMETERS>\n\n";
}

std::string boolParameters(const std::vector<std::string>& names) {
  std::string out = "    <BOOLPARAMETERS>\n";
  for (const auto& name : names) out += "      <P VALUE=\"" + name + "\" />\n";
  return out + "    </BOOLPARAMETERS>\n";
}

TEST(McfReader, ReadsTheSphereCase) {
  HOMESH_REQUIRE_PEER_FILES();
  const McfCase c = readMcfFile(peer("3d_sphere.mcf"));
  EXPECT_EQ(c.path, peer("3d_sphere.mcf"));
  EXPECT_EQ(c.cadFile, fs::path(peer("3d_sphere.stp")).lexically_normal().string());
  EXPECT_TRUE(fs::exists(c.cadFile));
  EXPECT_FALSE(c.isNaca());
  EXPECT_EQ(c.meshType, "3D");
  EXPECT_DOUBLE_EQ(*c.minDelta, 0.04);
  EXPECT_DOUBLE_EQ(*c.maxDelta, 0.2);
  EXPECT_DOUBLE_EQ(*c.eps, 0.02);
  EXPECT_EQ(*c.order, 4);
  EXPECT_TRUE(c.boundaryLayer.empty());
  EXPECT_FALSE(c.xmin || c.ymin || c.xmax || c.ymax || c.aoa);
  EXPECT_EQ(c.boolParameters, std::set<std::string>{"SurfaceOptimiser"});
  EXPECT_TRUE(c.refinementLines.empty());
  ASSERT_EQ(c.notices.size(), 1u);
  EXPECT_EQ(c.notices[0],
            "3d_sphere.mcf: BOOLPARAMETERS SurfaceOptimiser is not supported yet "
            "and is ignored");
}

TEST(McfReader, ReadsTheBoundaryLayerCylinderWithoutBoolParameters) {
  HOMESH_REQUIRE_PEER_FILES();
  const McfCase c = readMcfFile(peer("3d_bl_cyl.mcf"));
  EXPECT_EQ(c.meshType, "3DBndLayer");
  EXPECT_TRUE(c.hasBoundaryLayer());
  EXPECT_FALSE(c.is2D());
  EXPECT_EQ(fs::path(c.cadFile).filename(), "3d_bl_cyl.stp");
  EXPECT_DOUBLE_EQ(*c.minDelta, 0.03);
  EXPECT_DOUBLE_EQ(*c.maxDelta, 0.2);
  EXPECT_DOUBLE_EQ(*c.eps, 0.5);
  EXPECT_EQ(*c.order, 4);
  const std::map<std::string, std::string> bl = {{"BndLayerSurfaces", "1,8"},
                                                 {"BndLayerThickness", "0.04"},
                                                 {"BndLayerLayers", "6"},
                                                 {"BndLayerProgression", "1.5"}};
  EXPECT_EQ(c.boundaryLayer, bl);
  EXPECT_TRUE(c.boolParameters.empty());
  EXPECT_TRUE(c.notices.empty());
}

TEST(McfReader, ReadsThe2DAerofoilAndT106Cases) {
  HOMESH_REQUIRE_PEER_FILES();
  const McfCase a = readMcfFile(peer("2d_bl_aerofoil.mcf"));
  EXPECT_EQ(a.meshType, "2DBndLayer");
  EXPECT_TRUE(a.is2D());
  EXPECT_EQ(fs::path(a.cadFile).filename(), "2d_bl_aerofoil.stp");
  EXPECT_DOUBLE_EQ(*a.minDelta, 0.005);
  EXPECT_DOUBLE_EQ(*a.maxDelta, 2.0);
  EXPECT_DOUBLE_EQ(*a.eps, 0.0001);
  EXPECT_EQ(*a.order, 4);
  EXPECT_EQ(a.boundaryLayer.at("BndLayerSurfaces"), "2,4");
  EXPECT_EQ(a.boundaryLayer.at("BndLayerThickness"), "0.1");
  EXPECT_EQ(a.boundaryLayer.at("BndLayerLayers"), "6");
  EXPECT_EQ(a.boundaryLayer.at("BndLayerProgression"), "1.5");
  EXPECT_EQ(a.boundaryLayerLayers, 6);
  EXPECT_EQ(a.boundaryLayerProgression, 1.5);
  EXPECT_TRUE(a.boolParameters.empty());  // an empty BOOLPARAMETERS
  EXPECT_TRUE(a.notices.empty());

  const McfCase t = readMcfFile(peer("2d_bl_t106.mcf"));
  EXPECT_DOUBLE_EQ(*t.minDelta, 0.01);
  EXPECT_DOUBLE_EQ(*t.maxDelta, 0.5);
  EXPECT_DOUBLE_EQ(*t.eps, 1.0);  // the upper limit is valid
  EXPECT_EQ(t.boundaryLayer.at("BndLayerSurfaces"), "11-12");
  EXPECT_EQ(t.boundaryLayer.at("BndLayerThickness"), "0.01+0.05*x");  // an expression, as text
  EXPECT_EQ(t.boundaryLayer.size(), 2u);
  EXPECT_TRUE(t.notices.empty());
}

TEST(McfReader, ReadsTheNacaCase) {
  HOMESH_REQUIRE_PEER_FILES();
  const McfCase c = readMcfFile(peer("2d_bl_naca0012.mcf"));
  ASSERT_TRUE(c.isNaca());
  EXPECT_EQ(*c.nacaDigits, "0012");
  EXPECT_TRUE(c.cadFile.empty());
  EXPECT_EQ(c.meshType, "2DBndLayer");
  EXPECT_DOUBLE_EQ(*c.minDelta, 0.1);
  EXPECT_DOUBLE_EQ(*c.maxDelta, 5.0);
  EXPECT_DOUBLE_EQ(*c.eps, 0.1);
  EXPECT_EQ(*c.order, 4);
  EXPECT_DOUBLE_EQ(*c.xmin, -1.0);
  EXPECT_DOUBLE_EQ(*c.ymin, -2.0);
  EXPECT_DOUBLE_EQ(*c.xmax, 3.0);
  EXPECT_DOUBLE_EQ(*c.ymax, 2.0);
  EXPECT_DOUBLE_EQ(*c.aoa, 15.0);
  EXPECT_EQ(c.boundaryLayer.at("BndLayerSurfaces"), "5-6");
  EXPECT_EQ(c.boundaryLayer.at("BndLayerThickness"), "0.05");
  EXPECT_EQ(c.boundaryLayer.at("BndLayerAdjustment"), "2.0");
  EXPECT_EQ(c.boolParameters, std::set<std::string>{"BndLayerAdjustEverywhere"});
  ASSERT_EQ(c.notices.size(), 1u);
  EXPECT_EQ(c.notices[0],
            "2d_bl_naca0012.mcf: BOOLPARAMETERS BndLayerAdjustEverywhere is not "
            "supported yet and is ignored");
}

// The cases below are of the peer files' kinds, written here with values of their own, so that
// the reader is covered without NekMesh's files: every field it gives is checked.

// A 3D sphere case beside its CAD, a STEP file OCCT writes here: the CAD path resolves beside
// the case, and the one notice is for the surface optimiser HOMesh does not have.
TEST(McfReader, ReadsASphereCaseBesideItsStepFile) {
  const fs::path dir = test::tempDir();
  STEPControl_Writer step;
  ASSERT_EQ(step.Transfer(test::sphere(0.8), STEPControl_AsIs), IFSelect_RetDone);
  ASSERT_EQ(step.Write((dir / "ball.step").string().c_str()), IFSelect_RetDone);
  const std::string path = writeCase(
      dir, "ball.mcf",
      information("ball.step", "3D") +
          parameters({{"MinDelta", "0.05"}, {"MaxDelta", "0.3"}, {"EPS", "0.05"}, {"Order", "3"}}) +
          boolParameters({"SurfaceOptimiser"}));
  const McfCase c = readMcfFile(path);
  EXPECT_EQ(c.path, path);
  EXPECT_EQ(c.cadFile, (dir / "ball.step").lexically_normal().string());
  EXPECT_TRUE(fs::exists(c.cadFile));
  EXPECT_FALSE(c.isNaca());
  EXPECT_EQ(c.meshType, "3D");
  EXPECT_FALSE(c.is2D());
  EXPECT_FALSE(c.hasBoundaryLayer());
  EXPECT_DOUBLE_EQ(*c.minDelta, 0.05);
  EXPECT_DOUBLE_EQ(*c.maxDelta, 0.3);
  EXPECT_DOUBLE_EQ(*c.eps, 0.05);
  EXPECT_EQ(*c.order, 3);
  EXPECT_TRUE(c.boundaryLayer.empty());
  EXPECT_FALSE(c.boundaryLayerLayers || c.boundaryLayerProgression);
  EXPECT_FALSE(c.xmin || c.ymin || c.xmax || c.ymax || c.aoa);
  EXPECT_EQ(c.boolParameters, std::set<std::string>{"SurfaceOptimiser"});
  EXPECT_TRUE(c.refinementLines.empty());
  ASSERT_EQ(c.notices.size(), 1u);
  EXPECT_EQ(c.notices[0],
            "ball.mcf: BOOLPARAMETERS SurfaceOptimiser is not supported yet and is ignored");
}

// A 3D boundary-layer case without BOOLPARAMETERS, beside a copy of the repository's box with a
// hole: the layer's four parameters as text, the count and the progression parsed, no notice.
TEST(McfReader, ReadsABoundaryLayerCaseWithoutBoolParameters) {
  const fs::path dir = test::tempDir();
  fs::copy_file(fs::path(HOMESH_SOURCE_DIR) / "tests" / "data" / "box_hole.step",
                dir / "holed.step");
  const McfCase c = readMcfFile(writeCase(
      dir, "holed.mcf",
      information("holed.step", "3DBndLayer") + parameters({{"MinDelta", "0.02"},
                                                            {"MaxDelta", "0.5"},
                                                            {"EPS", "0.25"},
                                                            {"Order", "2"},
                                                            {"BndLayerSurfaces", "3,7"},
                                                            {"BndLayerThickness", "0.06"},
                                                            {"BndLayerLayers", "5"},
                                                            {"BndLayerProgression", "1.25"}})));
  EXPECT_EQ(c.meshType, "3DBndLayer");
  EXPECT_TRUE(c.hasBoundaryLayer());
  EXPECT_FALSE(c.is2D());
  EXPECT_FALSE(c.isNaca());
  EXPECT_EQ(c.cadFile, (dir / "holed.step").string());
  EXPECT_TRUE(fs::exists(c.cadFile));
  EXPECT_DOUBLE_EQ(*c.minDelta, 0.02);
  EXPECT_DOUBLE_EQ(*c.maxDelta, 0.5);
  EXPECT_DOUBLE_EQ(*c.eps, 0.25);
  EXPECT_EQ(*c.order, 2);
  const std::map<std::string, std::string> bl = {{"BndLayerSurfaces", "3,7"},
                                                 {"BndLayerThickness", "0.06"},
                                                 {"BndLayerLayers", "5"},
                                                 {"BndLayerProgression", "1.25"}};
  EXPECT_EQ(c.boundaryLayer, bl);
  EXPECT_EQ(c.boundaryLayerLayers, 5);
  EXPECT_EQ(c.boundaryLayerProgression, 1.25);
  EXPECT_FALSE(c.xmin || c.ymin || c.xmax || c.ymax || c.aoa);
  EXPECT_TRUE(c.boolParameters.empty());
  EXPECT_TRUE(c.refinementLines.empty());
  EXPECT_TRUE(c.notices.empty());
}

// 2D cases: a boundary layer with an empty BOOLPARAMETERS, one whose thickness is an expression
// (kept as text) with EPS at its upper limit, and a plain 2D case whose absent parameters stay
// absent (the pipeline's defaults apply).
TEST(McfReader, Reads2DCases) {
  const fs::path dir = test::tempDir();
  const McfCase a = readMcfFile(writeCase(dir, "fin.mcf",
                                          information("fin.stp", "2DBndLayer") +
                                              parameters({{"MinDelta", "0.002"},
                                                          {"MaxDelta", "1.5"},
                                                          {"EPS", "0.001"},
                                                          {"Order", "5"},
                                                          {"BndLayerSurfaces", "1,3"},
                                                          {"BndLayerThickness", "0.2"},
                                                          {"BndLayerLayers", "3"},
                                                          {"BndLayerProgression", "2"}}) +
                                              "    <BOOLPARAMETERS>\n    </BOOLPARAMETERS>\n"));
  EXPECT_EQ(a.meshType, "2DBndLayer");
  EXPECT_TRUE(a.is2D());
  EXPECT_TRUE(a.hasBoundaryLayer());
  EXPECT_EQ(a.cadFile, (dir / "fin.stp").string());
  EXPECT_DOUBLE_EQ(*a.minDelta, 0.002);
  EXPECT_DOUBLE_EQ(*a.maxDelta, 1.5);
  EXPECT_DOUBLE_EQ(*a.eps, 0.001);
  EXPECT_EQ(*a.order, 5);
  EXPECT_EQ(a.boundaryLayer.at("BndLayerSurfaces"), "1,3");
  EXPECT_EQ(a.boundaryLayer.at("BndLayerThickness"), "0.2");
  EXPECT_EQ(a.boundaryLayer.at("BndLayerLayers"), "3");
  EXPECT_EQ(a.boundaryLayer.at("BndLayerProgression"), "2");
  EXPECT_EQ(a.boundaryLayer.size(), 4u);
  EXPECT_EQ(a.boundaryLayerLayers, 3);
  EXPECT_EQ(a.boundaryLayerProgression, 2.0);
  EXPECT_TRUE(a.boolParameters.empty());  // an empty BOOLPARAMETERS
  EXPECT_TRUE(a.notices.empty());

  const McfCase b = readMcfFile(writeCase(
      dir, "blade.mcf",
      information("blade.stp", "2DBndLayer") + parameters({{"MinDelta", "0.02"},
                                                           {"MaxDelta", "0.4"},
                                                           {"EPS", "1"},
                                                           {"BndLayerSurfaces", "7-9"},
                                                           {"BndLayerThickness", "0.02+0.1*x"}})));
  EXPECT_DOUBLE_EQ(*b.minDelta, 0.02);
  EXPECT_DOUBLE_EQ(*b.maxDelta, 0.4);
  EXPECT_DOUBLE_EQ(*b.eps, 1.0);  // the upper limit is valid
  EXPECT_FALSE(b.order);
  EXPECT_EQ(b.boundaryLayer.at("BndLayerSurfaces"), "7-9");
  EXPECT_EQ(b.boundaryLayer.at("BndLayerThickness"), "0.02+0.1*x");  // an expression, as text
  EXPECT_EQ(b.boundaryLayer.size(), 2u);
  EXPECT_FALSE(b.boundaryLayerLayers || b.boundaryLayerProgression);
  EXPECT_TRUE(b.notices.empty());

  const McfCase c =
      readMcfFile(writeCase(dir, "plate.mcf",
                            information("shapes/plate.igs", "2D") +
                                parameters({{"MinDelta", "0.1"}, {"MaxDelta", "0.1"}})));
  EXPECT_EQ(c.meshType, "2D");
  EXPECT_TRUE(c.is2D());
  EXPECT_FALSE(c.hasBoundaryLayer());
  EXPECT_EQ(c.cadFile, (dir / "shapes" / "plate.igs").string());
  EXPECT_DOUBLE_EQ(*c.minDelta, 0.1);  // MinDelta equal to MaxDelta: a uniform size
  EXPECT_DOUBLE_EQ(*c.maxDelta, 0.1);
  EXPECT_FALSE(c.eps || c.order);
  EXPECT_TRUE(c.boundaryLayer.empty());
  EXPECT_TRUE(c.boolParameters.empty());
  EXPECT_TRUE(c.notices.empty());
}

// A NACA case: CADFile "NNNN" is the aerofoil's digits, not a file; its box and angle of attack
// are read, and the BOOLPARAMETERS HOMesh does not use yet gets its notice.
TEST(McfReader, ReadsANacaCase) {
  const McfCase c = readMcfFile(writeCase(test::tempDir(), "wing.mcf",
                                          information("4415", "2DBndLayer") +
                                              parameters({{"MinDelta", "0.05"},
                                                          {"MaxDelta", "4"},
                                                          {"EPS", "0.2"},
                                                          {"Order", "3"},
                                                          {"BndLayerSurfaces", "2-3"},
                                                          {"BndLayerThickness", "0.08"},
                                                          {"BndLayerAdjustment", "1.5"},
                                                          {"Xmin", "-2.5"},
                                                          {"Ymin", "-1.5"},
                                                          {"Xmax", "4"},
                                                          {"Ymax", "1.25"},
                                                          {"AOA", "7.5"}}) +
                                              boolParameters({"BndLayerAdjustEverywhere"})));
  ASSERT_TRUE(c.isNaca());
  EXPECT_EQ(*c.nacaDigits, "4415");
  EXPECT_TRUE(c.cadFile.empty());
  EXPECT_EQ(c.meshType, "2DBndLayer");
  EXPECT_TRUE(c.is2D());
  EXPECT_DOUBLE_EQ(*c.minDelta, 0.05);
  EXPECT_DOUBLE_EQ(*c.maxDelta, 4.0);
  EXPECT_DOUBLE_EQ(*c.eps, 0.2);
  EXPECT_EQ(*c.order, 3);
  EXPECT_DOUBLE_EQ(*c.xmin, -2.5);
  EXPECT_DOUBLE_EQ(*c.ymin, -1.5);
  EXPECT_DOUBLE_EQ(*c.xmax, 4.0);
  EXPECT_DOUBLE_EQ(*c.ymax, 1.25);
  EXPECT_DOUBLE_EQ(*c.aoa, 7.5);
  const std::map<std::string, std::string> bl = {
      {"BndLayerSurfaces", "2-3"}, {"BndLayerThickness", "0.08"}, {"BndLayerAdjustment", "1.5"}};
  EXPECT_EQ(c.boundaryLayer, bl);
  EXPECT_EQ(c.boolParameters, std::set<std::string>{"BndLayerAdjustEverywhere"});
  EXPECT_TRUE(c.refinementLines.empty());
  ASSERT_EQ(c.notices.size(), 1u);
  EXPECT_EQ(c.notices[0],
            "wing.mcf: BOOLPARAMETERS BndLayerAdjustEverywhere is not supported yet and is "
            "ignored");
}

TEST(McfReader, NoticesUnknownAndUnsupportedKeys) {
  const std::string path = writeMcf(
      "<INFORMATION><I PROPERTY=\"CADFile\" VALUE=\"part.stp\"/>"
      "<I PROPERTY=\"MeshType\" VALUE=\"3D\"/><I PROPERTY=\"Author\" VALUE=\"me\"/></INFORMATION>"
      "<PARAMETERS><P PARAM=\"Foo\" VALUE=\"1\"/><P PARAM=\"mindelta\" VALUE=\"0.1\"/>"
      "<P PARAM=\"SurfaceOptimiser\" VALUE=\"1\"/><P PARAM=\"BndLayerLayers\" VALUE=\"3\"/>"
      "<P PARAM=\"AOA\" VALUE=\"3\"/></PARAMETERS>"
      "<BOOLPARAMETERS><P VALUE=\"VariationalOptimiser\"/><P VALUE=\"WriteOctree\"/>"
      "<P VALUE=\"surfaceOptimiser\"/><P VALUE=\"Bar\"/></BOOLPARAMETERS>"
      "<PERIODIC><P PAIR=\"1,2\"/></PERIODIC><EXTRA/>",
      "x.mcf");
  const McfCase c = readMcfFile(path);
  for (const char* n : {
           "x.mcf: unknown INFORMATION key 'Author' is ignored",
           "x.mcf: unknown PARAMETERS key 'Foo' is ignored",
           "x.mcf: unknown PARAMETERS key 'mindelta' is ignored; did you mean 'MinDelta'? (keys "
           "are case-sensitive)",
           "x.mcf: unknown PARAMETERS key 'SurfaceOptimiser' is ignored; 'SurfaceOptimiser' "
           "belongs in BOOLPARAMETERS",
           "x.mcf: PARAMETERS BndLayerLayers is ignored: MeshType 3D makes no boundary layer",
           "x.mcf: PARAMETERS AOA is ignored: only a NACA case (CADFile NNNN) uses it",
           "x.mcf: BOOLPARAMETERS VariationalOptimiser is not supported yet and is ignored",
           "x.mcf: BOOLPARAMETERS WriteOctree is not supported yet and is ignored",
           "x.mcf: unknown BOOLPARAMETERS key 'surfaceOptimiser' is ignored; did you mean "
           "'SurfaceOptimiser'? (keys are case-sensitive)",
           "x.mcf: unknown BOOLPARAMETERS key 'Bar' is ignored",
           "x.mcf: section PERIODIC is not supported yet and is ignored",
           "x.mcf: unknown section <EXTRA> in MESHING is ignored",
       })
    EXPECT_TRUE(hasNotice(c, n)) << n;
  EXPECT_EQ(c.notices.size(), 12u);
  EXPECT_FALSE(c.minDelta);  // 'mindelta' is not MinDelta
  EXPECT_EQ(c.boolParameters.size(), 4u);
}

TEST(McfReader, ResolvesTheCadPathAgainstTheMcfFolder) {
  const fs::path dir = test::tempDir();
  fs::create_directories(dir / "cases");
  const auto write = [&](const std::string& cad) {
    std::ofstream(dir / "cases" / "c.mcf")
        << R"(<NEKTAR><MESHING><INFORMATION><I PROPERTY="CADFile" VALUE=")" << cad
        << R"("/><I PROPERTY="MeshType" VALUE="3D"/></INFORMATION></MESHING></NEKTAR>)";
    return (dir / "cases" / "c.mcf").string();
  };
  EXPECT_EQ(readMcfFile(write("part.stp")).cadFile, (dir / "cases" / "part.stp").string());
  EXPECT_EQ(readMcfFile(write("../cad/part.step")).cadFile, (dir / "cad" / "part.step").string());
  EXPECT_EQ(readMcfFile(write("/abs/part.igs")).cadFile, "/abs/part.igs");

  // A path without a folder resolves against the working directory.
  write("part.stp");
  const fs::path cwd = fs::current_path();
  fs::current_path(dir / "cases");
  const McfCase local = readMcfFile("c.mcf");
  fs::current_path(cwd);
  EXPECT_EQ(local.cadFile, "part.stp");
  EXPECT_EQ(local.path, "c.mcf");
}

TEST(McfReader, ReadsRefinementLinesInBothForms) {
  const std::string path =
      writeMcf(withParameters(R"(<P PARAM="MinDelta" VALUE="0.01"/>)") +
               "<REFINEMENT>"
               "<LINE><X1>0 0.5 1</X1><X2>1, 2,3</X2><R>0.25</R><D>0.01</D></LINE>"
               "<LINE><X1>-1</X1><Y1>-2</Y1><Z1>-3</Z1><X2>4</X2><Y2>5</Y2><Z2>6</Z2>"
               "<R>1e-1</R><D> 2E-2 </D></LINE>"
               "</REFINEMENT>");
  const McfCase c = readMcfFile(path);
  ASSERT_EQ(c.refinementLines.size(), 2u);
  EXPECT_EQ(c.refinementLines[0].x1, Eigen::Vector3d(0, 0.5, 1));
  EXPECT_EQ(c.refinementLines[0].x2, Eigen::Vector3d(1, 2, 3));
  EXPECT_DOUBLE_EQ(c.refinementLines[0].radius, 0.25);
  EXPECT_DOUBLE_EQ(c.refinementLines[0].delta, 0.01);
  EXPECT_EQ(c.refinementLines[1].x1, Eigen::Vector3d(-1, -2, -3));
  EXPECT_EQ(c.refinementLines[1].x2, Eigen::Vector3d(4, 5, 6));
  EXPECT_DOUBLE_EQ(c.refinementLines[1].radius, 0.1);
  EXPECT_DOUBLE_EQ(c.refinementLines[1].delta, 0.02);
  EXPECT_TRUE(c.notices.empty());
}

TEST(McfReader, RejectsBadRefinementLines) {
  const auto line = [](const std::string& inner) {
    return writeMcf(kInformation + "<REFINEMENT><LINE>" + inner + "</LINE></REFINEMENT>");
  };
  EXPECT_ERROR_HAS(line("<X1>0 0 0</X1><X2>1 0 0</X2><R>0.5</R>"),
                   "case.mcf: REFINEMENT LINE 1 has no <D>");
  EXPECT_ERROR_HAS(line("<X1>0 0 0</X1><R>0.5</R><D>0.1</D>"), "REFINEMENT LINE 1 has no <X2>");
  EXPECT_ERROR_HAS(line("<X1>0 0</X1><X2>1 0 0</X2><R>0.5</R><D>0.1</D>"),
                   "REFINEMENT LINE 1 X1 must be three numbers (x y z), got '0 0'");
  EXPECT_ERROR_HAS(line("<X1>0 0 0</X1><X2>1,,0 0</X2><R>0.5</R><D>0.1</D>"),
                   "REFINEMENT LINE 1 X2 must be three numbers");
  EXPECT_ERROR_HAS(line("<X1>0 0 0</X1><X2>1 0 0</X2><R>0</R><D>0.1</D>"),
                   "REFINEMENT LINE 1 R must be positive, got 0");
  EXPECT_ERROR_HAS(line("<X1>0 0 0</X1><X2>1 0 0</X2><R>0.5</R><D>-1</D>"),
                   "REFINEMENT LINE 1 D must be positive, got -1");
  EXPECT_ERROR_HAS(line("<X1>0 0 0</X1><X2>1 0 0</X2><R>0.5x</R><D>1</D>"),
                   "REFINEMENT LINE 1 R must be a number, got '0.5x'");
  // NekMesh's own form needs all six coordinates.
  EXPECT_ERROR_HAS(line("<X1>0</X1><Y1>0</Y1><X2>1</X2><Y2>0</Y2><Z2>0</Z2><R>1</R><D>1</D>"),
                   "REFINEMENT LINE 1 has no <Z1>");
}

TEST(McfReader, RejectsMissingAndBadValues) {
  EXPECT_ERROR_HAS(writeMcf("<INFORMATION><I PROPERTY=\"MeshType\" VALUE=\"3D\"/></INFORMATION>"),
                   "case.mcf: INFORMATION CADFile is missing");
  EXPECT_ERROR_HAS(writeMcf("<INFORMATION><I PROPERTY=\"CADFile\" VALUE=\"a.stp\"/></INFORMATION>"),
                   "INFORMATION MeshType is missing");
  EXPECT_ERROR_HAS(writeMcf("<INFORMATION><I PROPERTY=\"CADFile\" VALUE=\"a.stp\"/>"
                            "<I PROPERTY=\"MeshType\" VALUE=\"3d\"/></INFORMATION>"),
                   "INFORMATION MeshType must be 3D, 2D, 3DBndLayer or 2DBndLayer, got '3d'");
  EXPECT_ERROR_HAS(writeMcf("<INFORMATION><I PROPERTY=\"CADFile\" VALUE=\"a.stp\"/>"
                            "<I PROPERTY=\"MeshType\" VALUE=\"Manifold\"/></INFORMATION>"),
                   "got 'Manifold' (surface-only meshes are not supported yet)");
  EXPECT_ERROR_HAS(
      writeMcf(withParameters("<P PARAM=\"MinDelta\" VALUE=\"abc\"/>"), "3d_sphere.mcf"),
      "3d_sphere.mcf: PARAMETERS MinDelta must be a number, got 'abc'");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"MaxDelta\" VALUE=\"0.1abc\"/>")),
                   "PARAMETERS MaxDelta must be a number, got '0.1abc'");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"MaxDelta\" VALUE=\"nan\"/>")),
                   "PARAMETERS MaxDelta must be a number, got 'nan'");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"MinDelta\" VALUE=\"\"/>")),
                   "PARAMETERS MinDelta must be a number, got ''");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"MinDelta\" VALUE=\"0\"/>")),
                   "PARAMETERS MinDelta must be positive, got 0");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"EPS\" VALUE=\"1.5\"/>")),
                   "PARAMETERS EPS must be at most 1");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"EPS\" VALUE=\"-0.1\"/>")),
                   "PARAMETERS EPS must be positive, got -0.1");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"MinDelta\" VALUE=\"2\"/>"
                                           "<P PARAM=\"MaxDelta\" VALUE=\"1\"/>")),
                   "PARAMETERS MinDelta (2) must not exceed MaxDelta (1)");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"Order\" VALUE=\"4.5\"/>")),
                   "PARAMETERS Order must be an integer, got '4.5'");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"Order\" VALUE=\"11\"/>")),
                   "PARAMETERS Order must be between 1 and 10, got 11");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"Order\" VALUE=\"0\"/>")),
                   "PARAMETERS Order must be between 1 and 10, got 0");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"Order\" VALUE=\"3\"/>"
                                           "<P PARAM=\"Order\" VALUE=\"4\"/>")),
                   "PARAMETERS Order is given twice");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"BndLayerLayers\" VALUE=\"six\"/>")),
                   "PARAMETERS BndLayerLayers must be a positive integer, got 'six'");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P PARAM=\"BndLayerProgression\" VALUE=\"0\"/>")),
                   "PARAMETERS BndLayerProgression must be positive, got 0");
  EXPECT_ERROR_HAS(writeMcf(withParameters("<P VALUE=\"4\"/>")),
                   "PARAMETERS: a <P> has no PARAM attribute");
  EXPECT_ERROR_HAS(writeMcf("<PARAMETERS/>"), "no <INFORMATION> in <MESHING>");

  // Accepted spellings: surrounding blanks, a leading '+', exponents, EPS exactly 1.
  const McfCase ok = readMcfFile(writeMcf(
      withParameters("<P PARAM=\"MinDelta\" VALUE=\" +1e-2 \"/><P PARAM=\"EPS\" VALUE=\"1\"/>"
                     "<P PARAM=\"Order\" VALUE=\" 10\"/>")));
  EXPECT_DOUBLE_EQ(*ok.minDelta, 0.01);
  EXPECT_DOUBLE_EQ(*ok.eps, 1.0);
  EXPECT_EQ(*ok.order, 10);
}

TEST(McfReader, ChecksBoundaryLayerAndNacaRequirements) {
  const auto info = [](const std::string& cad, const std::string& type) {
    return R"(<INFORMATION><I PROPERTY="CADFile" VALUE=")" + cad +
           R"("/><I PROPERTY="MeshType" VALUE=")" + type + R"("/></INFORMATION>)";
  };
  EXPECT_ERROR_HAS(writeMcf(info("a.stp", "3DBndLayer") +
                            "<PARAMETERS><P PARAM=\"BndLayerSurfaces\" VALUE=\"1\"/></PARAMETERS>"),
                   "PARAMETERS BndLayerThickness is missing (needed by MeshType 3DBndLayer)");
  const std::string box =
      "<P PARAM=\"Xmin\" VALUE=\"-1\"/><P PARAM=\"Ymin\" VALUE=\"-1\"/>"
      "<P PARAM=\"Xmax\" VALUE=\"2\"/><P PARAM=\"Ymax\" VALUE=\"1\"/>";
  EXPECT_ERROR_HAS(writeMcf(info("2412", "2D") + "<PARAMETERS>" + box + "</PARAMETERS>"),
                   "PARAMETERS AOA is missing (needed by the NACA 2412 domain)");
  EXPECT_ERROR_HAS(writeMcf(info("2412", "3D") + "<PARAMETERS>" + box + "</PARAMETERS>"),
                   "names a NACA aerofoil, which needs MeshType 2D or 2DBndLayer");
  EXPECT_ERROR_HAS(writeMcf(info("24120", "2D")),
                   "INFORMATION CADFile '24120' has no extension, so it is read as a NACA code");
  EXPECT_ERROR_HAS(writeMcf(info("0012", "2D") + "<PARAMETERS>" + box +
                            "<P PARAM=\"AOA\" VALUE=\"0\"/><P PARAM=\"Xmax\" VALUE=\"-3\"/>"
                            "</PARAMETERS>"),
                   "PARAMETERS Xmax is given twice");
  const McfCase naca = readMcfFile(writeMcf(info("2412", "2D") + "<PARAMETERS>" + box +
                                            R"(<P PARAM="AOA" VALUE="-5"/>)" + "</PARAMETERS>"));
  EXPECT_EQ(*naca.nacaDigits, "2412");
  EXPECT_DOUBLE_EQ(*naca.aoa, -5.0);
}

TEST(McfReader, RejectsMissingAndMalformedFiles) {
  const fs::path dir = test::tempDir();
  EXPECT_THROW(readMcfFile((dir / "none.mcf").string()), IoError);
  EXPECT_THROW(readMcfFile(dir.string()), IoError);
  std::ofstream(dir / "broken.mcf") << "<NEKTAR><MESHING></NEKTAR>";
  EXPECT_THROW(readMcfFile((dir / "broken.mcf").string()), IoError);
  std::ofstream(dir / "other.mcf") << "<GEOMETRY/>";
  EXPECT_ERROR_HAS((dir / "other.mcf").string(),
                   "other.mcf: the root element is <GEOMETRY>, not <NEKTAR>");
  std::ofstream(dir / "empty.mcf") << "<NEKTAR/>";
  EXPECT_ERROR_HAS((dir / "empty.mcf").string(), "empty.mcf: no <MESHING> in <NEKTAR>");
}

}  // namespace
}  // namespace homesh
