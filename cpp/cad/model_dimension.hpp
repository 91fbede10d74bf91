// Which kind of mesh a CAD model gets: volumes for a model with solids, triangles for a model
// made only of planar faces in one plane.
#pragma once

#include <Eigen/Core>

namespace homesh {

class CadModel;

// 3 for a model with solids; 2 for planar faces in one plane (and then `normal` is the plane's
// unit normal, oriented like Face1). Throws CadError naming the face that prevents either.
int modelMeshDimension(const CadModel& cad, Eigen::Vector3d& normal);

}  // namespace homesh
