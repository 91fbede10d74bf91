// How closely a curved mesh's boundary follows its CAD model.
//
// Every boundary cell on a CAD entity is sampled at the quadrature points of its own element
// map (a rule of degree 2P + 2, the one the boundary quality measures use) and at its nodes:
//   - 3D: triangles and quadrilaterals on CAD faces (distance and normal angle), lines on CAD
//     curves (distance);
//   - 2D: lines on CAD curves (distance, and the angle between the mesh edge's tangent and the
//     curve's tangent, which is the angle between their normals in the mesh plane).
// Each sample point x(xi) is projected onto its entity, starting from the parameters of the
// cell's node nearest to xi in reference coordinates (CadModel checks the local result against
// its global search, see cad_model.hpp); the distance is |x - projection|. The angle compares
// the mesh normal x_xi1 x x_xi2 with the CAD normal S_u x S_v at the projected parameters,
// unsigned (atan2(|n x m|, |n . m|), accurate for tiny angles too). Points where the CAD normal
// is undefined (S_u x S_v below 1e-8 of max |S_u|^2, |S_v|^2: a sphere's pole) or the curve's
// tangent is (|C'| below 1e-3 of the curve's typical speed: an aerofoil's cosine-spaced
// trailing edge) are skipped for the angle and counted; a point where the mesh map itself
// degenerates (zero tangent) counts as 90 degrees.
//
// The result does not depend on the number of threads.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "core/parameters.hpp"

namespace homesh {

struct GeometryAccuracy {
  std::size_t samples = 0;           // points whose distance was measured
  std::size_t angleSamples = 0;      // of which the angle was measured too
  std::size_t undefinedNormals = 0;  // face (2D: curve) points with no CAD normal (tangent)
  double diagonal = 0.0;             // the model's bounding-box diagonal
  double maxDistance = 0.0;
  double meanDistance = 0.0;
  double maxAngleDeg = 0.0;   // mesh normal against CAD normal, degrees
  double meanAngleDeg = 0.0;  // over angleSamples
  // Where the largest distance and the largest angle were found: the CAD entity ("Face3",
  // "Edge7"; empty when nothing was sampled) and the sample point.
  std::string worstEntity;
  Eigen::Vector3d worstPoint = Eigen::Vector3d::Zero();
  std::string worstAngleEntity;
  Eigen::Vector3d worstAnglePoint = Eigen::Vector3d::Zero();

  double maxDistanceRelative() const { return diagonal > 0.0 ? maxDistance / diagonal : 0.0; }
  double meanDistanceRelative() const { return diagonal > 0.0 ? meanDistance / diagonal : 0.0; }
};

// Samples the boundary cells of `mesh` (made from `cad`: boundary cells record their CAD face or
// curve in ElementBlock::entity, nodes their parameters) on `threads` threads.
// Throws Error when a boundary cell names an entity the model does not have, CadError when the
// CAD cannot be evaluated.
GeometryAccuracy measureGeometryAccuracy(const Mesh& mesh, const CadModel& cad,
                                         int threads = defaultOf<int>("threads"));

}  // namespace homesh
