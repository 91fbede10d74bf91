// An automatic MinDelta (SizingParameters::minDelta 0) from the shape's own scales.
//
// MaxDelta / 20 alone fails on slender shapes: a cylinder of radius 1 and length 1000 has
// MaxDelta 50 and MinDelta 2.5, wider than its circle, and Gmsh then spends its whole time limit
// on a surface it cannot mesh at that size. Instead the boundary is sampled with MinDelta at a
// floor (kMinDeltaFloor of MaxDelta), so that every size curvature, a thin wall or a narrow face
// asks for down to the floor is seen, and MinDelta is the smallest of them: at most MaxDelta / 20
// (where no boundary asks for less, the sizes are what they were) and at least the floor. The
// cylinder gets its circle's curvature size, 0.62, about 2.5 elements per quarter turn at the
// default EPS. The floor keeps a needle's tip or a tiny fillet from asking for sizes no octree
// holds: Part.makeCone(0.01, 0, 100), every point of whose side has a radius of curvature below
// 0.01, needs more than the octree's 10^7 cells at MaxDelta / 500 and 9,700 elements at the
// floor, MaxDelta / 200. The octree's cell limit and the element limit bound it further
// (pipeline/mesh_pipeline.cpp, runSizing).
#pragma once

#include <vector>

#include "sizing/boundary_sampling.hpp"
#include "sizing/sizing_parameters.hpp"

namespace homesh {

inline constexpr double kMinDeltaFloor = 1.0 / 200.0;   // of MaxDelta
inline constexpr double kMinDeltaCeiling = 1.0 / 20.0;  // of MaxDelta (the rule before)

// The MinDelta to sample an automatic one with (the floor); `params.minDelta` when given.
double samplingMinDelta(const SizingParameters& params);

// For an automatic MinDelta (0 in `params`): sets params.minDelta to the smallest size of
// `samples` (taken with samplingMinDelta), within [floor, ceiling], and params.minDeltaSetBy to
// what asked for it (naming the CAD face or curve); the samples' sizes are raised to it. `dim`:
// the model's mesh dimension (in 2D every sample lies on a curve). Does nothing to a given one.
void resolveAutomaticMinDelta(std::vector<BoundarySample>& samples, SizingParameters& params,
                              int dim);

}  // namespace homesh
