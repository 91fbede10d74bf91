// Shared helpers of the C++ tests: analytic CAD shapes, temporary files, mesh measures.
#pragma once

#include <BOPAlgo_Builder.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Eigen/Geometry>
#include <GC_MakeArcOfCircle.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Precision.hxx>
#include <STEPControl_Writer.hxx>
#include <ShapeFix_Solid.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Shell.hxx>
#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "core/mesh.hpp"

namespace homesh::test {

// A fresh temporary folder per call, removed by the OS's tmp cleaning (tests stay hermetic).
inline std::filesystem::path tempDir() {
  static std::mt19937_64 rng(std::random_device{}());
  auto dir = std::filesystem::temp_directory_path() / ("homesh-test-" + std::to_string(rng()));
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string brepText(const TopoDS_Shape& shape) {
  std::ostringstream out;
  BRepTools::Write(shape, out);
  return out.str();
}

inline CadModel toModel(const TopoDS_Shape& shape) {
  return CadModel::fromBrepText(brepText(shape));
}

// The 1-based index of the model's vertex at p (to 1e-9), or 0 where there is none.
inline int vertexAt(const CadModel& cad, const Eigen::Vector3d& p) {
  for (int v = 1; v <= cad.numVertices(); ++v)
    if ((cad.vertexPoint(v) - p).norm() < 1e-9) return v;
  return 0;
}

inline TopoDS_Shape sphere(double r) {
  return BRepPrimAPI_MakeSphere(r).Shape();
}
inline TopoDS_Shape cylinder(double r, double h) {
  return BRepPrimAPI_MakeCylinder(r, h).Shape();
}
inline TopoDS_Shape torus(double major, double minor) {
  return BRepPrimAPI_MakeTorus(major, minor).Shape();
}
// A solid torus bounded by one rational B-spline face that is closed in both directions but
// not periodic (as revolved B-splines in STEP files often are), so its seams are found by
// CadModel's closure test, not by OCCT's periodicity flags.
inline TopoDS_Shape nurbsTorus(double major, double minor) {
  const TopoDS_Shape converted = BRepBuilderAPI_NurbsConvert(torus(major, minor)).Shape();
  TopExp_Explorer faces(converted, TopAbs_FACE);
  Handle(Geom_BSplineSurface) surface = Handle(Geom_BSplineSurface)::DownCast(
      BRep_Tool::Surface(TopoDS::Face(faces.Current()))->Copy());
  surface->SetUNotPeriodic();
  surface->SetVNotPeriodic();
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(surface, Precision::Confusion()).Face();
  TopoDS_Shell shell;
  BRep_Builder builder;
  builder.MakeShell(shell);
  builder.Add(shell, face);
  BRepBuilderAPI_MakeSolid solid(shell);
  ShapeFix_Solid fix(solid.Solid());
  fix.Perform();
  return fix.Solid();
}
// The prism of height 1 over the region bounded by the segment (0,0)-(2,0), the segment
// (2,0)-(1,h) and an arc from (1,h) back to the origin through `through`. With the defaults the
// arc is a quarter of the circle of radius 1 centred at (0,1): it leaves the origin along +x,
// like the segment, so the bottom and top faces have a cusp there (and the side faces meet
// tangentially along the vertical edge through it).
inline TopoDS_Shape cuspPrism(const gp_Pnt& through = gp_Pnt(std::sqrt(0.5), 1.0 - std::sqrt(0.5),
                                                             0),
                              double h = 1.0) {
  const gp_Pnt o(0, 0, 0), a(2, 0, 0), b(1, h, 0);
  const Handle(Geom_TrimmedCurve) arc = GC_MakeArcOfCircle(b, through, o).Value();
  BRepBuilderAPI_MakeWire wire(BRepBuilderAPI_MakeEdge(o, a).Edge(),
                               BRepBuilderAPI_MakeEdge(a, b).Edge(),
                               BRepBuilderAPI_MakeEdge(arc).Edge());
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(wire.Wire(), true).Face();
  return BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, 1)).Shape();
}

inline TopoDS_Shape box(double x, double y, double z) {
  return BRepPrimAPI_MakeBox(x, y, z).Shape();
}

// Two unit boxes side by side along x, sharing the face x = 1: a general fuse keeps both solids
// and the shared face once (11 faces).
inline TopoDS_Shape twoBoxes() {
  BOPAlgo_Builder builder;
  builder.AddArgument(box(1.0, 1.0, 1.0));
  gp_Trsf shift;
  shift.SetTranslation(gp_Vec(1.0, 0.0, 0.0));
  builder.AddArgument(BRepBuilderAPI_Transform(box(1.0, 1.0, 1.0), shift, true).Shape());
  builder.Perform();
  if (builder.HasErrors()) throw Error("two boxes: the general fuse failed");
  return builder.Shape();
}

// A 4 x 4 x 2 box with a vertical hole of radius 1 through its centre (7 faces).
inline TopoDS_Shape boxWithHole() {
  const TopoDS_Shape b = BRepPrimAPI_MakeBox(4.0, 4.0, 2.0).Shape();
  const TopoDS_Shape c =
      BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(2, 2, -1), gp_Dir(0, 0, 1)), 1.0, 4.0).Shape();
  return BRepAlgoAPI_Cut(b, c).Shape();
}

// A hemisphere of radius r cut out of the floor of the box [-4r, 12r] x [-4r, 4r] x [0, 3r]:
// the layout of NekMesh's 3d_sphere case (r = 0.25 m there), with OCCT's exact sphere.
inline TopoDS_Shape hemisphereInBox(double r) {
  const TopoDS_Shape floorBox =
      BRepPrimAPI_MakeBox(gp_Pnt(-4 * r, -4 * r, 0.0), gp_Pnt(12 * r, 4 * r, 3 * r)).Shape();
  return BRepAlgoAPI_Cut(floorBox, sphere(r)).Shape();
}

// `shape` as a STEP file at `path` (OCCT writes millimetres; a .mcf reads them in metres).
inline void writeStep(const TopoDS_Shape& shape, const std::filesystem::path& path) {
  STEPControl_Writer writer;
  writer.Transfer(shape, STEPControl_AsIs);
  if (writer.Write(path.string().c_str()) != IFSelect_RetDone)
    throw Error("cannot write " + path.string());
}

inline Eigen::Vector3d nodePoint(const Mesh& mesh, std::int64_t i) {
  return {mesh.xyz[3 * i], mesh.xyz[3 * i + 1], mesh.xyz[3 * i + 2]};
}

// Signed volume of a linear tetrahedron given by its first four nodes.
inline double tetVolume(const Mesh& mesh, const std::int64_t* t) {
  const Eigen::Vector3d a = test::nodePoint(mesh, t[0]);
  return (test::nodePoint(mesh, t[1]) - a)
             .cross(test::nodePoint(mesh, t[2]) - a)
             .dot(test::nodePoint(mesh, t[3]) - a) /
         6.0;
}

}  // namespace homesh::test
