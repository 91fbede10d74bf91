#include "sizing/wall_thickness.hpp"
#include "core/thread_count.hpp"
#include "sizing/sample_tree.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

namespace homesh {
namespace {

constexpr double kConeTangent = 0.57735026918962576;  // tan(30 degrees)
constexpr double kFacingCosine = 0.5;                 // cos(60 degrees)
// The bound makes a sample's size at most this many times smaller. Where a wall thins out to
// nothing (a surface of revolution pinched at its axis, a knife edge) it would otherwise ask
// for MinDelta all along: Gmsh's revolve.step demo went from 6,524 predicted tetrahedra to
// 886,224; with 3, 3.1x the elements of no bound at most on such a face, which meshes it.
constexpr double kMaxThinRefinement = 3.0;

bool isWall(const BoundarySample& s) {
  return !s.internal && s.outward.squaredNorm() > 0.0;
}

}  // namespace

std::vector<double> wallThickness(const std::vector<BoundarySample>& samples,
                                  const std::vector<double>& reach, int threads) {
  const double none = std::numeric_limits<double>::infinity();
  std::vector<double> thickness(samples.size(), none);
  const SampleTree tree(samples, isWall);
  const auto count = static_cast<std::int64_t>(samples.size());
#pragma omp parallel for schedule(dynamic, 256) num_threads(threadsToUse(threads))
  for (std::int64_t i = 0; i < count; ++i) {
    const BoundarySample& p = samples[static_cast<std::size_t>(i)];
    const double limit = reach[static_cast<std::size_t>(i)];
    if (!isWall(p) || !(limit > 0.0)) continue;
    const Eigen::Vector3d n = -p.outward.normalized();
    double best = none;
    // A sample q the cone accepts (a <= limit, lateral <= a tan 30 + half q's spacing) lies
    // within limit / cos(30) + half q's spacing of p: the patches within limit / cos(30).
    tree.nearPatches(p.x, 1.1547005383792515 * limit, [&](std::int32_t j) {
      const BoundarySample& q = samples[static_cast<std::size_t>(j)];
      const Eigen::Vector3d d = q.x - p.x;
      const double a = d.dot(n);
      if (!(a > 0.0) || a > limit || a >= best) return;
      if (q.outward.dot(n) < kFacingCosine * q.outward.norm()) return;
      const double lateral = (d - a * n).norm();
      if (lateral > kConeTangent * a + 0.5 * q.spacing) return;
      best = a;
    });
    thickness[static_cast<std::size_t>(i)] = best;
  }
  return thickness;
}

std::size_t applyThinWallSizes(std::vector<BoundarySample>& samples, const SizingParameters& params,
                               int threads) {
  if (!(params.thinWall > 0.0)) return 0;
  const double gamma = params.thinWall;
  // The bound is below the curvature's where thinWall t < eps R, and below maxDelta where
  // (the chord's sagitta being about c^2 / (8 R)) thinWall t < maxDelta^2 / (8 R); 10 % more
  // covers the approximation. Only the search stops there: sizes are compared exactly below.
  std::vector<double> reach(samples.size(), 0.0);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double k = samples[i].curvature;
    if (!(k > 0.0) || !isWall(samples[i])) continue;
    const double radius = 1.0 / k;
    reach[i] = 1.1 / gamma *
               std::min(params.eps * radius, params.maxDelta * params.maxDelta / (8.0 * radius));
  }
  const std::vector<double> thickness = wallThickness(samples, reach, threads);
  std::size_t limited = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(thickness[i])) continue;
    BoundarySample& s = samples[i];
    const double radius = 1.0 / s.curvature;
    const double size = chordSize(radius, std::min(1.0, gamma * thickness[i] / radius));
    const double current = s.delta > 0.0 ? s.delta : params.maxDelta;
    if (!(size < current)) continue;
    s.delta = std::max({size, current / kMaxThinRefinement, params.minDelta});
    if (s.delta < current) ++limited;
  }
  return limited;
}

}  // namespace homesh
