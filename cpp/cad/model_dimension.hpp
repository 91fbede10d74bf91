// Which kind of mesh a CAD model gets: volumes for a model with solids; triangles for a model
// of faces alone, in their plane when they are all planar and in one plane (a 2D case), else on
// the curved faces themselves (a surface mesh).
#pragma once

#include <Eigen/Core>

namespace homesh {

class CadModel;

// 3 for a model with solids; 2 for a model of faces and no solid: `normal` is then the unit
// normal of their plane (oriented like Face1) when every face is planar and in one plane, and
// zero when they are not (a surface mesh: Mesh::isSurface). Throws CadError for a model with
// neither solid nor face.
int modelMeshDimension(const CadModel& cad, Eigen::Vector3d& normal);

// Whether `cad` gets a surface mesh: faces and no solid, not all in one plane.
bool isSurfaceModel(const CadModel& cad);

}  // namespace homesh
