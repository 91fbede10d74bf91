#include "sizing/automatic_min_delta.hpp"

#include <algorithm>
#include <string>

#include "core/format.hpp"

namespace homesh {

namespace {

// What made a sample's size: its curvature, a thin wall, a narrow face (boundary_sampling.hpp,
// wall_thickness.hpp, narrow_face.hpp), with the CAD entity it lies on.
std::string describeSample(const BoundarySample& s, const SizingParameters& params, int dim) {
  const bool onFace = dim == 3 && !s.outward.isZero();
  std::string entity = (onFace ? "face " : "curve ") + std::to_string(s.cadIndex);
  if (s.narrowFace) return "a narrow face along " + entity;
  if (!(s.curvature > 0.0)) return entity;
  const double radius = 1.0 / s.curvature;
  if (s.delta < chordSize(radius, params.eps) * (1.0 - 1e-9)) return "a thin wall at " + entity;
  return "curvature radius " + formatNumber(radius) + " of " + entity;
}

}  // namespace

double samplingMinDelta(const SizingParameters& params) {
  return params.minDelta > 0.0 ? params.minDelta : kMinDeltaFloor * params.maxDelta;
}

void resolveAutomaticMinDelta(std::vector<BoundarySample>& samples, SizingParameters& params,
                              int dim) {
  if (params.minDelta > 0.0) return;
  const double floor = kMinDeltaFloor * params.maxDelta;
  const double ceiling = kMinDeltaCeiling * params.maxDelta;
  const BoundarySample* smallest = nullptr;
  for (const BoundarySample& s : samples)
    if (s.delta > 0.0 && (smallest == nullptr || s.delta < smallest->delta)) smallest = &s;
  if (smallest == nullptr || smallest->delta >= ceiling) {
    params.minDelta = ceiling;
    params.minDeltaSetBy = "MaxDelta / 20 (no boundary asks for less)";
  } else if (smallest->delta > floor) {
    params.minDelta = smallest->delta;
    params.minDeltaSetBy = describeSample(*smallest, params, dim);
  } else {
    params.minDelta = floor;
    // (The sample's own size was raised to the floor when it was taken: it asks for less.)
    params.minDeltaSetBy =
        "MaxDelta / 200, the floor (" + describeSample(*smallest, params, dim) + " asks for less)";
  }
  for (BoundarySample& s : samples)
    if (s.delta > 0.0) s.delta = std::max(s.delta, params.minDelta);
}

}  // namespace homesh
