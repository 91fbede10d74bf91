#include "cad/cad_model.hpp"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRepLProp_SLProps.hxx>
#include <BRepTools.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Eigen/Geometry>
#include <Geom2d_Curve.hxx>
#include <GeomLib_IsPlanarSurface.hxx>
#include <Geom_Surface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <ShapeAnalysis_Curve.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <mutex>
#include <sstream>
#include <vector>

#include "cad/occt_access.hpp"
#include "core/error.hpp"
#include "core/input_file.hpp"

namespace homesh {

struct CadModel::Impl {
  TopoDS_Shape shape;
  std::string source;
  TopTools_IndexedMapOfShape vertices, edges, faces, solids;
  double diagonal = 1.0;
  // Lazily built evaluators, one per sub-shape (index 0 unused).
  mutable std::vector<std::unique_ptr<BRepAdaptor_Curve>> curves;
  mutable std::vector<std::unique_ptr<BRepAdaptor_Surface>> surfaces;
  mutable std::vector<Handle(ShapeAnalysis_Surface)> analysers;
  mutable std::vector<std::unique_ptr<BRepTopAdaptor_FClass2d>> classifiers;
  // Per face: its surface's periods, native or from a closed seam (below), built once.
  struct Periods {
    bool built = false;
    std::array<double, 2> period{};  // 0: not periodic in that direction
    std::array<double, 2> first{};   // start of the range a closed direction wraps into
    std::array<bool, 2> wraps{};     // closed, not periodic: evaluation must wrap
  };
  mutable std::vector<Periods> periods;

  void index() {
    TopExp::MapShapes(shape, TopAbs_VERTEX, vertices);
    TopExp::MapShapes(shape, TopAbs_EDGE, edges);
    TopExp::MapShapes(shape, TopAbs_FACE, faces);
    TopExp::MapShapes(shape, TopAbs_SOLID, solids);
    curves.resize(edges.Extent() + 1);
    surfaces.resize(faces.Extent() + 1);
    analysers.resize(faces.Extent() + 1);
    classifiers.resize(faces.Extent() + 1);
    periods.resize(faces.Extent() + 1);
    Bnd_Box box;  // the geometric box, not enlarged by the shape's tolerances
    BRepBndLib::AddOptimal(shape, box, false, false);
    if (!box.IsVoid()) {
      double x0, y0, z0, x1, y1, z1;
      box.Get(x0, y0, z0, x1, y1, z1);
      diagonal = std::sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0) + (z1 - z0) * (z1 - z0));
      if (!(diagonal > 0.0)) diagonal = 1.0;
    }
  }

  void checkIndex(int dim, int i, int count) const {
    if (i < 1 || i > count)
      throw CadError(cadEntityName(dim, i) + " does not exist in " + source + " (it has " +
                     std::to_string(count) + ")");
  }

  const BRepAdaptor_Curve& curve(int e) const {
    checkIndex(1, e, edges.Extent());
    if (BRep_Tool::Degenerated(TopoDS::Edge(edges(e))))
      throw CadError(cadEntityName(1, e) + " is degenerated (a point) and has no curve");
    auto& slot = curves[e];
    if (!slot)
      slot = withOcctErrors(cadEntityName(1, e), [&] {
        return std::make_unique<BRepAdaptor_Curve>(TopoDS::Edge(edges(e)));
      });
    return *slot;
  }

  const BRepAdaptor_Surface& surface(int f) const {
    checkIndex(2, f, faces.Extent());
    auto& slot = surfaces[f];
    if (!slot)
      slot = withOcctErrors(cadEntityName(2, f), [&] {
        return std::make_unique<BRepAdaptor_Surface>(TopoDS::Face(faces(f)));
      });
    return *slot;
  }

  // Point-in-face classification of (u, v) against the face's trimming loops, built once.
  BRepTopAdaptor_FClass2d& classifier(int f) const {
    checkIndex(2, f, faces.Extent());
    auto& slot = classifiers[f];
    if (!slot)
      slot = withOcctErrors(cadEntityName(2, f), [&] {
        const TopoDS_Face face = TopoDS::Face(faces(f));
        return std::make_unique<BRepTopAdaptor_FClass2d>(face, BRep_Tool::Tolerance(face));
      });
    return *slot;
  }

  // A surface that is closed in a direction without being periodic there (a B-spline revolved
  // through 360 degrees, its first and last rows of poles the same) has a seam like a periodic
  // one, but OCCT evaluates it beyond its range by extrapolation, not by coming round: a node
  // placed across the seam in an unwrapped chart would land far off the surface. Such a
  // direction gets its range as a period, and evaluation wraps into the range.
  const Periods& facePeriods(int f) const {
    const BRepAdaptor_Surface& s = surface(f);
    Periods& out = periods[f];
    if (out.built) return out;
    withOcctErrors(cadEntityName(2, f), [&] {
      const TopoDS_Face face = TopoDS::Face(faces(f));
      const Handle(Geom_Surface) geometry = BRep_Tool::Surface(face);
      double range[2][2];
      geometry->Bounds(range[0][0], range[0][1], range[1][0], range[1][1]);
      const double tol = 10.0 * std::max(BRep_Tool::Tolerance(face), 1e-7 * diagonal);
      for (int d = 0; d < 2; ++d) {
        if (d == 0 ? s.IsUPeriodic() : s.IsVPeriodic()) {
          out.period[d] = d == 0 ? s.UPeriod() : s.VPeriod();
          continue;
        }
        const double a = range[d][0], b = range[d][1];
        const double oa = range[1 - d][0], ob = range[1 - d][1];
        if (!std::isfinite(a) || !std::isfinite(b) || !(b > a) || !std::isfinite(oa) ||
            !std::isfinite(ob))
          continue;
        bool closed = true;
        for (int k = 0; k <= 8 && closed; ++k) {
          const double o = oa + (ob - oa) * k / 8.0;
          const gp_Pnt pa = d == 0 ? geometry->Value(a, o) : geometry->Value(o, a);
          const gp_Pnt pb = d == 0 ? geometry->Value(b, o) : geometry->Value(o, b);
          closed = pa.Distance(pb) <= tol;
        }
        if (!closed) continue;
        out.period[d] = b - a;
        out.first[d] = a;
        out.wraps[d] = true;
      }
    });
    out.built = true;
    return out;
  }

  // (u, v) wrapped into a closed, non-periodic surface's range where it has one.
  std::array<double, 2> wrapClosed(int f, double u, double v) const {
    const Periods& p = facePeriods(f);
    std::array<double, 2> uv{u, v};
    for (int d = 0; d < 2; ++d)
      if (p.wraps[d] && std::isfinite(uv[d])) {
        const double t = std::fmod(uv[d] - p.first[d], p.period[d]);
        uv[d] = p.first[d] + (t < 0.0 ? t + p.period[d] : t);
      }
    return uv;
  }

  ShapeAnalysis_Surface& analyser(int f) const {
    checkIndex(2, f, faces.Extent());
    auto& slot = analysers[f];
    if (slot.IsNull())
      slot = withOcctErrors(cadEntityName(2, f), [&] {
        return Handle(ShapeAnalysis_Surface)(
            new ShapeAnalysis_Surface(BRep_Tool::Surface(TopoDS::Face(faces(f)))));
      });
    return *slot;
  }
};

namespace {

Eigen::Vector3d toEigen(const gp_Pnt& p) {
  return {p.X(), p.Y(), p.Z()};
}
Eigen::Vector3d toEigen(const gp_Vec& v) {
  return {v.X(), v.Y(), v.Z()};
}
Eigen::Vector3d toEigen(const gp_Dir& d) {
  return {d.X(), d.Y(), d.Z()};
}
gp_Pnt toGp(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}

// OCCT's STEP and IGES readers share process-wide state (the XSControl session, static
// parameters): two threads reading at once corrupt each other. Reads are serialised.
std::mutex& dataExchangeMutex() {
  static std::mutex mutex;
  return mutex;
}

TopoDS_Shape readStep(const std::string& path) {
  const std::lock_guard<std::mutex> lock(dataExchangeMutex());
  STEPControl_Reader reader;
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone)
    throw IoError("'" + path + "' is not a readable STEP file");
  if (reader.TransferRoots() == 0) throw CadError("'" + path + "' contains no transferable shape");
  return reader.OneShape();
}

TopoDS_Shape readIges(const std::string& path) {
  const std::lock_guard<std::mutex> lock(dataExchangeMutex());
  IGESControl_Reader reader;
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone)
    throw IoError("'" + path + "' is not a readable IGES file");
  if (reader.TransferRoots() == 0) throw CadError("'" + path + "' contains no transferable shape");
  return reader.OneShape();
}

TopoDS_Shape readBrep(const std::string& path) {
  TopoDS_Shape shape;
  BRep_Builder builder;
  if (!BRepTools::Read(shape, path.c_str(), builder))
    throw IoError("'" + path + "' is not a readable BREP file");
  return shape;
}

}  // namespace

CadModel::CadModel(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {
  if (impl_->shape.IsNull()) throw CadError(impl_->source + " contains no shape");
  withOcctErrors(impl_->source, [&] { impl_->index(); });
  if (impl_->faces.Extent() == 0)
    throw CadError(impl_->source + " contains no face or solid (nothing to mesh)");
}

CadModel::CadModel(CadModel&&) noexcept = default;
CadModel& CadModel::operator=(CadModel&&) noexcept = default;
CadModel::~CadModel() = default;

CadModel CadModel::fromFile(const std::string& path) {
  namespace fs = std::filesystem;
  requireRegularFile(path, "input file");
  const std::string ext = lowerExtension(path);
  auto impl = std::make_unique<Impl>();
  impl->source = "'" + fs::path(path).filename().string() + "'";
  impl->shape = withOcctErrors("reading '" + path + "'", [&] {
    if (ext == ".step" || ext == ".stp") return readStep(path);
    if (ext == ".iges" || ext == ".igs") return readIges(path);
    if (ext == ".brep" || ext == ".brp") return readBrep(path);
    throw IoError("unsupported CAD format '" + ext + "' of '" + path +
                  "' (use .step, .stp, .iges, .igs, .brep or .brp)");
  });
  return CadModel(std::move(impl));
}

CadModel CadModel::fromBrepText(const std::string& text, const std::string& name) {
  auto impl = std::make_unique<Impl>();
  impl->source = name;
  impl->shape = withOcctErrors("reading BRep text", [&] {
    TopoDS_Shape shape;
    BRep_Builder builder;
    std::istringstream stream(text);
    BRepTools::Read(shape, stream, builder);
    return shape;
  });
  if (impl->shape.IsNull()) throw CadError(name + " is not a valid BRep shape");
  return CadModel(std::move(impl));
}

CadModel cadModelFromShape(const TopoDS_Shape& shape, const std::string& source) {
  auto impl = std::make_unique<CadModel::Impl>();
  impl->shape = shape;
  impl->source = source;
  return CadModel(std::move(impl));
}

CadModel CadModel::clone() const {
  auto impl = std::make_unique<Impl>();
  impl->shape = impl_->shape;
  impl->source = impl_->source;
  return CadModel(std::move(impl));
}

CadModel CadModel::scaled(double factor) const {
  if (!(factor > 0.0) || !std::isfinite(factor))
    throw ParameterError("CAD scale factor must be a positive number");
  auto impl = std::make_unique<Impl>();
  impl->source = impl_->source;
  impl->shape = withOcctErrors("scaling " + impl_->source, [&] {
    gp_Trsf scale;
    scale.SetScale(gp_Pnt(0.0, 0.0, 0.0), factor);
    BRepBuilderAPI_Transform transform(impl_->shape, scale, true);
    return transform.Shape();
  });
  return CadModel(std::move(impl));
}

int CadModel::numVertices() const {
  return impl_->vertices.Extent();
}
int CadModel::numEdges() const {
  return impl_->edges.Extent();
}
int CadModel::numFaces() const {
  return impl_->faces.Extent();
}
int CadModel::numSolids() const {
  return impl_->solids.Extent();
}
const std::string& CadModel::sourceName() const {
  return impl_->source;
}
double CadModel::boundingDiagonal() const {
  return impl_->diagonal;
}

std::vector<int> CadModel::subShapeIndices(int dim, int index, int subDim) const {
  static const TopAbs_ShapeEnum types[] = {TopAbs_VERTEX, TopAbs_EDGE, TopAbs_FACE, TopAbs_SOLID};
  const TopTools_IndexedMapOfShape* maps[] = {&impl_->vertices, &impl_->edges, &impl_->faces,
                                              &impl_->solids};
  if (dim < 1 || dim > 3 || subDim < 0 || subDim >= dim)
    throw Error("subShapeIndices: bad dimensions " + std::to_string(dim) + ", " +
                std::to_string(subDim));
  impl_->checkIndex(dim, index, maps[dim]->Extent());
  std::vector<int> result;
  for (TopExp_Explorer ex((*maps[dim])(index), types[subDim]); ex.More(); ex.Next())
    result.push_back(maps[subDim]->FindIndex(ex.Current()));
  std::sort(result.begin(), result.end());
  result.erase(std::unique(result.begin(), result.end()), result.end());
  return result;
}

Eigen::Vector3d CadModel::vertexPoint(int vertex) const {
  return toEigen(BRep_Tool::Pnt(occtVertex(*this, vertex)));
}

bool CadModel::isDegenerated(int edge) const {
  return BRep_Tool::Degenerated(occtEdge(*this, edge));
}

ParameterRange CadModel::edgeRange(int edge) const {
  const auto& c = impl_->curve(edge);
  return {c.FirstParameter(), c.LastParameter()};
}

CurveDerivatives CadModel::evaluateCurve(int edge, double t) const {
  const auto& c = impl_->curve(edge);
  return withOcctErrors(cadEntityName(1, edge), [&] {
    gp_Pnt p;
    gp_Vec d1, d2;
    c.D2(t, p, d1, d2);
    return CurveDerivatives{toEigen(p), toEigen(d1), toEigen(d2)};
  });
}

double CadModel::vertexParameter(int vertex, int edge, std::optional<double> near) const {
  const TopoDS_Vertex v = occtVertex(*this, vertex);
  const TopoDS_Edge e = occtEdge(*this, edge);
  return withOcctErrors(cadEntityName(1, edge), [&] {
    TopoDS_Vertex first, last;
    TopExp::Vertices(e, first, last);
    double t0 = 0.0, t1 = 0.0;
    BRep_Tool::Range(e, t0, t1);
    const bool atFirst = first.IsSame(v), atLast = last.IsSame(v);
    if (!atFirst && !atLast)
      throw CadError(cadEntityName(0, vertex) + " does not bound " + cadEntityName(1, edge));
    if (atFirst && atLast) {
      if (near && std::abs(*near - t1) < std::abs(*near - t0)) return t1;
      return t0;
    }
    return atFirst ? t0 : t1;
  });
}

CurveProjection CadModel::projectOnCurve(int edge, const Eigen::Vector3d& p,
                                         std::optional<double> guess) const {
  const auto& c = impl_->curve(edge);
  return withOcctErrors("projecting onto " + cadEntityName(1, edge), [&] {
    gp_Pnt proj;
    double t = 0.0;
    const double precision = 1e-9 * impl_->diagonal;
    const ShapeAnalysis_Curve analysis;
    double d = analysis.Project(c, toGp(p), precision, proj, t);
    const double first = c.FirstParameter(), last = c.LastParameter();
    const double slack = 1e-9 * std::max(1.0, last - first);
    if (c.IsPeriodic()) {  // the same point in the edge's own period
      const double period = c.Period();
      t = first + std::fmod(std::fmod(t - first, period) + period, period);
      if (t > last + slack && t - period >= first - slack) t -= period;
    }
    if (t < first - slack || t > last + slack) {
      // OCCT projected onto the curve beyond the edge (a seam's circle on its other half): the
      // nearest point of the edge is then an end or a local minimum found from its middle.
      d = std::numeric_limits<double>::infinity();
      const auto keep = [&](double s, const gp_Pnt& q) {
        const double ds = q.Distance(toGp(p));
        if (s >= first - slack && s <= last + slack && ds < d) d = ds, t = s, proj = q;
      };
      keep(first, c.Value(first));
      keep(last, c.Value(last));
      gp_Pnt q;
      double s = 0.5 * (first + last);
      analysis.NextProject(s, c, toGp(p), precision, q, s);
      keep(s, q);
    }
    CurveProjection best{t, toEigen(proj), d};
    // The local search from the guess settles ties (a point as near to both ends of a closed
    // curve) on the guess's side. Alone it is not enough: it stops at once where the curve's
    // speed vanishes (a cosine-spaced aerofoil's trailing edge) and can end at the opposite
    // point of a closed curve, so the global result stands unless the local one is as near.
    if (guess) {
      const double dLocal = analysis.NextProject(*guess, c, toGp(p), precision, proj, t);
      if (dLocal <= d + precision && t >= first - slack && t <= last + slack)
        best = CurveProjection{t, toEigen(proj), dLocal};
    }
    return best;
  });
}

SurfaceBounds CadModel::faceBounds(int face) const {
  const TopoDS_Face f = occtFace(*this, face);
  SurfaceBounds b;
  withOcctErrors(cadEntityName(2, face),
                 [&] { BRepTools::UVBounds(f, b.uMin, b.uMax, b.vMin, b.vMax); });
  return b;
}

SurfaceDerivatives CadModel::evaluateSurface(int face, double u, double v) const {
  const auto& s = impl_->surface(face);
  const std::array<double, 2> uv = impl_->wrapClosed(face, u, v);
  return withOcctErrors(cadEntityName(2, face), [&] {
    gp_Pnt p;
    gp_Vec du, dv, duu, dvv, duv;
    s.D2(uv[0], uv[1], p, du, dv, duu, dvv, duv);
    return SurfaceDerivatives{toEigen(p),   toEigen(du),  toEigen(dv),
                              toEigen(duu), toEigen(duv), toEigen(dvv)};
  });
}

SurfaceProjection CadModel::projectOnSurface(int face, const Eigen::Vector3d& p,
                                             std::optional<std::array<double, 2>> guess) const {
  ShapeAnalysis_Surface& analyser = impl_->analyser(face);
  const auto& surface = impl_->surface(face);
  return withOcctErrors("projecting onto " + cadEntityName(2, face), [&] {
    const double precision = 1e-9 * impl_->diagonal;
    const gp_Pnt target = toGp(p);
    const auto result = [&](const gp_Pnt2d& uv) {
      const gp_Pnt q = analyser.Value(uv);
      return SurfaceProjection{uv.X(), uv.Y(), toEigen(q), q.Distance(target)};
    };
    std::optional<SurfaceProjection> local;
    if (guess) {
      const std::array<double, 2> g = impl_->wrapClosed(face, (*guess)[0], (*guess)[1]);
      const gp_Pnt2d start(g[0], g[1]);
      local = result(analyser.NextValueOfUV(start, target, precision));
      // Kept when it lies on the surface, or is a foot point (the residual normal to a regular
      // surface there) no farther than its start; a local search can stop where the
      // parametrisation degenerates or end farther than it began.
      if (local->distance <= 1e3 * precision) return *local;
      gp_Pnt q;
      gp_Vec du, dv;
      surface.D1(local->u, local->v, q, du, dv);
      const gp_Vec r(q, target);
      const double rn = r.Magnitude();
      const bool regular =
          du.Crossed(dv).Magnitude() > 1e-8 * std::max(du.SquareMagnitude(), dv.SquareMagnitude());
      const bool foot = regular && std::abs(r.Dot(du)) <= 1e-3 * rn * du.Magnitude() &&
                        std::abs(r.Dot(dv)) <= 1e-3 * rn * dv.Magnitude();
      if (foot && local->distance <= analyser.Value(start).Distance(target) + precision)
        return *local;
    }
    const SurfaceProjection global = result(analyser.ValueOfUV(target, precision));
    return local && local->distance <= global.distance ? *local : global;
  });
}

PrincipalCurvatures CadModel::curvature(int face, double u, double v) const {
  const auto& s = impl_->surface(face);
  const bool reversed = occtFace(*this, face).Orientation() == TopAbs_REVERSED;
  const std::array<double, 2> uv = impl_->wrapClosed(face, u, v);
  return withOcctErrors("curvature of " + cadEntityName(2, face), [&] {
    BRepLProp_SLProps props(s, uv[0], uv[1], 2, 1e-9 * impl_->diagonal);
    PrincipalCurvatures k;
    if (!props.IsCurvatureDefined()) return k;
    k.defined = true;
    k.kMin = props.MinCurvature();
    k.kMax = props.MaxCurvature();
    gp_Dir dMax, dMin;
    props.CurvatureDirections(dMax, dMin);
    k.dirMin = toEigen(dMin);
    k.dirMax = toEigen(dMax);
    if (reversed) {  // OCCT measures against du x dv; the face's outward normal is opposite
      std::swap(k.kMin, k.kMax);
      std::swap(k.dirMin, k.dirMax);
      k.kMin = -k.kMin;
      k.kMax = -k.kMax;
    }
    return k;
  });
}

bool CadModel::isPlanar(int face) const {
  const TopoDS_Face f = occtFace(*this, face);
  return withOcctErrors(cadEntityName(2, face), [&] {
    return static_cast<bool>(
        GeomLib_IsPlanarSurface(BRep_Tool::Surface(f), 1e-9 * impl_->diagonal).IsPlanar());
  });
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> CadModel::plane(int face) const {
  if (!isPlanar(face)) throw CadError(cadEntityName(2, face) + " is not planar");
  const SurfaceBounds b = faceBounds(face);
  const SurfaceDerivatives d =
      evaluateSurface(face, 0.5 * (b.uMin + b.uMax), 0.5 * (b.vMin + b.vMax));
  Eigen::Vector3d normal = d.du.cross(d.dv);
  if (!(normal.norm() > 0.0))
    throw CadError(cadEntityName(2, face) + " has a singular parametrisation at its centre");
  normal.normalize();
  // The face's normal is du x dv unless the face uses its surface reversed.
  if (occtFace(*this, face).Orientation() == TopAbs_REVERSED) normal = -normal;
  return std::make_pair(d.point, normal);
}

std::array<double, 2> CadModel::edgeParameterOnFace(int edge, int face, double t) const {
  const TopoDS_Edge e = occtEdge(*this, edge);
  const TopoDS_Face f = occtFace(*this, face);
  return withOcctErrors(cadEntityName(1, edge) + " on " + cadEntityName(2, face), [&] {
    double first = 0.0, last = 0.0;
    const Handle(Geom2d_Curve) pcurve = BRep_Tool::CurveOnSurface(e, f, first, last);
    if (pcurve.IsNull())
      throw CadError(cadEntityName(1, edge) + " does not lie on " + cadEntityName(2, face));
    const gp_Pnt2d uv = pcurve->Value(t);
    return std::array<double, 2>{uv.X(), uv.Y()};
  });
}

std::array<double, 2> CadModel::facePeriods(int face) const {
  return impl_->facePeriods(face).period;
}

double CadModel::wrapIntoPeriod(int face, double x, int axis) const {
  const double period = facePeriods(face)[axis];
  if (period <= 0.0) return x;
  const SurfaceBounds b = faceBounds(face);
  const double lo = axis == 0 ? b.uMin : b.vMin;
  return lo + std::fmod(std::fmod(x - lo, period) + period, period);
}

bool CadModel::faceContains(int face, double u, double v) const {
  BRepTopAdaptor_FClass2d& classifier = impl_->classifier(face);
  return withOcctErrors(cadEntityName(2, face), [&] {
    const TopAbs_State state = classifier.Perform(gp_Pnt2d(u, v));
    return state == TopAbs_IN || state == TopAbs_ON;
  });
}

double CadModel::tolerance(int dim, int index) const {
  switch (dim) {
    case 0:
      return BRep_Tool::Tolerance(occtVertex(*this, index));
    case 1:
      return BRep_Tool::Tolerance(occtEdge(*this, index));
    case 2:
      return BRep_Tool::Tolerance(occtFace(*this, index));
    default:
      throw Error("tolerance: dimension " + std::to_string(dim) + " has no CAD tolerance");
  }
}

std::string cadEntityName(int dim, int index) {
  static const char* names[] = {"Vertex", "Edge", "Face", "Solid"};
  if (dim < 0 || dim > 3) return "Entity" + std::to_string(index);
  return names[dim] + std::to_string(index);
}

const TopoDS_Shape& occtShape(const CadModel& cad) {
  return cad.impl().shape;
}

TopoDS_Vertex occtVertex(const CadModel& cad, int index) {
  cad.impl().checkIndex(0, index, cad.numVertices());
  return TopoDS::Vertex(cad.impl().vertices(index));
}
TopoDS_Edge occtEdge(const CadModel& cad, int index) {
  cad.impl().checkIndex(1, index, cad.numEdges());
  return TopoDS::Edge(cad.impl().edges(index));
}
TopoDS_Face occtFace(const CadModel& cad, int index) {
  cad.impl().checkIndex(2, index, cad.numFaces());
  return TopoDS::Face(cad.impl().faces(index));
}
TopoDS_Solid occtSolid(const CadModel& cad, int index) {
  cad.impl().checkIndex(3, index, cad.numSolids());
  return TopoDS::Solid(cad.impl().solids(index));
}

}  // namespace homesh
