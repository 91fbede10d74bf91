// What the sizing octree learns from the CAD: points on the domain boundary with their outward
// normal, the boundary measure they stand for, and the size the curvature there asks for.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace homesh {

class CadModel;
struct SizingParameters;

struct BoundarySample {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  // Unit normal out of the domain (in the model's plane for a 2D model); zero for a sample that
  // only carries a size (a point of a curve of a 3D model).
  Eigen::Vector3d outward = Eigen::Vector3d::Zero();
  double weight = 0.0;     // area (3D) or length (2D) of the boundary the sample stands for
  double spacing = 0.0;    // distance to the neighbouring samples (at most)
  double delta = 0.0;      // size from curvature in [minDelta, maxDelta); 0 where flat enough
  double curvature = 0.0;  // largest absolute (principal) curvature there; 0 on a plane
  // Mean curvature against the outward normal: negative where the wall bends away from it (a
  // convex wall: a ball, a rod), positive where it bends towards it (a hole); 0 on a plane.
  double meanCurvature = 0.0;
  bool internal = false;    // on a face between two solids (a curve between two faces in 2D)
  bool narrowFace = false;  // delta bounded by the width of the curve's faces (narrow_face.hpp)
  int cadIndex = 0;         // the face (3D) or curve (2D); the curve for size-only samples
};

// Samples every face of a 3D model (every curve of a 2D one) on a parameter grid whose spacing
// is at most half of min(maxDelta, the smallest curvature size on that entity), at least 40 per
// direction on curved entities; points outside a trimmed face are skipped. In 3D the curves add
// size-only samples (a curve can bend more tightly than the faces it bounds), bounded where the
// faces the curve bounds are narrow (sizing/narrow_face.hpp; not with narrowFace 0).
// Throws CadError naming the entity OCCT cannot evaluate.
std::vector<BoundarySample> sampleBoundary(const CadModel& cad, int dim,
                                           const SizingParameters& params);

}  // namespace homesh
