#include "cad/solid_imprint.hpp"

#include <BOPAlgo_Builder.hxx>
#include <BRepBndLib.hxx>
#include <BRep_Builder.hxx>
#include <Bnd_Box.hxx>
#include <TopExp.hxx>
#include <TopTools_DataMapOfShapeInteger.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Compound.hxx>

#include <algorithm>
#include <chrono>
#include <set>
#include <sstream>
#include <utility>

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
  BOPAlgo_Builder fuse;
  fuse.SetNonDestructive(true);  // the model's own shapes stay as they are
  fuse.SetFuzzyValue(tolerance);
  fuse.SetRunParallel(false);
  for (int s = 1; s <= solids.Extent(); ++s)
    if (touching[static_cast<std::size_t>(s)] != 0) fuse.AddArgument(solids(s));
  const std::string what = "imprinting the solids of " + cad.sourceName() + " on each other";
  std::string failure;
  try {
    withOcctErrors(what, [&] { fuse.Perform(); });
    if (fuse.HasErrors()) {
      std::ostringstream dump;
      fuse.DumpErrors(dump);
      failure = "OpenCASCADE's general fuse failed" +
                (dump.str().empty() ? std::string() : " (" + dump.str() + ")");
    }
  } catch (const CadError& e) {
    failure = e.what();
  }
  const auto notImprinted = [&](const std::string& why) {
    record.warning = why +
                     "; each solid is meshed with its own nodes where they touch, so the "
                     "mesh does not conform across them";
    record.seconds = secondsSince(start);
    return std::move(cad);
  };
  if (!failure.empty()) return notImprinted("the touching solids were not imprinted: " + failure);
  // A solid the fuse cut into pieces shares volume with another. (A solid that was not an
  // argument has no history: Modified is empty, its image itself.)
  std::vector<int> overlapping;
  std::vector<TopoDS_Shape> images(static_cast<std::size_t>(solids.Extent()) + 1);
  for (int s = 1; s <= solids.Extent(); ++s) {
    const TopTools_ListOfShape& modified = fuse.Modified(solids(s));
    if (modified.Extent() > 1) overlapping.push_back(s);
    images[static_cast<std::size_t>(s)] = modified.IsEmpty() ? solids(s) : modified.First();
  }
  if (!overlapping.empty())
    return notImprinted(namesOf(overlapping) +
                        " share volume with other solids (they overlap, not only touch): the "
                        "solids were not imprinted");
  // Each solid must become one solid of its own: a solid the fuse removed, or two that became
  // one (a copy of a solid), would leave fewer solids than the model has.
  TopTools_DataMapOfShapeInteger owner;  // image -> the first solid that became it
  std::set<int> merged;
  for (int s = 1; s <= solids.Extent(); ++s) {
    const TopoDS_Shape& solid = images[static_cast<std::size_t>(s)];
    if (fuse.IsDeleted(solids(s))) {
      merged.insert(s);
    } else if (owner.IsBound(solid)) {
      merged.insert(owner(solid));
      merged.insert(s);
    } else {
      owner.Bind(solid, s);
    }
  }
  if (!merged.empty())
    return notImprinted(namesOf(std::vector<int>(merged.begin(), merged.end())) +
                        ": the fuse made one solid of two, or removed one (a solid and its "
                        "copy?): the solids were not imprinted");
  if (!fuse.HasModified()) return unchanged();  // the boxes met, the solids did not
  BRep_Builder builder;
  TopoDS_Compound result;
  builder.MakeCompound(result);
  for (int s = 1; s <= solids.Extent(); ++s)
    builder.Add(result, images[static_cast<std::size_t>(s)]);
  const NumberingMap numbering = NumberingMap::fromHistory(shape, result, *fuse.History(), kImprintOperation);
  // The solids already shared what they touch (fused before): their numbering stays.
  if (!numbering.changed()) return unchanged();
  record.numbering = numbering;
  record.interfaces = interfacesOf(result);
  for (int s = 1; s <= solids.Extent(); ++s)
    if (!images[static_cast<std::size_t>(s)].IsSame(solids(s))) ++record.joined;
  record.imprinted = true;
  CadModel imprinted = cadModelFromShape(result, cad.sourceName());
  record.seconds = secondsSince(start);
  return imprinted;
}

}  // namespace homesh
