#include "cad/solid_imprint.hpp"

#include <BOPAlgo_Builder.hxx>
#include <BRepBndLib.hxx>
#include <BRepTools_History.hxx>
#include <BRepTools_ReShape.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_DataMapOfShapeInteger.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Iterator.hxx>

#include <algorithm>
#include <chrono>
#include <memory>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include "cad/occt_access.hpp"
#include "core/error.hpp"

namespace homesh {

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Per solid (1-based), whether its box, widened by `tolerance`, meets another solid's: only
// those can touch, and only those go through the fuse (its cost grows with its arguments).
std::vector<char> touchingBoxes(const TopTools_IndexedMapOfShape& solids, double tolerance) {
  const int n = solids.Extent();
  std::vector<Bnd_Box> boxes(static_cast<std::size_t>(n) + 1);
  for (int s = 1; s <= n; ++s) {
    BRepBndLib::Add(solids(s), boxes[static_cast<std::size_t>(s)], /*useTriangulation=*/false);
    boxes[static_cast<std::size_t>(s)].Enlarge(tolerance);
  }
  std::vector<char> touching(static_cast<std::size_t>(n) + 1, 0);
  for (int a = 1; a <= n; ++a)
    for (int b = a + 1; b <= n; ++b)
      if (!boxes[static_cast<std::size_t>(a)].IsOut(boxes[static_cast<std::size_t>(b)]))
        touching[static_cast<std::size_t>(a)] = touching[static_cast<std::size_t>(b)] = 1;
  return touching;
}

// A wire of internal edges that the fuse made (none of `original`'s edges): where two solids
// touch at a point or along a line (a ball on its race), the fuse leaves such edges inside each
// face, bounding nothing.
bool contactWire(const TopoDS_Shape& wire, const TopTools_IndexedMapOfShape& original) {
  if (wire.ShapeType() != TopAbs_WIRE) return false;
  bool any = false;
  for (TopoDS_Iterator e(wire); e.More(); e.Next()) {
    if (e.Value().ShapeType() != TopAbs_EDGE || e.Value().Orientation() != TopAbs_INTERNAL ||
        original.Contains(e.Value()))
      return false;
    any = true;
  }
  return any;
}

// `shape` with the contact wires (contactWire) taken out of its faces; how many edges in
// `edges`. Gmsh cannot mesh internal edges shorter than its elements (Gmsh 4.8 aborts: "The 1D
// mesh seems not to be forming a closed loop": the balls of OpenCASCADE's Axis_of_bearing left
// 332 such edges, 0.006 to 0.05 long, on their races), and a point or line contact has no face
// to conform across. `history`: what the removal did, for the numbering.
TopoDS_Shape withoutContactEdges(const TopoDS_Shape& shape,
                                 const TopTools_IndexedMapOfShape& original, int& edges,
                                 Handle(BRepTools_History) & history) {
  edges = 0;
  Handle(BRepTools_ReShape) reshape = new BRepTools_ReShape;
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  BRep_Builder builder;
  for (int f = 1; f <= faces.Extent(); ++f) {
    // Read forward, so that the wires keep their orientation in the face rebuilt from them.
    const TopoDS_Face face = TopoDS::Face(faces(f).Oriented(TopAbs_FORWARD));
    int here = 0;
    std::vector<TopoDS_Shape> kept;
    for (TopoDS_Iterator w(face); w.More(); w.Next()) {
      if (!contactWire(w.Value(), original)) {
        kept.push_back(w.Value());
        continue;
      }
      for (TopoDS_Iterator e(w.Value()); e.More(); e.Next()) ++here;
    }
    if (here == 0) continue;
    TopoDS_Face copy = TopoDS::Face(face.EmptyCopied());
    for (const TopoDS_Shape& wire : kept) builder.Add(copy, wire);
    builder.NaturalRestriction(copy, BRep_Tool::NaturalRestriction(face));
    reshape->Replace(face, copy);
    edges += here;
  }
  if (edges == 0) return shape;
  TopoDS_Shape result = reshape->Apply(shape);
  history = reshape->History();
  return result;
}

// How far past the fuzzy value the fuse may stretch a tolerance before it is done again finer.
constexpr double kToleranceGrowth = 10.0;

// The largest tolerance of a vertex or edge of `shape`.
double largestTolerance(const TopoDS_Shape& shape) {
  double largest = 0.0;
  for (TopExp_Explorer v(shape, TopAbs_VERTEX); v.More(); v.Next())
    largest = std::max(largest, BRep_Tool::Tolerance(TopoDS::Vertex(v.Current())));
  for (TopExp_Explorer e(shape, TopAbs_EDGE); e.More(); e.Next())
    largest = std::max(largest, BRep_Tool::Tolerance(TopoDS::Edge(e.Current())));
  return largest;
}

std::string namesOf(const std::vector<int>& solids) {
  std::string s;
  for (std::size_t k = 0; k < solids.size() && k < 4; ++k)
    s += (k == 0 ? "" : k + 1 == solids.size() ? " and " : ", ") + cadEntityName(3, solids[k]);
  if (solids.size() > 4) s += " and " + std::to_string(solids.size() - 4) + " more";
  return s;
}

// The faces of `shape` that two of its solids share, with those solids.
std::vector<SolidInterface> interfacesOf(const TopoDS_Shape& shape) {
  TopTools_IndexedMapOfShape faces, solids;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  TopExp::MapShapes(shape, TopAbs_SOLID, solids);
  TopTools_IndexedDataMapOfShapeListOfShape owners;
  TopExp::MapShapesAndUniqueAncestors(shape, TopAbs_FACE, TopAbs_SOLID, owners);
  std::vector<SolidInterface> out;
  for (int f = 1; f <= faces.Extent(); ++f) {
    const int k = owners.FindIndex(faces(f));
    if (k == 0) continue;
    std::set<int> by;
    for (const TopoDS_Shape& solid : owners(k)) by.insert(solids.FindIndex(solid));
    if (by.size() == 2) out.push_back({f, *by.begin(), *by.rbegin()});
  }
  return out;
}

// The general fuse of the touching solids (`touching`, by number) with fuzzy value
// `tolerance`, or a tenth of it (see below); `fuzzy` the value used; `failure` why it failed
// ("" when it did not).
std::unique_ptr<BOPAlgo_Builder> fuseTouching(const TopTools_IndexedMapOfShape& solids,
                                              const std::vector<char>& touching, double tolerance,
                                              const std::string& source, double& fuzzy,
                                              std::string& failure) {
  const std::string what = "imprinting the solids of " + source + " on each other";
  // The fuse with fuzzy value `value`; "" or why it failed.
  const auto perform = [&](BOPAlgo_Builder& fuse, double value) {
    fuse.SetNonDestructive(true);  // the model's own shapes stay as they are
    fuse.SetFuzzyValue(value);
    fuse.SetRunParallel(false);
    for (int s = 1; s <= solids.Extent(); ++s)
      if (touching[static_cast<std::size_t>(s)] != 0) fuse.AddArgument(solids(s));
    try {
      withOcctErrors(what, [&] { fuse.Perform(); });
      if (!fuse.HasErrors()) return std::string();
      std::ostringstream dump;
      fuse.DumpErrors(dump);
      return "OpenCASCADE's general fuse failed" +
             (dump.str().empty() ? std::string() : " (" + dump.str() + ")");
    } catch (const CadError& e) {
      return std::string(e.what());
    }
  };
  auto fuse = std::make_unique<BOPAlgo_Builder>();
  failure = perform(*fuse, tolerance);
  fuzzy = tolerance;
  if (!failure.empty()) return fuse;
  // Where solids touch tangentially (balls on their races), a fuzzy fuse can stretch a vertex's
  // tolerance far past the fuzzy value to close a gap it made, and leave a face Gmsh cannot
  // mesh: on Axis_of_bearing at 1.4e-3 a vertex of tolerance 0.11 joined a race's edges out of
  // order ("The 1D mesh seems not to be forming a closed loop"), which a tenth of the value
  // does not. Such a fuse (stretched past ten times the value and past what the solids had
  // before) is done again with a tenth, kept where it shares as many faces between solids, so
  // that no contact is lost to it.
  TopoDS_Compound arguments;
  BRep_Builder builder;
  builder.MakeCompound(arguments);
  for (int s = 1; s <= solids.Extent(); ++s) builder.Add(arguments, solids(s));
  if (largestTolerance(fuse->Shape()) <=
      std::max(kToleranceGrowth * tolerance, largestTolerance(arguments)))
    return fuse;
  auto finer = std::make_unique<BOPAlgo_Builder>();
  if (perform(*finer, 0.1 * tolerance).empty() &&
      interfacesOf(finer->Shape()).size() >= interfacesOf(fuse->Shape()).size()) {
    fuzzy = 0.1 * tolerance;
    return finer;
  }
  return fuse;
}

}  // namespace

CadModel imprintSolids(CadModel cad, double tolerance, ImprintRecord& record) {
  const auto start = std::chrono::steady_clock::now();
  const bool enabled = record.enabled;
  record = ImprintRecord{};
  record.enabled = enabled;
  const TopoDS_Shape& shape = occtShape(cad);
  record.numbering = NumberingMap::identity(shape);
  TopTools_IndexedMapOfShape solids;
  TopExp::MapShapes(shape, TopAbs_SOLID, solids);
  record.solids = solids.Extent();
  if (!enabled || record.solids < 2) return cad;
  const auto unchanged = [&] {  // the model as it was, nothing to say
    record.seconds = secondsSince(start);
    return std::move(cad);
  };
  const std::vector<char> touching = touchingBoxes(solids, tolerance);
  record.touching = static_cast<int>(std::count(touching.begin(), touching.end(), 1));
  if (record.touching == 0) return unchanged();
  std::string failure;
  const std::unique_ptr<BOPAlgo_Builder> fuse =
      fuseTouching(solids, touching, tolerance, cad.sourceName(), record.fuzzy, failure);
  const auto notImprinted = [&](const std::string& why) {
    record.warning = why +
                     "; each solid is meshed with its own nodes where they touch, so the "
                     "mesh does not conform across them";
    record.seconds = secondsSince(start);
    return std::move(cad);
  };
  if (!failure.empty()) return notImprinted("the touching solids were not imprinted: " + failure);
  // Each solid's pieces: itself (a solid that was not an argument has no history), or what the
  // fuse made of it. Solids that share volume are cut where they overlap, the overlap a piece
  // of both; a solid and its copy become one piece. A solid the fuse removed leaves nothing.
  std::vector<TopTools_ListOfShape> pieces(static_cast<std::size_t>(solids.Extent()) + 1);
  std::vector<int> removed;
  for (int s = 1; s <= solids.Extent(); ++s) {
    const TopTools_ListOfShape& modified = fuse->Modified(solids(s));
    if (fuse->IsDeleted(solids(s))) removed.push_back(s);
    if (modified.IsEmpty())
      pieces[static_cast<std::size_t>(s)].Append(solids(s));
    else
      pieces[static_cast<std::size_t>(s)] = modified;
  }
  if (!removed.empty())
    return notImprinted(namesOf(removed) +
                        ": the fuse removed them: the solids were not imprinted");
  // The result's solids in the model's order, a piece two solids share listed once.
  TopTools_DataMapOfShapeInteger firstOwner;  // piece -> the first solid it is a piece of
  std::vector<TopoDS_Shape> result;
  std::set<int> cut;  // solids cut into pieces, or sharing one with another
  for (int s = 1; s <= solids.Extent(); ++s) {
    const TopTools_ListOfShape& mine = pieces[static_cast<std::size_t>(s)];
    if (mine.Extent() > 1) cut.insert(s);
    for (const TopoDS_Shape& piece : mine) {
      if (firstOwner.IsBound(piece)) {
        cut.insert(firstOwner(piece));
        cut.insert(s);
        continue;
      }
      firstOwner.Bind(piece, s);
      result.push_back(piece);
    }
  }
  if (!fuse->HasModified()) return unchanged();  // the boxes met, the solids did not
  BRep_Builder builder;
  TopoDS_Compound compound;
  builder.MakeCompound(compound);
  for (const TopoDS_Shape& piece : result) builder.Add(compound, piece);
  NumberingMap numbering =
      NumberingMap::fromHistory(shape, compound, *fuse->History(), kImprintOperation);
  // The model's own edges and the fuse's pieces of them (an internal edge of the model's stays).
  TopTools_IndexedMapOfShape originalEdges, inputEdges;
  TopExp::MapShapes(shape, TopAbs_EDGE, inputEdges);
  for (int e = 1; e <= inputEdges.Extent(); ++e) {
    originalEdges.Add(inputEdges(e));
    for (const TopoDS_Shape& piece : fuse->Modified(inputEdges(e))) originalEdges.Add(piece);
  }
  Handle(BRepTools_History) loopHistory;
  const TopoDS_Shape fused = compound;
  const TopoDS_Shape imprintedShape =
      withoutContactEdges(fused, originalEdges, record.contactEdges, loopHistory);
  if (record.contactEdges > 0)
    numbering = numbering.then(
        NumberingMap::fromHistory(fused, imprintedShape, *loopHistory, kImprintOperation));
  // The solids already shared what they touch (fused before): their numbering stays.
  if (!numbering.changed()) return unchanged();
  record.numbering = numbering;
  record.interfaces = interfacesOf(imprintedShape);
  for (int s = 1; s <= solids.Extent(); ++s)
    if (!pieces[static_cast<std::size_t>(s)].First().IsSame(solids(s)) ||
        pieces[static_cast<std::size_t>(s)].Extent() > 1)
      ++record.joined;
  if (!cut.empty()) {
    std::string into;
    for (const int s : cut) {
      const std::vector<int>& finals = numbering.finalNumbers(3, s);
      into += (into.empty() ? "" : ", ") + cadEntityName(3, s) + " -> ";
      for (std::size_t k = 0; k < finals.size(); ++k)
        into += (k == 0 ? "" : " + ") + cadEntityName(3, finals[k]);
    }
    record.overlap = namesOf(std::vector<int>(cut.begin(), cut.end())) +
                     " share volume (they overlap, not only touch): cut where they overlap, "
                     "each overlap a solid of its own meshed once (" +
                     into + ")";
  }
  record.imprinted = true;
  CadModel imprinted = cadModelFromShape(imprintedShape, cad.sourceName());
  record.seconds = secondsSince(start);
  return imprinted;
}

}  // namespace homesh
