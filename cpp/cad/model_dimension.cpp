#include "cad/model_dimension.hpp"

#include <cmath>
#include <string>

#include "cad/cad_model.hpp"
#include "core/error.hpp"

namespace homesh {

int modelMeshDimension(const CadModel& cad, Eigen::Vector3d& normal) {
  if (cad.numSolids() > 0) return 3;
  if (cad.numFaces() == 0)
    throw CadError(cad.sourceName() +
                   " has no solid and no face: HOMesh meshes solids, planar faces in one plane "
                   "(2D) or faces (a surface mesh)");
  normal = Eigen::Vector3d::Zero();
  for (int f = 1; f <= cad.numFaces(); ++f)
    if (!cad.isPlanar(f)) return 2;
  const auto [origin, n] = cad.plane(1);
  const double tol = 1e-7 * cad.boundingDiagonal();
  for (int f = 2; f <= cad.numFaces(); ++f) {
    const auto [o, m] = cad.plane(f);
    if (std::abs(n.dot(m)) < 1.0 - 1e-9 || std::abs(n.dot(o - origin)) > tol) return 2;
  }
  normal = n;
  return 2;
}

bool isSurfaceModel(const CadModel& cad) {
  if (cad.numSolids() > 0 || cad.numFaces() == 0) return false;
  Eigen::Vector3d normal;
  modelMeshDimension(cad, normal);
  return normal.isZero();
}

}  // namespace homesh
