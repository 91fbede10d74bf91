// Which CAD sub-shape each Gmsh entity is.
//
// Gmsh numbers the entities of an imported OCCT shape in its own binding order, which differs
// from FreeCAD's (TopExp::MapShapes) for compounds. The map is rebuilt from geometry and
// topology alone: vertices by position; curves by their end vertices and the point at a common
// parameter (Gmsh keeps OCCT's parametrisation); surfaces by their boundary curves and a point;
// volumes by their boundary surfaces. It must be a bijection between Gmsh's entities and the
// CAD entities (degenerated edges included), or the import is rejected.
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
