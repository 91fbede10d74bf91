#include "sizing/wall_thickness.hpp"
#include "core/thread_count.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

namespace homesh {
namespace {

constexpr double kConeTangent = 0.57735026918962576;  // tan(30 degrees)
constexpr double kFacingCosine = 0.5;                 // cos(60 degrees)
constexpr int kLeafSize = 16;
// The bound makes a sample's size at most this many times smaller. Where a wall thins out to
// nothing (a surface of revolution pinched at its axis, a knife edge) it would otherwise ask
// for MinDelta all along: Gmsh's revolve.step demo went from 6,524 predicted tetrahedra to
// 886,224; with 3, 3.1x the elements of no bound at most on such a face, which meshes it.
constexpr double kMaxThinRefinement = 3.0;

bool isWall(const BoundarySample& s) {
  return !s.internal && s.outward.squaredNorm() > 0.0;
}

// A static k-d tree over the wall samples: nodes split at the median of their widest axis;
// radius queries visit the leaves whose boxes the query ball reaches.
class SampleTree {
 public:
  explicit SampleTree(const std::vector<BoundarySample>& samples) : samples_(samples) {
    for (std::size_t i = 0; i < samples.size(); ++i)
      if (isWall(samples[i])) order_.push_back(static_cast<std::int32_t>(i));
    if (!order_.empty()) build(0, order_.size());
  }

  // Calls visit(j) for every wall sample j within `radius` of x (and perhaps a few beyond).
  template <class Visit>
  void near(const Eigen::Vector3d& x, double radius, Visit&& visit) const {
    if (!nodes_.empty()) query(0, x, radius, visit);
  }

 private:
  struct Node {
    Eigen::Vector3d lo, hi;  // box of its samples
    std::size_t begin = 0, end = 0;
    std::int32_t left = -1, right = -1;  // children; -1: a leaf
  };

  std::int32_t build(std::size_t begin, std::size_t end) {
    Node node;
    node.begin = begin;
    node.end = end;
    node.lo = node.hi = samples_[order_[begin]].x;
    for (std::size_t k = begin; k < end; ++k) {
      node.lo = node.lo.cwiseMin(samples_[order_[k]].x);
      node.hi = node.hi.cwiseMax(samples_[order_[k]].x);
    }
    const auto index = static_cast<std::int32_t>(nodes_.size());
    nodes_.push_back(node);
    if (end - begin <= static_cast<std::size_t>(kLeafSize)) return index;
    int axis = 0;
    (node.hi - node.lo).maxCoeff(&axis);
    const std::size_t mid = begin + (end - begin) / 2;
    std::nth_element(
        order_.begin() + static_cast<std::ptrdiff_t>(begin),
        order_.begin() + static_cast<std::ptrdiff_t>(mid),
        order_.begin() + static_cast<std::ptrdiff_t>(end),
        [&](std::int32_t a, std::int32_t b) { return samples_[a].x[axis] < samples_[b].x[axis]; });
    const std::int32_t left = build(begin, mid);
    const std::int32_t right = build(mid, end);
    nodes_[index].left = left;
    nodes_[index].right = right;
    return index;
  }

  template <class Visit>
  void query(std::int32_t i, const Eigen::Vector3d& x, double radius, Visit& visit) const {
    const Node& node = nodes_[i];
    const Eigen::Vector3d gap =
        (node.lo - x).cwiseMax(x - node.hi).cwiseMax(Eigen::Vector3d::Zero());
    if (gap.squaredNorm() > radius * radius) return;
    if (node.left < 0) {
      for (std::size_t k = node.begin; k < node.end; ++k) visit(order_[k]);
      return;
    }
    query(node.left, x, radius, visit);
    query(node.right, x, radius, visit);
  }

  const std::vector<BoundarySample>& samples_;
  std::vector<std::int32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace

std::vector<double> wallThickness(const std::vector<BoundarySample>& samples,
                                  const std::vector<double>& reach, int threads) {
  const double none = std::numeric_limits<double>::infinity();
  std::vector<double> thickness(samples.size(), none);
  const SampleTree tree(samples);
  double widest = 0.0;  // the coarsest spacing: how far a wall's point can be from its samples
  for (const BoundarySample& s : samples)
    if (isWall(s)) widest = std::max(widest, s.spacing);
  const auto count = static_cast<std::int64_t>(samples.size());
#pragma omp parallel for schedule(dynamic, 256) num_threads(threadsToUse(threads))
  for (std::int64_t i = 0; i < count; ++i) {
    const BoundarySample& p = samples[static_cast<std::size_t>(i)];
    const double limit = reach[static_cast<std::size_t>(i)];
    if (!isWall(p) || !(limit > 0.0)) continue;
    const Eigen::Vector3d n = -p.outward.normalized();
    double best = none;
    // A point of the cone with a <= limit lies within limit / cos(30) (+ the slack) of p.
    tree.near(p.x, 1.1547005383792515 * limit + 0.5 * widest, [&](std::int32_t j) {
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
