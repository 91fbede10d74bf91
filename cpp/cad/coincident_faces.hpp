// Faces of a model's solids that lie on each other without being one face: what a mesh does
// not conform across, and what a loose copy of a solid's face is. Found by their boxes first,
// then their areas and centres of mass.
#pragma once

#include <vector>

class Bnd_Box;
class TopoDS_Shape;

namespace homesh {

// Whether two boxes have the same corners, to `tolerance`: the first test of two shapes being
// one (a copied solid, coincident faces), before their volumes or areas are measured.
bool sameBox(const Bnd_Box& a, const Bnd_Box& b, double tolerance);

// Faces of different solids that lie on each other without being one shared face (the same
// box, area and centre of mass, to `tolerance`): each solid's mesh gets its own triangles and
// nodes there, so the mesh does not conform across them. As "Face7 on Face8" (FaceN in the
// shape's numbering), with the two solids' SolidN. A face in no solid counts as one of solid
// 0: a pair with solidB 0 is a loose face (faceB) lying on a solid's face (faceA), a copy.
struct CoincidentFaces {
  int solidA = 0, solidB = 0, faceA = 0, faceB = 0;
};

std::vector<CoincidentFaces> coincidentFaces(const TopoDS_Shape& shape, double tolerance);

}  // namespace homesh
