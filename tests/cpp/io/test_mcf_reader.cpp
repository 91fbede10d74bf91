// NekMesh mesh configuration files (.mcf): the five peer cases, notices for keys HOMesh does not
// use, and malformed files.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "io/mcf_reader.hpp"
#include "test_support.hpp"

#ifndef HOMESH_SHARED_DIR
#error "HOMESH_SHARED_DIR must name the shared data folder"
#endif

namespace homesh {
namespace {

namespace fs = std::filesystem;

std::string peer(const std::string& name) {
  return std::string(HOMESH_SHARED_DIR) + "/peer-cases/nekmesh/meshgen/" + name;
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

TEST(McfReader, ReadsTheSphereCase) {
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
