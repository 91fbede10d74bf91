// What the user asks of the automatic mesh sizing (DESIGN.md section 2).
//
// The sizing field delta(x) is the target edge length at x: curvature-driven near the CAD
// (the chord of a circle of radius R = 1/max|k| whose sagitta is EPS * R), graded away from it by
// at most `gradation` per unit distance, clamped to [minDelta, maxDelta], and refined further by
// the user's sources. Where a curved wall is thin, the sagitta is bounded by thinWall times the
// wall's local thickness t as well: the size there is the chord whose sagitta is
// min(eps R, thinWall t), at least a third of the curvature size (sizing/wall_thickness.hpp).
#pragma once

#include <string>
#include <vector>

#include "core/parameters.hpp"
#include "sizing/refinement_source.hpp"

namespace homesh {

struct SizingParameters {
  // 0 for minDelta or maxDelta: automatic. An automatic maxDelta is a twentieth of the CAD's
  // bounding-box diagonal (completeSizing in pipeline/mesh_pipeline.hpp); an automatic minDelta
  // is what the shape itself asks for, found by the sizing octree from its samples (the
  // smallest size curvature, a thin wall or a narrow face asks for), at most maxDelta / 20.
  double minDelta = 0.0;  // smallest size curvature may ask for (> 0)
  double maxDelta = 0.0;  // size far from curved boundaries (>= minDelta)
  // What set each size, for the report: empty when given; filled in where an automatic one is
  // resolved ("bounding-box diagonal / 20", "curvature radius 1 of face 3", ...).
  std::string minDeltaSetBy, maxDeltaSetBy;
  double eps = parameterDefault("eps");  // sagitta over the radius of curvature
  double gradation = 0.2;                // largest |d delta / d x| (> 0)
  // Sagitta at most this fraction of the wall's local thickness, in [0, 1]; 0: no such bound
  // (NekMesh's sizing, which a .mcf case keeps). 0.1: on OpenCASCADE's bottle (a 0.6 mm wall
  // with fillets of radius 2.5 mm) the curvature size alone left six elements spanning the
  // wall folded after curving and repair; with the bound none (bench/results/corpus.md).
  double thinWall = 0.1;
  // Sagitta at most this fraction of the width of the faces a curved edge bounds, in [0, 1]; 0:
  // no such bound (a .mcf case keeps NekMesh's sizing). On OpenCASCADE's Motor-c, a ledge 0.05
  // wide along a circle of radius 20 held 71 of the 168 invalid elements left after 3 optimiser
  // sweeps with the curvature size alone, and 2 of 94 with the bound (sizing/narrow_face.hpp).
  double narrowFace = 0.25;
  std::vector<RefinementSource> sources;

  // Throws ParameterError naming the offending parameter.
  void validate() const;
};

// The curvature-to-size rule: delta = 2 R sqrt(eps (2 - eps)) for radius of curvature R.
double chordSize(double radius, double eps);

}  // namespace homesh
