#include "cad/cad_healing.hpp"

#include <BRepAdaptor_Curve.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepGProp.hxx>
#include <BRepTools_History.hxx>
#include <BRepTools_ReShape.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GCPnts_AbscissaPoint.hxx>
#include <GProp_GProps.hxx>
#include <ShapeAnalysis_CheckSmallFace.hxx>
#include <ShapeBuild_ReShape.hxx>
#include <ShapeFix_FixSmallFace.hxx>
#include <ShapeFix_Shape.hxx>
#include <ShapeFix_Solid.hxx>
#include <ShapeFix_Wireframe.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Shell.hxx>

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <set>
#include <vector>

#include "cad/coincident_faces.hpp"
#include "cad/model_dimension.hpp"
#include "cad/occt_access.hpp"
#include "core/error.hpp"
#include "core/format.hpp"

namespace homesh {
namespace {

// Relative to the bounding-box diagonal: the sewing and fixing tolerance (gaps a STEP exporter
// leaves between faces are of this order), edges shorter than kSmallEdge are merged away (a
// mesher would need elements that small there), and a fix may widen a tolerance to kMaxWiden.
constexpr double kTolerance = 1e-6, kSmallEdge = 1e-5, kMaxWiden = 1e-3;

int count(const TopoDS_Shape& shape, TopAbs_ShapeEnum type) {
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(shape, type, map);
  return map.Extent();
}

// The numbering's map carried through a healing step that made `after` of `before`, as
// `history` (the step's context) records it; what the step did, `action`, names what it
// removed. A sub-shape that a fix rebuilt without recording it is found by its place, to the
// length of the edges healing merges away.
void trace(HealingRecord& record, const TopoDS_Shape& before, const TopoDS_Shape& after,
           const Handle(BRepTools_History) & history, const std::string& action) {
  const BRepTools_History none;
  record.numbering = record.numbering.then(
      NumberingMap::fromHistory(before, after, history.IsNull() ? none : *history,
                                std::string(kHealingOperation) + " (" + action + ")",
                                kSmallEdge / kTolerance * record.tolerance));
}

// Whether healing gave a face or edge it kept another number (those it removed do not count:
// faces left out after the solids' leave their numbers as they were).
bool renumbered(const NumberingMap& numbering) {
  for (const int dim : {1, 2})
    for (const auto& [from, to] : numbering.changes(dim))
      if (!to.empty()) return true;
  return false;
}

Handle(BRepTools_History) historyOf(const Handle(BRepTools_ReShape) & context) {
  return context.IsNull() ? Handle(BRepTools_History)() : context->History();
}

bool bounding(TopAbs_Orientation o) {
  return o == TopAbs_FORWARD || o == TopAbs_REVERSED;
}

// Edge -> the faces of `shape` using it, repeats kept (a seam edge is used twice by its face);
// internal and external faces and edges (not on the boundary) left out.
TopTools_IndexedDataMapOfShapeListOfShape edgeUses(const TopoDS_Shape& shape) {
  TopTools_IndexedDataMapOfShapeListOfShape uses;
  for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next()) {
    if (!bounding(f.Current().Orientation())) continue;
    for (TopExp_Explorer e(f.Current(), TopAbs_EDGE); e.More(); e.Next()) {
      if (!bounding(e.Current().Orientation())) continue;
      if (!uses.Contains(e.Current())) uses.Add(e.Current(), TopTools_ListOfShape());
      uses.ChangeFromKey(e.Current()).Append(f.Current());
    }
  }
  return uses;
}

// The first free edge of `solid` (an edge used once by its bounding faces: not a seam, which a
// face uses twice, not degenerated, and not an internal or external edge imprinted on a face),
// as its index in `edges`; 0 when its boundary is closed.
// The free edges of `shape` (used once by its bounding faces: not a seam, which a face uses
// twice, not degenerated, and not an internal or external edge imprinted on a face).
std::vector<TopoDS_Edge> freeEdges(const TopoDS_Shape& shape) {
  const TopTools_IndexedDataMapOfShapeListOfShape uses = edgeUses(shape);
  std::vector<TopoDS_Edge> free;
  for (int i = 1; i <= uses.Extent(); ++i) {
    const TopoDS_Edge& edge = TopoDS::Edge(uses.FindKey(i));
    if (uses(i).Extent() == 1 && !BRep_Tool::Degenerated(edge)) free.push_back(edge);
  }
  return free;
}

// The first free edge of `solid` as its index in `edges`; 0 when its boundary is closed.
int firstFreeEdge(const TopoDS_Shape& solid, const TopTools_IndexedMapOfShape& edges) {
  const std::vector<TopoDS_Edge> free = freeEdges(solid);
  return free.empty() ? 0 : edges.FindIndex(free.front());
}

int freeEdgeCount(const TopoDS_Shape& shape) {
  return static_cast<int>(freeEdges(shape).size());
}

// The faces of a model kept for a surface mesh, sewn into shells where sewing joins faces that
// meet without sharing their edges (a conforming mesh across them) and loses none; else as
// they are.
TopoDS_Shape sewSurface(const TopoDS_Shape& shape, double tolerance, HealingRecord& record) {
  BRepBuilderAPI_Sewing sewing(tolerance);
  sewing.Add(shape);
  sewing.Perform();
  const TopoDS_Shape sewn = sewing.SewedShape();
  if (sewn.IsNull() || count(sewn, TopAbs_FACE) != count(shape, TopAbs_FACE)) return shape;
  const int before = freeEdgeCount(shape), after = freeEdgeCount(sewn);
  if (after >= before) return shape;
  record.actions.push_back("sewed the faces (tolerance " + formatNumber(tolerance) +
                           ") for the surface mesh: " + std::to_string(before) + " -> " +
                           std::to_string(after) + " edges bounding one face");
  trace(record, shape, sewn, historyOf(sewing.GetContext()), record.actions.back());
  return sewn;
}

double volumeOf(const TopoDS_Shape& solid) {
  GProp_GProps props;
  BRepGProp::VolumeProperties(solid, props);
  return std::abs(props.Mass());
}

// Whether a solid has no volume to mesh: its mean thickness (volume / boundary area) is below
// the healing tolerance. (Relative to the area, not to the bounding box: a needle is thin, not
// empty.)
bool hasNoVolume(const TopoDS_Shape& solid, double diagonal, double& volume) {
  GProp_GProps props;
  BRepGProp::SurfaceProperties(solid, props);
  volume = volumeOf(solid);
  return volume < std::abs(props.Mass()) * kTolerance * diagonal;
}

// The faces of `shape` that no solid of it bounds, as their indices in its face map (1-based,
// FaceN), and as a compound.
struct LooseFaces {
  std::vector<int> indices;
  TopoDS_Compound faces;
};

LooseFaces facesInNoSolid(const TopoDS_Shape& shape) {
  TopTools_IndexedMapOfShape all, bounding;
  TopExp::MapShapes(shape, TopAbs_FACE, all);
  for (TopExp_Explorer s(shape, TopAbs_SOLID); s.More(); s.Next())
    TopExp::MapShapes(s.Current(), TopAbs_FACE, bounding);
  LooseFaces loose;
  BRep_Builder builder;
  builder.MakeCompound(loose.faces);
  for (int i = 1; i <= all.Extent(); ++i) {
    if (bounding.Contains(all(i))) continue;
    loose.indices.push_back(i);
    builder.Add(loose.faces, all(i));
  }
  return loose;
}

// The solids of `shape` alone, in a compound (or the solid itself when there is one).
TopoDS_Shape solidsOf(const TopoDS_Shape& shape) {
  TopoDS_Compound solids;
  BRep_Builder builder;
  builder.MakeCompound(solids);
  int n = 0;
  for (TopExp_Explorer s(shape, TopAbs_SOLID); s.More(); s.Next(), ++n)
    builder.Add(solids, s.Current());
  return n == 1 ? TopExp_Explorer(shape, TopAbs_SOLID).Current() : TopoDS_Shape(solids);
}

// "Face3, Face7-Face9": FaceN names of sorted indices, runs joined, at most `max` items.
std::string faceNames(const std::vector<int>& indices, std::size_t max = 6) {
  std::string out;
  std::size_t items = 0;
  for (std::size_t i = 0; i < indices.size(); ++items) {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    if (items == max) return out + ", ...";
    out += (out.empty() ? "" : ", ") + cadEntityName(2, indices[i]) +
           (j > i ? "-" + cadEntityName(2, indices[j]) : std::string());
    i = j + 1;
  }
  return out;
}

std::string boxText(const TopoDS_Shape& shape) {
  Bnd_Box box;
  BRepBndLib::AddOptimal(shape, box, /*useTriangulation=*/false, /*useShapeTolerance=*/false);
  double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
  box.Get(x0, y0, z0, x1, y1, z1);
  const auto range = [](double a, double b) {
    return "[" + formatNumber(a) + ", " + formatNumber(b) + "]";
  };
  return "x " + range(x0, x1) + ", y " + range(y0, y1) + ", z " + range(z0, z1);
}

struct Findings {
  bool invalid = false, unsewn = false, openSolid = false;
  int smallEdges = 0, smallFaces = 0;
  int facesInNoSolid = 0;                 // beside solids (a loose shell, a stray face)
  std::vector<TopoDS_Shape> emptySolids;  // solids without a face (an exporter's leftovers)
  bool any() const {
    return invalid || unsewn || openSolid || smallEdges > 0 || smallFaces > 0 ||
           facesInNoSolid > 0 || !emptySolids.empty();
  }
};

// `planar`: a model of planar faces in one plane (a 2D case), whose faces are not meant to be
// sewn into a solid.
Findings inspect(const TopoDS_Shape& shape, double diagonal, bool planar,
                 std::vector<std::string>& problems) {
  Findings f;
  TopTools_IndexedMapOfShape edges, faces, solids;
  TopExp::MapShapes(shape, TopAbs_EDGE, edges);
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  TopExp::MapShapes(shape, TopAbs_SOLID, solids);
  if (!BRepCheck_Analyzer(shape).IsValid()) {
    f.invalid = true;
    problems.emplace_back("OpenCASCADE's check finds the shape invalid");
  }
  for (int s = 1; s <= solids.Extent(); ++s) {
    if (count(solids(s), TopAbs_FACE) > 0) continue;
    if (f.emptySolids.empty())
      problems.push_back(cadEntityName(3, s) + " has no face (an empty solid)");
    f.emptySolids.push_back(solids(s));
  }
  if (solids.Extent() == 0 && faces.Extent() > 1 && !planar) {
    f.unsewn = true;
    problems.push_back("no solid: " + std::to_string(faces.Extent()) + " loose faces");
  }
  if (solids.Extent() > 0) {
    const LooseFaces loose = facesInNoSolid(shape);
    f.facesInNoSolid = static_cast<int>(loose.indices.size());
    if (f.facesInNoSolid > 0)
      problems.push_back(std::to_string(f.facesInNoSolid) +
                         (f.facesInNoSolid == 1 ? " face" : " faces") + " in no solid (" +
                         faceNames(loose.indices) + ")");
  }
  for (int s = 1; s <= solids.Extent(); ++s) {
    const int edge = firstFreeEdge(solids(s), edges);
    if (edge == 0) continue;
    f.openSolid = true;
    problems.push_back(cadEntityName(3, s) + " is open (" + cadEntityName(1, edge) +
                       " bounds only one of its faces)");
  }
  const double shortest = kSmallEdge * diagonal;
  int firstSmall = 0;
  for (int e = 1; e <= edges.Extent(); ++e) {
    const TopoDS_Edge& edge = TopoDS::Edge(edges(e));
    if (BRep_Tool::Degenerated(edge)) continue;
    if (GCPnts_AbscissaPoint::Length(BRepAdaptor_Curve(edge)) < shortest) {
      ++f.smallEdges;
      if (firstSmall == 0) firstSmall = e;
    }
  }
  if (f.smallEdges > 0)
    problems.push_back(std::to_string(f.smallEdges) + " edges shorter than " +
                       formatNumber(shortest) + " (first " + cadEntityName(1, firstSmall) + ")");
  ShapeAnalysis_CheckSmallFace check;
  int firstFace = 0;
  for (int i = 1; i <= faces.Extent(); ++i) {
    const TopoDS_Face& face = TopoDS::Face(faces(i));
    TopoDS_Edge e1, e2;
    if (check.CheckSpotFace(face, shortest) || check.CheckStripFace(face, e1, e2, shortest)) {
      ++f.smallFaces;
      if (firstFace == 0) firstFace = i;
    }
  }
  if (f.smallFaces > 0)
    problems.push_back(std::to_string(f.smallFaces) + " tiny or sliver faces (first " +
                       cadEntityName(2, firstFace) + ")");
  return f;
}

// Sews the faces and makes a solid of every closed shell; nullopt when no closed shell results,
// when some face ends up in no solid and `keepOpen` is false, or when a new solid lies inside
// another or in one of `existing` (the model's solids the faces were sewn beside), or
// duplicates one of those. With `keepOpen`, the shells that do not close (and faces in no
// shell) come back beside the solids, to be left out and named by healModel. `history`: what
// sewing made of `shape`'s faces, edges and vertices.
std::optional<TopoDS_Shape> sewIntoSolids(const TopoDS_Shape& shape, double tolerance,
                                          double diagonal, bool keepOpen,
                                          const TopoDS_Shape& existing, HealingRecord& record,
                                          Handle(BRepTools_History) & history) {
  BRepBuilderAPI_Sewing sewing(tolerance);
  sewing.Add(shape);
  sewing.Perform();
  const TopoDS_Shape sewn = sewing.SewedShape();
  history = historyOf(sewing.GetContext());
  TopoDS_Compound solids, rest;
  BRep_Builder builder;
  builder.MakeCompound(solids);
  builder.MakeCompound(rest);
  int made = 0, shellCount = 0, restCount = 0;
  for (TopExp_Explorer shells(sewn, TopAbs_SHELL); shells.More(); shells.Next()) {
    ++shellCount;
    const TopoDS_Shell& shell = TopoDS::Shell(shells.Current());
    double volume = 0.0;
    TopoDS_Solid solid;
    if (BRep_Tool::IsClosed(shell)) {
      ShapeFix_Solid fix;
      solid = fix.SolidFromShell(shell);
    }
    // Two faces on one boundary loop also close: a solid of no volume is no solid.
    if (solid.IsNull() || hasNoVolume(solid, diagonal, volume)) {
      builder.Add(rest, shell);
      ++restCount;
      continue;
    }
    builder.Add(solids, solid);
    ++made;
  }
  int strayFaces = 0;
  for (TopExp_Explorer f(sewn, TopAbs_FACE, TopAbs_SHELL); f.More(); f.Next(), ++strayFaces)
    builder.Add(rest, f.Current());
  restCount += strayFaces;
  // Only when every face ends up in a solid (or keepOpen), none was lost on the way, and no
  // solid lies inside another (an inner shell is a void, not material): else the model is
  // refused as it is, naming a free edge.
  const int lost =
      count(shape, TopAbs_FACE) - count(solids, TopAbs_FACE) - count(rest, TopAbs_FACE);
  if (made == 0 || restCount > 0 || lost > 0)
    record.sewing = "sewing closed " + std::to_string(made) + " of " +
                    std::to_string(std::max(shellCount, made)) +
                    (shellCount == 1 ? " shell" : " shells") +
                    (strayFaces > 0 ? ", " + std::to_string(strayFaces) +
                                          (strayFaces == 1 ? " face" : " faces") + " in no shell"
                                    : std::string()) +
                    (lost > 0 ? ", " + std::to_string(lost) + " faces lost" : std::string());
  // (What --solids-only could keep: the closed shells, unless faces were lost.)
  record.sewnSolids = lost > 0 ? 0 : made;
  if (made == 0 || lost > 0 || (restCount > 0 && !keepOpen)) return std::nullopt;
  // A solid is inside another when its box is and one of its vertices lies strictly inside the
  // other (a void's vertices all do; solids that merely touch, or whose boxes nest, like a
  // resistor's leads and body, have theirs on or outside it: RLF_12545.igs).
  const auto boxOf = [](const TopoDS_Shape& solid) {
    Bnd_Box box;
    BRepBndLib::Add(solid, box);
    return box;
  };
  std::vector<std::pair<TopoDS_Shape, Bnd_Box>> seen;
  if (!existing.IsNull())
    for (TopExp_Explorer s(existing, TopAbs_SOLID); s.More(); s.Next())
      seen.emplace_back(s.Current(), boxOf(s.Current()));
  const std::size_t existingCount = seen.size();
  // A copy of a solid (a surface model exported beside the body) has its vertices on the
  // other's boundary, not inside: the same box and volume, to the sewing tolerance.
  const auto duplicate = [&](const TopoDS_Shape& a, const Bnd_Box& aBox, const TopoDS_Shape& b,
                             const Bnd_Box& bBox) {
    if (!sameBox(aBox, bBox, 10.0 * tolerance)) return false;
    const double va = volumeOf(a), vb = volumeOf(b);
    return std::abs(va - vb) <= 1e-6 * std::max(va, vb);
  };
  const auto nested = [](const TopoDS_Shape& inner, const Bnd_Box& innerBox,
                         const TopoDS_Shape& outer, const Bnd_Box& outerBox) {
    if (outerBox.IsOut(innerBox.CornerMin()) || outerBox.IsOut(innerBox.CornerMax())) return false;
    BRepClass3d_SolidClassifier classifier(outer);
    for (TopExp_Explorer v(inner, TopAbs_VERTEX); v.More(); v.Next()) {
      classifier.Perform(BRep_Tool::Pnt(TopoDS::Vertex(v.Current())),
                         1e-9 * outerBox.SquareExtent());
      if (classifier.State() == TopAbs_IN) return true;
    }
    return false;
  };
  for (TopExp_Explorer s(solids, TopAbs_SOLID); s.More(); s.Next()) {
    const Bnd_Box box = boxOf(s.Current());
    for (std::size_t k = 0; k < seen.size(); ++k) {
      const auto& [other, otherBox] = seen[k];
      const std::string where =
          k < existingCount ? "a closed shell and " + cadEntityName(3, static_cast<int>(k) + 1)
                            : std::string("closed shells");
      if (duplicate(s.Current(), box, other, otherBox)) {
        record.sewing = "sewing gave " + where + " that are copies of each other";
        record.sewnSolids = 0;
        return std::nullopt;
      }
      if (nested(other, otherBox, s.Current(), box) || nested(s.Current(), box, other, otherBox)) {
        record.sewing = "sewing gave " + where +
                        " one inside the other: a void, and which side is material is not known";
        record.sewnSolids = 0;
        return std::nullopt;
      }
    }
    seen.emplace_back(s.Current(), box);
  }
  record.actions.push_back("sewed the faces (tolerance " + formatNumber(tolerance) + ") into " +
                           std::to_string(made) + (made == 1 ? " closed shell" : " closed shells") +
                           " and made " + (made == 1 ? "a solid of it" : "solids of them"));
  if (restCount > 0) {
    builder.Add(solids, rest);
    return TopoDS_Shape(solids);
  }
  return solidsOf(solids);
}

TopoDS_Shape heal(TopoDS_Shape shape, const Findings& found, double diagonal, bool keepOpen,
                  HealingRecord& record) {
  if (!found.emptySolids.empty()) {
    const Handle(BRepTools_ReShape) reshape = new BRepTools_ReShape;
    for (const TopoDS_Shape& solid : found.emptySolids) reshape->Remove(solid);
    const TopoDS_Shape before = shape;
    shape = reshape->Apply(shape);
    record.actions.push_back("removed " + std::to_string(found.emptySolids.size()) +
                             (found.emptySolids.size() == 1 ? " empty solid" : " empty solids"));
    trace(record, before, shape, reshape->History(), record.actions.back());
  }
  const double tolerance = kTolerance * diagonal;
  bool sewn = false;
  Handle(BRepTools_History) sewing;
  const TopoDS_Shape unsewn = shape;
  if (found.unsewn || found.openSolid) {
    // An open solid stays refused by name: solids only leaves out faces that were in no solid.
    if (auto solids = sewIntoSolids(shape, 10.0 * tolerance, diagonal, keepOpen && !found.openSolid,
                                    TopoDS_Shape(), record, sewing)) {
      shape = *solids;
      sewn = true;
    }
  } else if (found.facesInNoSolid > 0) {
    // The solids stay as they are; the faces beside them are sewn alone.
    const TopoDS_Shape solids = solidsOf(shape);
    if (auto more = sewIntoSolids(facesInNoSolid(shape).faces, 10.0 * tolerance, diagonal, keepOpen,
                                  solids, record, sewing)) {
      TopoDS_Compound both;
      BRep_Builder builder;
      builder.MakeCompound(both);
      builder.Add(both, solids);
      builder.Add(both, *more);
      shape = both;
      sewn = true;
    }
  }
  if (sewn) trace(record, unsewn, shape, sewing, record.actions.back());
  if (found.invalid || sewn) {
    ShapeFix_Shape fix(shape);
    fix.SetPrecision(tolerance);
    fix.SetMaxTolerance(kMaxWiden * diagonal);
    if (fix.Perform()) {
      record.actions.emplace_back(
          "fixed wires, edges, tolerances and orientation (ShapeFix_Shape)");
      trace(record, shape, fix.Shape(), historyOf(fix.Context()), record.actions.back());
      shape = fix.Shape();
    }
  }
  if (found.smallEdges > 0) {
    ShapeFix_Wireframe wires(shape);
    wires.SetPrecision(kSmallEdge * diagonal);
    wires.SetMaxTolerance(kMaxWiden * diagonal);
    const bool gaps = wires.FixWireGaps();
    const bool small = wires.FixSmallEdges();
    if (gaps || small) {
      record.actions.push_back("merged edges shorter than " + formatNumber(kSmallEdge * diagonal) +
                               " and closed wire gaps");
      trace(record, shape, wires.Shape(), historyOf(wires.Context()), record.actions.back());
      shape = wires.Shape();
    }
  }
  if (found.smallFaces > 0) {
    ShapeFix_FixSmallFace faces;
    faces.Init(shape);
    faces.SetPrecision(kSmallEdge * diagonal);
    faces.SetMaxTolerance(kMaxWiden * diagonal);
    faces.Perform();
    const TopoDS_Shape fixed = faces.Shape();
    if (!fixed.IsNull() && count(fixed, TopAbs_FACE) < count(shape, TopAbs_FACE)) {
      record.actions.push_back(
          "removed " + std::to_string(count(shape, TopAbs_FACE) - count(fixed, TopAbs_FACE)) +
          " tiny or sliver faces");
      trace(record, shape, fixed, historyOf(faces.Context()), record.actions.back());
      shape = fixed;
    }
  }
  return shape;
}

// The refusal of a model that has no solid once healed (and is not planar): under
// HealingOptions::automatic, the cue to keep its faces as a surface instead.
class NoSolidError : public CadError {
 public:
  NoSolidError(std::string reason, const std::string& message)
      : CadError(message), why(std::move(reason)) {}
  std::string why;  // why there is none, in words ("its 5 faces do not close (...)")
};

CadModel healAs(CadModel cad, const HealingOptions& options, HealingRecord& record);

// The solids of `cad` that have a face (empty ones, which healing removes, do not count).
int solidsWithFaces(const CadModel& cad) {
  int n = 0;
  for (int s = 1; s <= cad.numSolids(); ++s)
    if (count(occtSolid(cad, s), TopAbs_FACE) > 0) ++n;
  return n;
}

}  // namespace

void HealingOptions::validate() const {
  if (automatic && (surface || solidsOnly))
    throw ParameterError(
        "automatic mode (--auto) chooses between --solids-only and --surface itself: give none "
        "of them with it");
  if (surface && solidsOnly)
    throw ParameterError(
        "--surface meshes a model without solids and --solids-only its solids "
        "alone: give one of them");
}

CadModel healModel(CadModel cad, const HealingOptions& options, HealingRecord& record) {
  options.validate();
  if (!options.automatic) return healAs(std::move(cad), options, record);
  // Solids in the file: the faces beside them are left out. None: the faces are all kept,
  // made solids where every shell closes, else a surface (not a solid of the shells that
  // close with the rest left out: surface_filling.step's one closed shell is no solid Gmsh
  // can mesh, and a model of faces alone loses none of them this way).
  const bool solidInFile = solidsWithFaces(cad) > 0;
  const std::string name = cad.sourceName();
  HealingOptions first = options;
  first.automatic = false;
  if (solidInFile) {
    first.solidsOnly = true;
    CadModel healed = healAs(std::move(cad), first, record);
    if (!record.leftOut.empty() && !record.leftOutCopies)
      record.automatic = "automatic mode: " + name +
                         " is meshed as its solids, the faces in no solid left out (as "
                         "--solids-only does)";
    return healed;
  }
  try {
    // On a copy: the fixes of a failed attempt (tolerances widened in place) stay out of the
    // surface attempt, which starts from the file's own shape.
    return healAs(cadModelFromShape(BRepBuilderAPI_Copy(occtShape(cad)).Shape(), name), first,
                  record);
  } catch (const NoSolidError& e) {
    const double firstSeconds = record.seconds;
    HealingOptions faces = options;
    faces.automatic = false;
    faces.surface = true;
    CadModel healed = healAs(std::move(cad), faces, record);
    record.seconds += firstSeconds;
    record.automatic = "automatic mode: " + name + " has no solid (" + e.why +
                       "), so its faces get a surface mesh, as --surface does";
    return healed;
  }
}

namespace {

const char* const kSolidsOnlyOption = "--solids-only (Python solids_only=True, FreeCAD SolidsOnly)";

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A model of faces alone whose faces all lie in one plane (a 2D case).
bool planarFaces(const CadModel& cad, int withFaces) {
  if (withFaces != 0 || cad.numFaces() == 0) return false;
  try {
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    return modelMeshDimension(cad, normal) == 2 && !normal.isZero();
  } catch (const CadError&) {  // (OCCT could not give a face's plane: reported below)
    return false;
  }
}

// The check's findings. A check that fails (OCCT cannot measure an edge, say) is recorded, not
// fatal: the model is then meshed as it is, and a stage that cannot handle it says so.
Findings checkModel(const CadModel& cad, double diagonal, bool faces, HealingRecord& record) {
  Findings found;
  try {
    found = withOcctErrors("checking " + cad.sourceName(), [&] {
      return inspect(occtShape(cad), diagonal, faces, record.problems);
    });
  } catch (const CadError& e) {
    record.problems.push_back(std::string("the check failed: ") + e.what());
  }
  return found;
}

// Sews, fixes and merges what the check found; `cad` becomes the healed model if that changed
// anything.
void healFindings(CadModel& cad, const Findings& found, double diagonal, bool solidsOnly,
                  HealingRecord& record) {
  const TopoDS_Shape healed = withOcctErrors("healing " + cad.sourceName(), [&] {
    return heal(occtShape(cad), found, diagonal, solidsOnly, record);
  });
  if (!record.changed()) return;
  cad = cadModelFromShape(healed, cad.sourceName());
  record.facesAfter = cad.numFaces();
  record.solidsAfter = cad.numSolids();
}

// A solid that is still open, or has no volume, cannot be meshed: say where.
void refuseUnmeshableSolids(const CadModel& cad, const TopTools_IndexedMapOfShape& solids,
                            const TopTools_IndexedMapOfShape& edges, double diagonal,
                            const std::string& healingNote) {
  for (int s = 1; s <= solids.Extent(); ++s) {
    const int edge = firstFreeEdge(solids(s), edges);
    if (edge != 0)
      throw CadError(cad.sourceName() + ": " + cadEntityName(3, s) + " is not closed (" +
                     cadEntityName(1, edge) + " bounds only one of its faces)" + healingNote);
    double volume = 0.0;
    if (hasNoVolume(solids(s), diagonal, volume))
      throw CadError(cad.sourceName() + ": " + cadEntityName(3, s) + " has no volume (" +
                     formatNumber(volume) + " for a bounding-box diagonal of " +
                     formatNumber(diagonal) + "): a zero-thickness solid cannot be meshed");
  }
}

// A model without solids meshed as a surface: its faces sewn (when healing is on) and the
// surface described in the record.
CadModel surfaceModel(CadModel cad, bool enabled, HealingRecord& record) {
  if (cad.numFaces() == 0)
    throw CadError(cad.sourceName() + " has no face: nothing for a surface mesh");
  if (enabled && cad.numFaces() > 1) {
    const TopoDS_Shape& shape = occtShape(cad);
    const TopoDS_Shape sewn = withOcctErrors("sewing " + cad.sourceName(), [&] {
      return sewSurface(shape, 10.0 * record.tolerance, record);
    });
    if (!sewn.IsSame(shape)) {
      cad = cadModelFromShape(sewn, cad.sourceName());
      record.facesAfter = cad.numFaces();
    }
  }
  const int open = freeEdgeCount(occtShape(cad));
  record.surface = "a surface mesh of its " + std::to_string(cad.numFaces()) +
                   (cad.numFaces() == 1 ? " face" : " faces") +
                   " (no solid: triangles on the faces, no volume" +
                   (open > 0 ? "; " + std::to_string(open) +
                                   (open == 1 ? " edge bounds" : " edges bound") + " only one face"
                             : std::string("; the faces close")) +
                   ")";
  return cad;
}

// Faces that close into no solid and are not planar: NoSolidError, naming the option that meshes
// the shells that did close.
[[noreturn]] void refuseNoSolid(const CadModel& cad, const TopTools_IndexedMapOfShape& edges,
                                const std::string& healingNote, const HealingOptions& options,
                                const HealingRecord& record) {
  const int edge = firstFreeEdge(occtShape(cad), edges);
  // Some shells closed: the option that meshes them and leaves the others out is worth naming.
  const std::string notClosed =
      cad.numFaces() == 1 ? std::string("its one face does not close")
                          : "its " + std::to_string(cad.numFaces()) + " faces do not close";
  // (Automatic mode's note leaves the edge out: it is numbered in this attempt's model.)
  throw NoSolidError(
      notClosed + healingNote,
      cad.sourceName() + " is not a closed solid: it has no solid, and " + notClosed +
          (edge != 0 ? " (" + cadEntityName(1, edge) + " bounds only one face)" : "") +
          healingNote +
          "; HOMesh meshes solids, planar faces in one plane (2D), or the faces alone "
          "as a surface mesh: --surface (Python surface=True, FreeCAD Surface)" +
          (record.sewnSolids > 0 && !options.solidsOnly
               ? "; " + std::string(kSolidsOnlyOption) + " meshes the closed shells alone"
               : std::string()));
}

// The solids' faces that the loose faces copy (each loose face on one of them), sorted; empty
// unless every loose face is such a copy.
std::vector<int> copiedFaces(const CadModel& cad, const LooseFaces& loose, double tolerance) {
  std::vector<int> copied;
  std::set<int> copies;
  for (const CoincidentFaces& c : withOcctErrors("checking " + cad.sourceName(), [&] {
         return coincidentFaces(occtShape(cad), tolerance);
       }))
    if (c.solidB == 0 && copies.insert(c.faceB).second) copied.push_back(c.faceA);
  if (copies.size() != loose.indices.size()) copied.clear();
  std::sort(copied.begin(), copied.end());
  return copied;
}

// Faces beside the solids would not be meshed: refused, or (solidsOnly, or copies of the
// solids' faces) left out and recorded.
void leaveOutLooseFaces(CadModel& cad, const LooseFaces& loose,
                        const TopTools_IndexedMapOfShape& edges, const HealingOptions& options,
                        HealingRecord& record) {
  const TopoDS_Shape kept = solidsOf(occtShape(cad));
  const bool one = loose.indices.size() == 1;
  const bool ownNumbers = !record.changed();
  // Faces and edges named by the file's numbers (healing's map back), when each is one of the
  // file's.
  const auto fileNumber = [&](int dim, int index) {
    const std::vector<int> originals = record.numbering.originals(dim, index);
    return originals.size() == 1 ? originals.front() : 0;
  };
  std::vector<int> named;
  for (const int face : loose.indices)
    if (const int n = fileNumber(2, face); n > 0) named.push_back(n);
  std::sort(named.begin(), named.end());
  if (named.size() != loose.indices.size()) named.clear();
  const int free = firstFreeEdge(loose.faces, edges);
  const int edge = free == 0 ? 0 : fileNumber(1, free);
  const std::string which = std::to_string(loose.indices.size()) + (one ? " face" : " faces") +
                            (named.empty() ? std::string() : " (" + faceNames(named) + ")") +
                            " in no solid, within " + boxText(loose.faces);
  const std::string what =
      which + (edge != 0 ? (one ? ": it does not close (" : ": they do not close (") +
                               cadEntityName(1, edge) + " bounds only one face)"
                         : "");
  // Loose faces that all lie on faces of the solids (a surface model exported beside its
  // body, as Gmsh's shell_sewing demo writes it) are copies: leaving them out loses nothing.
  const std::vector<int> copied =
      ownNumbers ? copiedFaces(cad, loose, 10.0 * record.tolerance) : std::vector<int>{};
  if ((!options.solidsOnly && copied.empty()) || count(kept, TopAbs_FACE) == 0)
    throw CadError(cad.sourceName() + ": " + what +
                   (!options.enabled ? "; healing is off (it may close them)"
                    : record.sewing.empty()
                        ? std::string()
                        : "; healing could not make a solid of them (" + record.sewing + ")") +
                   (options.solidsOnly ? "; and no solid has a face"
                                       : "; close them in the CAD, or mesh the solids alone: " +
                                             std::string(kSolidsOnlyOption)));
  record.leftOut = what + (record.sewing.empty() ? std::string() : " (" + record.sewing + ")");
  if (!copied.empty()) {
    record.leftOut = which + ": " + (one ? "a copy of " : "copies of ") + faceNames(copied) +
                     " of the solids; nothing of the model is lost";
    record.leftOutCopies = true;
  }
  // The faces left out, and their edges and vertices the solids do not have, are removed.
  BRepTools_History history;
  for (const TopAbs_ShapeEnum type : {TopAbs_FACE, TopAbs_EDGE, TopAbs_VERTEX}) {
    TopTools_IndexedMapOfShape inSolids, inLoose;
    TopExp::MapShapes(kept, type, inSolids);
    TopExp::MapShapes(loose.faces, type, inLoose);
    for (int i = 1; i <= inLoose.Extent(); ++i)
      if (!inSolids.Contains(inLoose(i))) history.Remove(inLoose(i));
  }
  record.numbering = record.numbering.then(NumberingMap::fromHistory(
      occtShape(cad), kept, history, "leaving out the faces in no solid (" + which + ")"));
  cad = cadModelFromShape(kept, cad.sourceName());
  record.facesAfter = cad.numFaces();
  record.solidsAfter = cad.numSolids();
}

// Solids that touch on faces of their own (not one shared face) are meshed apart there: a
// warning names the first pairs. `imprint`: whether imprinting was on (it failed, or the solids
// overlap: record.imprint.warning says so).
void warnTouchingSolids(const CadModel& cad, bool imprint, HealingRecord& record) {
  std::vector<CoincidentFaces> pairs = withOcctErrors("checking " + cad.sourceName(), [&] {
    return coincidentFaces(occtShape(cad), 10.0 * record.tolerance);
  });
  pairs.erase(std::remove_if(pairs.begin(), pairs.end(),
                             [](const CoincidentFaces& c) { return c.solidB == 0; }),
              pairs.end());
  std::string where;
  for (std::size_t k = 0; k < pairs.size() && k < 3; ++k)
    where += (k == 0 ? "" : ", ") + cadEntityName(3, pairs[k].solidA) + " and " +
             cadEntityName(3, pairs[k].solidB) + " (" + cadEntityName(2, pairs[k].faceA) + " on " +
             cadEntityName(2, pairs[k].faceB) + ")";
  if (pairs.size() > 3) where += " and " + std::to_string(pairs.size() - 3) + " more pairs";
  if (!pairs.empty())
    record.warnings.push_back(
        "solids lie against each other on faces they do not share: " + where +
        "; each is meshed with its own nodes there, so the mesh does not conform across "
        "them" +
        (imprint ? std::string(" (make them touch without overlapping, or fuse them in the CAD: "
                               "FreeCAD Part > Boolean > Boolean fragments)")
                 : std::string(" (imprinting is off: --no-imprint, imprint=False, Imprint)")));
}

// Touching solids imprinted on each other (options.imprint), or the warnings of why not.
CadModel imprintTouchingSolids(CadModel cad, const HealingOptions& options, HealingRecord& record) {
  record.imprint.enabled = options.imprint;
  cad = imprintSolids(std::move(cad), 10.0 * record.tolerance, record.imprint);
  if (record.imprint.imprinted) {
    record.facesAfter = cad.numFaces();
    record.solidsAfter = cad.numSolids();
    if (!record.imprint.overlap.empty()) record.warnings.push_back(record.imprint.overlap);
    return cad;
  }
  if (!record.imprint.warning.empty())
    record.warnings.push_back(record.imprint.warning);
  else
    warnTouchingSolids(cad, options.imprint, record);
  return cad;
}

CadModel healAs(CadModel cad, const HealingOptions& options, HealingRecord& record) {
  const auto start = std::chrono::steady_clock::now();
  const bool enabled = options.enabled;
  const TopoDS_Shape original = occtShape(cad);
  record = HealingRecord{};
  record.enabled = enabled;
  record.imprint.enabled = options.imprint;
  const double diagonal = cad.boundingDiagonal();
  record.tolerance = kTolerance * diagonal;
  record.facesBefore = record.facesAfter = cad.numFaces();
  record.solidsBefore = record.solidsAfter = cad.numSolids();
  record.numbering = NumberingMap::identity(original);
  // (Solids without a face are removed below: they do not count.)
  const int withFaces = solidsWithFaces(cad);
  if (options.surface && withFaces > 0)
    throw CadError(cad.sourceName() + " has " + std::to_string(withFaces) +
                   (withFaces == 1 ? " solid" : " solids") +
                   ": a surface mesh (--surface, Python surface=True, FreeCAD Surface) is for a "
                   "model of faces alone; without it the solids get a volume mesh");
  // Faces not meant to be sewn into a solid: planar ones in one plane (a 2D case), or any when
  // a surface mesh is asked for.
  const bool planar = planarFaces(cad, withFaces);
  const bool faces = planar || (options.surface && withFaces == 0);
  const Findings found = checkModel(cad, diagonal, faces, record);
  if (enabled && found.any()) healFindings(cad, found, diagonal, options.solidsOnly, record);
  record.seconds = secondsSince(start);
  TopTools_IndexedMapOfShape edges, solids;
  TopExp::MapShapes(occtShape(cad), TopAbs_EDGE, edges);
  TopExp::MapShapes(occtShape(cad), TopAbs_SOLID, solids);
  const std::string healingNote =
      enabled ? "; healing could not close it" +
                    (record.sewing.empty() ? std::string() : " (" + record.sewing + ")")
              : "; healing is off (it may close it)";
  refuseUnmeshableSolids(cad, solids, edges, diagonal, healingNote);
  if (solids.Extent() == 0 && faces && !planar) {
    cad = surfaceModel(std::move(cad), enabled, record);
    record.renumbered = renumbered(record.numbering);
    record.seconds = secondsSince(start);
    return cad;
  }
  if (solids.Extent() == 0 && !planar) refuseNoSolid(cad, edges, healingNote, options, record);
  const LooseFaces loose = solids.Extent() > 0 ? facesInNoSolid(occtShape(cad)) : LooseFaces{};
  if (!loose.indices.empty()) leaveOutLooseFaces(cad, loose, edges, options, record);
  record.renumbered = renumbered(record.numbering);
  if (cad.numSolids() > 1) cad = imprintTouchingSolids(std::move(cad), options, record);
  if (record.imprint.imprinted) record.numbering = record.numbering.then(record.imprint.numbering);
  record.seconds = secondsSince(start);
  return cad;
}

}  // namespace

}  // namespace homesh
