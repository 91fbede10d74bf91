#include "sizing/element_count.hpp"
#include "core/thread_count.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "core/first_failure.hpp"
#include "sizing/sizing_octree.hpp"

namespace homesh {
namespace {

// The densities of the model in element_count.hpp for Gmsh 4.8 (3D: Delaunay with its default
// optimisation; 2D: Frontal-Delaunay) driven by our size callback. Fitted by least squares with
// `bench_sizing_prediction --calibrate [--gradient-term]` on cases that are not the NekMesh
// peer cases the acceptance checks (bench/README.md lists them):
//  - 3D, uniform sizes on tests/data/sphere.brep, box_hole.step and examples/bracket.step
//    (1 200 to 41 000 tets, fitted/actual 0.97 to 1.03). The gradient term is not significant
//    in 3D on the graded cases we have (its fit is small and changes sign), so it is left out.
//  - 2D, uniform and graded sizes on the peer aerofoil and T106 geometries with parameters other
//    than the peer cases' (fitted/actual 0.98 to 1.02); a regular triangle gives 4/sqrt(3) = 2.31.
constexpr double kVolumeDensity3 = 4.14;
constexpr double kBoundaryDensity3 = 1.33;
constexpr double kGradientDensity3 = 0.0;
constexpr double kAreaDensity2 = 2.309;
constexpr double kBoundaryDensity2 = 0.465;
constexpr double kGradientDensity2 = 1.41;

// A surface mesh's triangles: the 2D area density over the faces, integrated with the face
// samples' areas (the faces are the domain; no volume, and no boundary term fitted for it).
ElementCountPrediction predictSurfaceTriangles(const SizingOctree& tree) {
  ElementCountPrediction out;
  out.dim = 2;
  double area = 0.0, integral = 0.0;
  for (const BoundarySample& s : tree.samples()) {
    if (s.outward.isZero()) continue;  // a curve's size-only sample
    const double h = tree.delta(s.x);
    area += s.weight;
    integral += s.weight / (h * h);
  }
  out.domainMeasure = area;
  out.volumeIntegral = integral;
  out.elements = kAreaDensity2 * integral;
  return out;
}

}  // namespace

ElementCountPrediction predictElementCount(const SizingOctree& tree, int threads) {
  if (tree.surface()) return predictSurfaceTriangles(tree);
  ElementCountPrediction out;
  out.dim = tree.dim();
  const int d = out.dim;
  // One pass over the leaves for both domain integrals.
  double volume = 0.0, gradient = 0.0;
  const auto leaves = static_cast<std::int64_t>(tree.numLeaves());
  const bool withGradient = (d == 3 ? kGradientDensity3 : kGradientDensity2) != 0.0;
  FirstFailure failure;  // an allocation failure must not leave the parallel region
#pragma omp parallel num_threads(threadsToUse(threads)) reduction(+ : volume, gradient)
  {
    std::vector<SizingOctree::QuadraturePoint> points;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t i = 0; i < leaves; ++i) {
      try {
        tree.leafQuadrature(static_cast<std::size_t>(i), points, withGradient);
      } catch (...) {
        failure.capture();
        continue;
      }
      for (const SizingOctree::QuadraturePoint& q : points) {
        const double h = tree.delta(q.x);
        const double density = q.weight / (d == 3 ? h * h * h : h * h);
        volume += density;
        gradient += density * q.gradient;
      }
    }
  }
  failure.rethrow();
  out.volumeIntegral = volume;
  out.gradientIntegral = gradient;
  out.domainMeasure = tree.domainMeasure();
  const std::vector<BoundarySample>& samples = tree.samples();
  double boundary = 0.0;
#pragma omp parallel for num_threads(threadsToUse(threads)) reduction(+ : boundary) schedule(static)
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(samples.size()); ++i) {
    const BoundarySample& s = samples[static_cast<std::size_t>(i)];
    const double h = tree.delta(s.x);
    boundary += (s.internal ? 2.0 : 1.0) * s.weight / (d == 3 ? h * h : h);
  }
  out.boundaryIntegral = boundary;
  out.elements =
      d == 3
          ? kVolumeDensity3 * volume + kBoundaryDensity3 * boundary + kGradientDensity3 * gradient
          : kAreaDensity2 * volume + kBoundaryDensity2 * boundary + kGradientDensity2 * gradient;
  return out;
}

}  // namespace homesh
