#include "cad/model_dimension.hpp"

#include <cmath>
#include <string>

#include "cad/cad_model.hpp"
#include "core/error.hpp"

namespace homesh {

int modelMeshDimension(const CadModel& cad, Eigen::Vector3d& normal) {
  if (cad.numSolids() > 0) return 3;
  const std::string hint =
      ": HOMesh meshes solids, or planar faces in one plane (2D); a closed shell must be made a "
      "solid first (FreeCAD: Part > Convert to solid)";
  if (cad.numFaces() == 0) throw CadError(cad.sourceName() + " has no solid and no face" + hint);
  for (int f = 1; f <= cad.numFaces(); ++f)
    if (!cad.isPlanar(f))
      throw CadError(cad.sourceName() + " has no solid and " + cadEntityName(2, f) +
                     " is not planar" + hint);
  const auto [origin, n] = cad.plane(1);
  const double tol = 1e-7 * cad.boundingDiagonal();
  for (int f = 2; f <= cad.numFaces(); ++f) {
    const auto [o, m] = cad.plane(f);
    if (std::abs(n.dot(m)) < 1.0 - 1e-9 || std::abs(n.dot(o - origin)) > tol)
      throw CadError(cad.sourceName() + " has no solid and its faces are not in one plane (" +
                     cadEntityName(2, f) + " is not in the plane of Face1)" + hint);
  }
  normal = n;
  return 2;
}

}  // namespace homesh
