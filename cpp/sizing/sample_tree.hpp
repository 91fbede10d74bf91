// A static k-d tree over some of a model's boundary samples, for the searches that look for
// the boundary near a point (a wall's far side, the distance to the nearest wall). Nodes split
// at the median of their widest axis; radius queries visit the leaves whose boxes the query
// ball reaches.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "sizing/boundary_sampling.hpp"

namespace homesh {

class SampleTree {
 public:
  // Holds the samples `keep` accepts; `samples` must outlive the tree.
  template <class Keep>
  SampleTree(const std::vector<BoundarySample>& samples, Keep&& keep) : samples_(samples) {
    for (std::size_t i = 0; i < samples.size(); ++i)
      if (keep(samples[i])) order_.push_back(static_cast<std::int32_t>(i));
    if (!order_.empty()) build(0, order_.size());
  }

  bool empty() const { return order_.empty(); }

  // Calls visit(j) for every held sample j whose patch (a disc of half its spacing) may reach
  // within `radius` of x: those within radius + half their own spacing, and perhaps a few
  // beyond. Widening `radius` by the coarsest spacing of all instead would visit every fine
  // sample near a coarse one (93 % of a swept wing's `homesh predict` went there).
  template <class Visit>
  void nearPatches(const Eigen::Vector3d& x, double radius, Visit&& visit) const {
    if (!nodes_.empty()) query(0, x, radius, visit);
  }

  // Whether test(j) holds for a held sample j whose patch may reach within `radius` of x (as
  // nearPatches); stops at the first, searching the nearer half of each split first.
  template <class Test>
  bool anyPatch(const Eigen::Vector3d& x, double radius, Test&& test) const {
    return !nodes_.empty() && find(0, x, radius, test);
  }

  // The smallest distance(j) over the held samples whose patch may lie nearer than `cap`, or
  // `cap` when none does; distance(j) must be at least |x - x_j| - half j's spacing.
  template <class Distance>
  double nearestPatch(const Eigen::Vector3d& x, double cap, Distance&& distance) const {
    double best = cap;
    if (!nodes_.empty()) nearest(0, x, best, distance);
    return best;
  }

 private:
  static constexpr int kLeafSize = 16;

  template <class Distance>
  void nearest(std::int32_t i, const Eigen::Vector3d& x, double& best, Distance& distance) const {
    const Node& node = nodes_[i];
    if (gapSquared(node, x) >= square(best + 0.5 * node.spacing)) return;
    if (node.left < 0) {
      for (std::size_t k = node.begin; k < node.end; ++k)
        best = std::min(best, distance(order_[k]));
      return;
    }
    const bool leftFirst = gapSquared(nodes_[node.left], x) <= gapSquared(nodes_[node.right], x);
    nearest(leftFirst ? node.left : node.right, x, best, distance);
    nearest(leftFirst ? node.right : node.left, x, best, distance);
  }

  struct Node {
    Eigen::Vector3d lo, hi;  // box of its samples
    double spacing = 0.0;    // the largest spacing of its samples
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
      node.spacing = std::max(node.spacing, samples_[order_[k]].spacing);
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

  template <class Test>
  bool find(std::int32_t i, const Eigen::Vector3d& x, double radius, Test& test) const {
    const Node& node = nodes_[i];
    if (gapSquared(node, x) > square(radius + 0.5 * node.spacing)) return false;
    if (node.left < 0) {
      for (std::size_t k = node.begin; k < node.end; ++k)
        if (test(order_[k])) return true;
      return false;
    }
    const bool leftFirst = gapSquared(nodes_[node.left], x) <= gapSquared(nodes_[node.right], x);
    const std::int32_t first = leftFirst ? node.left : node.right;
    const std::int32_t second = leftFirst ? node.right : node.left;
    return find(first, x, radius, test) || find(second, x, radius, test);
  }

  static double square(double v) { return v * v; }

  // Squared distance from x to the node's box (0 inside).
  static double gapSquared(const Node& node, const Eigen::Vector3d& x) {
    return (node.lo - x).cwiseMax(x - node.hi).cwiseMax(Eigen::Vector3d::Zero()).squaredNorm();
  }

  // Visits the samples of the leaves within radius + half their largest spacing.
  template <class Visit>
  void query(std::int32_t i, const Eigen::Vector3d& x, double radius, Visit& visit) const {
    const Node& node = nodes_[i];
    if (gapSquared(node, x) > square(radius + 0.5 * node.spacing)) return;
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

}  // namespace homesh
