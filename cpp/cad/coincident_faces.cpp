#include "cad/coincident_faces.hpp"

#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Shape.hxx>

#include <cmath>
#include <optional>
#include <utility>

namespace homesh {

bool sameBox(const Bnd_Box& a, const Bnd_Box& b, double tolerance) {
  return a.CornerMin().Distance(b.CornerMin()) <= tolerance &&
         a.CornerMax().Distance(b.CornerMax()) <= tolerance;
}

std::vector<CoincidentFaces> coincidentFaces(const TopoDS_Shape& shape, double tolerance) {
  TopTools_IndexedMapOfShape faces, solids;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  TopExp::MapShapes(shape, TopAbs_SOLID, solids);
  std::vector<int> owner(static_cast<std::size_t>(faces.Extent()) + 1, 0);  // 0: none, -1: two
  for (int s = 1; s <= solids.Extent(); ++s)
    for (TopExp_Explorer f(solids(s), TopAbs_FACE); f.More(); f.Next()) {
      int& o = owner[static_cast<std::size_t>(faces.FindIndex(f.Current()))];
      o = (o == 0 || o == s) ? s : -1;
    }
  struct Candidate {
    int face = 0, solid = 0;
    Bnd_Box box;
    std::optional<GProp_GProps> props;  // area and centre, measured once a box matches
  };
  std::vector<Candidate> candidates;
  for (int i = 1; i <= faces.Extent(); ++i) {
    const int solid = owner[static_cast<std::size_t>(i)];
    if (solid < 0) continue;
    Candidate c;
    c.face = i;
    c.solid = solid;
    BRepBndLib::AddOptimal(faces(i), c.box, /*useTriangulation=*/false,
                           /*useShapeTolerance=*/false);
    candidates.push_back(c);
  }
  const auto props = [&](Candidate& c) -> const GProp_GProps& {
    if (!c.props) {
      c.props.emplace();
      BRepGProp::SurfaceProperties(faces(c.face), *c.props);
    }
    return *c.props;
  };
  std::vector<CoincidentFaces> found;
  for (std::size_t a = 0; a < candidates.size(); ++a)
    for (std::size_t b = a + 1; b < candidates.size(); ++b) {
      Candidate* p = &candidates[a];
      Candidate* q = &candidates[b];
      if (p->solid == q->solid || !sameBox(p->box, q->box, tolerance)) continue;
      if (p->solid == 0) std::swap(p, q);  // the loose face second
      const GProp_GProps& pp = props(*p);
      const GProp_GProps& qp = props(*q);
      if (std::abs(pp.Mass() - qp.Mass()) > 1e-6 * std::max(pp.Mass(), qp.Mass()) ||
          pp.CentreOfMass().Distance(qp.CentreOfMass()) > tolerance)
        continue;
      found.push_back({p->solid, q->solid, p->face, q->face});
    }
  return found;
}

}  // namespace homesh
