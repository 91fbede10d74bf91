#include "optimise/stop_rules.hpp"

#include <algorithm>
#include <cmath>

namespace homesh::optimiser {

namespace {

bool provenValid(const IterationRecord& r) {
  return r.invalid + r.undecided == 0;
}

}  // namespace

double energyFall(const IterationRecord& r, const IterationRecord& previous) {
  return (previous.energy - r.energy) / std::max(std::abs(r.energy), 1e-300);
}

bool displacementRule(const IterationRecord& r, const OptimiserOptions& options) {
  return r.maxRelativeMove <= options.tolerance;
}

bool energyRule(const IterationRecord& r, const IterationRecord& previous,
                const OptimiserOptions& options) {
  // In stall mode a sweep that still raises the worst is progress, however little the energy
  // falls (most nodes rest around a mesh that is good elsewhere).
  if (options.stall > 0.0 && r.worst - previous.worst >= options.stall) return false;
  return provenValid(r) && energyFall(r, previous) < options.energyTolerance;
}

bool stalledRule(const std::vector<IterationRecord>& history, const IterationRecord& previous,
                 const IterationRecord& input, const OptimiserOptions& options) {
  const IterationRecord& r = history.back();
  if (!(options.stall > 0.0 && provenValid(r) && energyFall(r, previous) < options.stallEnergy))
    return false;
  const auto n = static_cast<int>(history.size());  // r is the last entry
  // The lowest worst of the state before the window and the window's earlier sweeps: the
  // last sweep measured against it, not only against the state before, so that climbing
  // back from a dip inside the window (a sweep that lowers the worst while it lowers the
  // energy elsewhere) is not a stall.
  double low = n > options.stallWindow ? history[n - 1 - options.stallWindow].worst : input.worst;
  for (int k = std::max(0, n - options.stallWindow); k < n - 1; ++k)
    low = std::min(low, history[k].worst);
  return n >= options.stallWindow && r.worst - low < options.stall;
}

bool stuckRule(const std::vector<IterationRecord>& history, const IterationRecord& previous,
               const OptimiserOptions& options) {
  const IterationRecord& r = history.back();
  if (!(options.stall > 0.0 && !provenValid(r) && energyFall(r, previous) < options.stallEnergy))
    return false;
  // Invalid and stuck: over the last stuckWindow sweeps no element became proven valid and the
  // worst value did not rise by `stall`; what is left is for a repair round, not more sweeps.
  const auto n = static_cast<int>(history.size());
  if (n <= options.stuckWindow) return false;
  const IterationRecord& then = history[n - 1 - options.stuckWindow];
  return r.invalid + r.undecided >= then.invalid + then.undecided &&
         r.worst - then.worst < options.stall;
}

std::string stopRule(const std::vector<IterationRecord>& history, const IterationRecord& previous,
                     const IterationRecord& input, const OptimiserOptions& options) {
  const IterationRecord& r = history.back();
  if (displacementRule(r, options)) return stop::kDisplacement;
  if (energyRule(r, previous, options)) return stop::kEnergy;
  if (stalledRule(history, previous, input, options)) return stop::kStalled;
  if (stuckRule(history, previous, options)) return stop::kStuck;
  return "";
}

bool acceptable(const IterationRecord& r, const IterationRecord& input) {
  return r.invalid <= input.invalid && r.worst >= input.worst;
}

bool better(const IterationRecord& r, const IterationRecord& than) {
  const std::size_t a = r.invalid + r.undecided, b = than.invalid + than.undecided;
  if (a != b) return a < b;
  if (r.worst != than.worst) return r.worst > than.worst;
  return r.energy < than.energy;
}

}  // namespace homesh::optimiser
