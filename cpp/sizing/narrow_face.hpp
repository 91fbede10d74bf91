// Narrow faces along curved edges: a chamfer 0.05 wide around a hole of radius 20, a ledge
// left where a cone meets a cylinder. The curvature size along such an edge (a chord whose
// sagitta is EPS R) can sag across the whole face: a tetrahedron on the face then spans it from
// one edge to the other, and curving its edge onto the CAD folds it. The face's width there
// bounds the sagitta as a wall's thickness does (sizing/wall_thickness.hpp).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "sizing/sizing_parameters.hpp"

namespace homesh {

class CadModel;

class NarrowFaces {
 public:
  // Per edge, the edges across its faces: those of a face the edge bounds that share no vertex
  // with it (edges that meet it at a corner are the face's sides, not its far side).
  explicit NarrowFaces(const CadModel& cad);

  // The width of the edge's faces at x, a point of the edge: the distance to the nearest edge
  // across them, searched only within `reach` (infinity where none is that near).
  // Throws CadError naming the edge OCCT cannot project onto.
  double width(int edge, const Eigen::Vector3d& x, double reach) const;

  // The size bound at a point of a curved edge of radius R whose faces are `width` wide: the
  // chord whose sagitta is params.narrowFace x width, where that is below `current` (the size
  // there so far), and at least params.minDelta. `current` itself where the bound does not
  // bind, or with narrowFace 0. Unlike a thin wall's, the bound has no floor of a third of the
  // curvature size: a face narrowing to nothing meets its far side at a vertex, which is no
  // edge across it, so the width never drops to zero along an edge.
  static double size(double radius, double width, double current, const SizingParameters& params);

  // How far across a face the search must look for the bound to bind at a point of radius R
  // whose size is `current` (10 % more than the width whose bound is `current`).
  static double reach(double radius, double current, const SizingParameters& params);

 private:
  const CadModel& cad_;
  std::vector<std::vector<int>> across_;        // [edge] -> edges across its faces
  std::vector<Eigen::Vector3d> boxLo_, boxHi_;  // [edge] bounding boxes
};

}  // namespace homesh
