// Which CAD sub-shape each Gmsh entity is.
//
// Gmsh numbers the entities of an imported OCCT shape in its own binding order, which differs
// from FreeCAD's (TopExp::MapShapes) for compounds. The map is rebuilt from geometry and
// topology, top down: each Gmsh volume is matched to the CAD solid whose faces it has, then the
// boundary of every matched entity to the boundary of its CAD counterpart (surfaces, curves,
// points), and finally entities with no parent (free faces, edges, vertices) among what is left.
// Geometry decides between candidates: a point at the entity's parametric centre (Gmsh keeps
// OCCT's parametrisations), with the parameter ranges breaking ties between pieces of one
// underlying curve or surface. Going top down keeps distinct but coincident entities apart
// (two solids touching without shared topology). The result must be a bijection between Gmsh's
// entities and the CAD's (degenerated edges included), or the import is rejected.
#pragma once

#include <map>
#include <utility>

#include "cad/cad_model.hpp"

namespace homesh {

class GmshEntityMap {
 public:
  // Requires `cad` imported into the current Gmsh model and synchronised.
  // Throws MeshingError when no bijection exists.
  static GmshEntityMap build(const CadModel& cad);

  // 1-based CAD index of Gmsh entity (dim, tag); throws MeshingError if unknown.
  int cadIndex(int dim, int tag) const;

 private:
  std::map<std::pair<int, int>, int> toCad_;
};

}  // namespace homesh
