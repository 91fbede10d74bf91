// What a boundary layer is asked to be: the faces (in 2D, curves) that carry it, its thickness
// (a number or an expression of x, y, z), the number of thin layers and their progression, all
// checked at once (validate), and the split coordinates across the layer that they give.
#pragma once

#include <string>
#include <vector>

#include "core/parameters.hpp"

namespace homesh {

struct BoundaryLayerParameters {
  std::vector<int> faces;  // 1-based CAD faces (FaceN) that carry the layer
  // Where a layer face lies between two solids: the solid (SolidN) it grows into, of the two
  // (a face of one solid grows into it, named or not).
  std::vector<int> solids;
  std::string thickness;  // total thickness: a number or an expression of x, y, z
  // Defaults as NekMesh's (core/parameters.hpp).
  int layers = static_cast<int>(parameterDefault("layers"));  // thin layers per macro prism
  double progression = parameterDefault("progression");       // consecutive layers' height ratio

  // Throws ParameterError naming the parameter (no faces, a face or solid number below 1, a
  // thickness that does not parse, layers or progression out of range).
  void validate() const;
  // The split coordinates across the layer: z_0 = 0 < z_1 < ... < z_n = 1, with
  // z_{k+1} - z_k = z_1 r^k (a geometric progression of ratio r, n layers).
  std::vector<double> splitCoordinates() const;
};

// "1,8", "11-12", "1, 3-5": a list of positive integers and ranges (NekMesh's
// BndLayerSurfaces), sorted, without repeats. Throws ParameterError naming `what`.
std::vector<int> parseIndexList(const std::string& text, const std::string& what);

}  // namespace homesh
