#include "curving/spring_energy.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace homesh {
namespace {

struct Evaluation {
  std::vector<MappedPoint> points;
  double energy = 0.0;
};

Evaluation evaluate(const SpringSystem& s, const std::vector<double>& params,
                    const ParameterMap& map) {
  Evaluation e;
  e.points.resize(static_cast<std::size_t>(s.numNodes()));
  for (int i = 0; i < s.numNodes(); ++i) {
    if (s.fixed[i] != 0 && !s.pinned.empty()) {
      e.points[i].point = s.pinned[i];
      e.points[i].jacobian.setZero();
    } else {
      e.points[i] =
          map(&params[static_cast<std::size_t>(s.paramDim) * static_cast<std::size_t>(i)]);
    }
  }
  for (const Spring& sp : s.springs)
    e.energy += sp.weight * (e.points[sp.a].point - e.points[sp.b].point).squaredNorm();
  return e;
}

}  // namespace

SpringResult minimiseSprings(SpringSystem& s, const ParameterMap& map, int maxIterations) {
  const int k = s.paramDim;
  const auto n = static_cast<std::size_t>(s.numNodes());
  if ((k != 1 && k != 2) || s.params.size() != k * n ||
      (!s.pinned.empty() && s.pinned.size() != n) ||
      (!s.lower.empty() && (s.lower.size() != k * n || s.upper.size() != k * n)))
    throw Error("spring system: inconsistent sizes (" + std::to_string(n) + " nodes, " +
                std::to_string(s.params.size()) + " parameters)");
  for (const Spring& sp : s.springs)
    if (sp.a < 0 || sp.b < 0 || sp.a >= s.numNodes() || sp.b >= s.numNodes())
      throw Error("spring system: a spring refers to a missing node");

  // Free parameter j of the solve <-> node free[j / k], component j % k.
  std::vector<int> slot(n, -1), free;
  for (std::size_t i = 0; i < n; ++i)
    if (s.fixed[i] == 0) {
      slot[i] = static_cast<int>(free.size());
      free.push_back(static_cast<int>(i));
    }
  Evaluation current = evaluate(s, s.params, map);
  SpringResult result{current.energy, current.energy, 0};
  if (free.empty()) return result;

  const int m = k * static_cast<int>(free.size());
  double lambda = 1e-3;
  for (int it = 0; it < maxIterations; ++it) {
    result.iterations = it + 1;
    Eigen::VectorXd g = Eigen::VectorXd::Zero(m);
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(m, m);
    for (const Spring& sp : s.springs) {
      const MappedPoint& pa = current.points[sp.a];
      const MappedPoint& pb = current.points[sp.b];
      const Eigen::Vector3d d = pa.point - pb.point;
      const int ends[2] = {sp.a, sp.b};
      const double sign[2] = {1.0, -1.0};
      const MappedPoint* mp[2] = {&pa, &pb};
      for (int x = 0; x < 2; ++x) {
        if (slot[ends[x]] < 0) continue;
        const int rx = k * slot[ends[x]];
        const auto jx = mp[x]->jacobian.leftCols(k);
        g.segment(rx, k) += 2.0 * sp.weight * sign[x] * jx.transpose() * d;
        for (int y = 0; y < 2; ++y) {
          if (slot[ends[y]] < 0) continue;
          const int ry = k * slot[ends[y]];
          const auto jy = mp[y]->jacobian.leftCols(k);
          h.block(rx, ry, k, k) += 2.0 * sp.weight * sign[x] * sign[y] * jx.transpose() * jy;
        }
      }
    }
    if (!g.allFinite() || !h.allFinite() || g.norm() == 0.0) break;
    // Damping scaled by the curvature of each unknown; the floor keeps a singular direction
    // (a node at a pole moving in u) solvable.
    const double floor = 1e-12 * std::max(h.diagonal().maxCoeff(), 1e-300);
    bool accepted = false;
    while (!accepted && lambda < 1e12) {
      Eigen::MatrixXd a = h;
      for (int j = 0; j < m; ++j) a(j, j) += lambda * h(j, j) + floor;
      const Eigen::VectorXd step = a.ldlt().solve(-g);
      if (!step.allFinite()) {
        lambda *= 10.0;
        continue;
      }
      std::vector<double> trial = s.params;
      for (int j = 0; j < m; ++j) {
        const auto p = static_cast<std::size_t>(k) * static_cast<std::size_t>(free[j / k]) +
                       static_cast<std::size_t>(j % k);
        trial[p] += step[j];
        if (!s.lower.empty()) trial[p] = std::clamp(trial[p], s.lower[p], s.upper[p]);
      }
      Evaluation next;
      try {
        next = evaluate(s, trial, map);
      } catch (const Error&) {  // the parametrisation cannot be evaluated there: a shorter step
        lambda *= 10.0;
        continue;
      }
      if (std::isfinite(next.energy) && next.energy < current.energy) {
        const double gain = current.energy - next.energy;
        s.params = std::move(trial);
        current = std::move(next);
        lambda = std::max(lambda * 0.3, 1e-9);
        accepted = true;
        // Converged when a step gains nothing that rounding could not explain.
        if (gain <= 1e-14 * current.energy) {
          result.finalEnergy = current.energy;
          return result;
        }
      } else {
        lambda *= 10.0;
      }
    }
    if (!accepted) break;
  }
  result.finalEnergy = current.energy;
  return result;
}

}  // namespace homesh
