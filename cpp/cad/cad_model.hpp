// The CAD model: one OpenCASCADE shape, its numbered sub-shapes and geometric queries.
//
// Numbering follows FreeCAD: FaceN is the N-th entry (1-based) of TopExp::MapShapes(shape, FACE),
// and likewise for vertices, edges and solids. All queries take these 1-based indices.
// Every OCCT failure is converted to CadError naming the entity ("Face3", "Edge7").
//
// Thread safety: loading and const queries may not run concurrently on one CadModel, because
// OCCT's adaptors cache B-spline evaluation state; give each thread its own copy via clone().
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

class TopoDS_Shape;

namespace homesh {

struct CurveDerivatives {
  Eigen::Vector3d point, d1, d2;
};

struct SurfaceDerivatives {
  Eigen::Vector3d point, du, dv, duu, duv, dvv;

  // The normal direction S_u x S_v (not normalised), or none where it is undefined: S_u and
  // S_v parallel or one vanishing (a sphere's pole), where the cross product is rounding noise
  // of relative size ~1e-16, far below the bound 1e-8 max(|S_u|^2, |S_v|^2).
  std::optional<Eigen::Vector3d> normalDirection() const {
    const Eigen::Vector3d m = du.cross(dv);
    const double scale = std::max(du.squaredNorm(), dv.squaredNorm());
    if (!(m.norm() > 1e-8 * scale)) return std::nullopt;
    return m;
  }
  // Per parameter direction (u, v): whether r does not move along it here (a pole, a cone's
  // apex). Such a derivative vanishes up to the rounding of the surface's own formulas
  // (cos(pi/2) ~ 1e-16 times the radius); 1e-7 of the other leaves ample room without mistaking
  // a merely stretched chart.
  std::array<bool, 2> degenerate() const {
    const double nu = du.norm(), nv = dv.norm(), scale = std::max(nu, nv);
    return {nu <= 1e-7 * scale, nv <= 1e-7 * scale};
  }
};

struct CurveProjection {
  double t = 0.0;
  Eigen::Vector3d point;
  double distance = 0.0;
};

struct SurfaceProjection {
  double u = 0.0, v = 0.0;
  Eigen::Vector3d point;
  double distance = 0.0;
};

struct PrincipalCurvatures {
  bool defined = false;  // false at umbilic-free singular points (e.g. a cone apex)
  // Signed against the face's normal (outward for a solid's face): negative where the surface
  // bends away from the normal (a sphere), positive where it bends towards it (a hole's wall).
  double kMin = 0.0, kMax = 0.0;  // kMin <= kMax
  Eigen::Vector3d dirMin, dirMax;
};

struct ParameterRange {
  double first = 0.0, last = 0.0;
};

struct SurfaceBounds {
  double uMin = 0.0, uMax = 0.0, vMin = 0.0, vMax = 0.0;
};

class CadModel {
 public:
  // Loads .step/.stp, .iges/.igs or .brep/.brp (case-insensitive extension).
  // Throws IoError (missing or unreadable file) or CadError (no usable shape).
  static CadModel fromFile(const std::string& path);

  // Loads a shape written by BRepTools::Write (FreeCAD's Shape.exportBrepToString()); `name`
  // is how messages refer to it (a FreeCAD object's label, say).
  static CadModel fromBrepText(const std::string& text, const std::string& name = "the shape");

  CadModel(CadModel&& other) noexcept;
  CadModel& operator=(CadModel&& other) noexcept;
  ~CadModel();

  // The model scaled by `factor` about the origin (a unit change: 0.001 turns millimetres into
  // metres). Numbering and names are kept. Throws ParameterError for a factor that is not > 0.
  CadModel scaled(double factor) const;

  // A copy sharing the (immutable) shape with fresh evaluation caches, for another thread.
  CadModel clone() const;

  // Sub-shape counts; degenerated edges (sphere poles) are counted as edges.
  int numVertices() const;
  int numEdges() const;
  int numFaces() const;
  int numSolids() const;

  // Sorted 1-based indices of the sub-shapes of dimension subDim < dim of entity (dim, index):
  // the vertices of an edge, the edges of a face, the faces of a solid, ...
  std::vector<int> subShapeIndices(int dim, int index, int subDim) const;

  // Where the shape came from ("part.step", "BRep text") for messages.
  const std::string& sourceName() const;

  // Axis-aligned bounding box diagonal length (a length scale for tolerances).
  double boundingDiagonal() const;

  Eigen::Vector3d vertexPoint(int vertex) const;

  bool isDegenerated(int edge) const;
  ParameterRange edgeRange(int edge) const;
  CurveDerivatives evaluateCurve(int edge, double t) const;
  // Parameter of a vertex on an edge it bounds. For a closed edge both ends qualify; the one
  // nearer `near` is returned when given, else the first.
  double vertexParameter(int vertex, int edge, std::optional<double> near = std::nullopt) const;
  // Closest point on the edge's curve within its parameter range, found to 1e-9 of the
  // bounding diagonal (the precision handed to OCCT's search); `guess` (a nearby parameter)
  // starts a local search there, whose result is kept when it is as near as the global one
  // (it decides between equally near points, e.g. either side of a closed curve's seam).
  CurveProjection projectOnCurve(int edge, const Eigen::Vector3d& p,
                                 std::optional<double> guess = std::nullopt) const;

  SurfaceBounds faceBounds(int face) const;
  SurfaceDerivatives evaluateSurface(int face, double u, double v) const;
  // Closest point on the face's underlying surface, found to 1e-9 of the bounding diagonal;
  // `guess` speeds up and disambiguates (its local search is kept when it ends on the surface or
  // at a regular foot point no farther than the guess, otherwise the nearer of it and the global
  // search). The point returned is S(u, v) itself.
  SurfaceProjection projectOnSurface(int face, const Eigen::Vector3d& p,
                                     std::optional<std::array<double, 2>> guess = {}) const;
  PrincipalCurvatures curvature(int face, double u, double v) const;
  // Plane of a planar face: a point and the unit normal oriented like the face.
  bool isPlanar(int face) const;
  std::pair<Eigen::Vector3d, Eigen::Vector3d> plane(int face) const;
  // Parameters (u,v) of the point of an edge at parameter t on a face containing the edge
  // (via the edge's p-curve on that face).
  std::array<double, 2> edgeParameterOnFace(int edge, int face, double t) const;
  // Periods of the face's surface in u and v; 0 where that direction is not periodic (a
  // sphere or cylinder is periodic in u, a torus in both). A direction in which the surface is
  // closed without being periodic (a B-spline revolved through 360 degrees) has its parameter
  // range as its period, and evaluateSurface, curvature and projectOnSurface's guess wrap into
  // that range, so such a seam behaves as a periodic one.
  std::array<double, 2> facePeriods(int face) const;
  // A parameter of the face (axis 0: u, 1: v) moved by whole periods into [min, min + period)
  // of its bounds where that direction is periodic (facePeriods), else as it is: what
  // faceContains expects.
  double wrapIntoPeriod(int face, double x, int axis) const;
  // Whether (u, v) lies on the face: inside its trimming loops or on them within the face's
  // tolerance (classified in the face's own parameter range; wrap periodic values first).
  bool faceContains(int face, double u, double v) const;
  // The CAD tolerance of a sub-shape (BRep_Tool::Tolerance): how far its points may lie from
  // the exact geometry of its neighbours. dim 0, 1 or 2.
  double tolerance(int dim, int index) const;

  // Implementation detail shared with the components that hand the shape to OCCT-based tools
  // (see cad/occt_access.hpp).
  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  friend CadModel cadModelFromShape(const TopoDS_Shape& shape, const std::string& source);
  explicit CadModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// "Face3", "Edge12", ...: the FreeCAD name of sub-shape `index` of dimension `dim` (0..3).
std::string cadEntityName(int dim, int index);

}  // namespace homesh
