#include "optimise/optimiser_options.hpp"

#include <cmath>

#include "core/error.hpp"

namespace homesh {

void OptimiserOptions::validate() const {
  checkParameter("optimise", maxIterations);
  checkParameter("tolerance", tolerance);
  checkParameter("optimise_seconds", timeLimit);
  if (threads != 0) checkParameter("threads", threads);  // 0: every core
  if (regionThreshold) checkParameter("region", *regionThreshold);
  checkParameter("region_layers", regionLayers);
  checkParameter("focus", focusPasses);
  checkParameter("facet_weight", facetWeight);
  checkParameter("fidelity_weight", fidelityWeight);
  // The internal rules' settings (not user-facing: no table rows).
  if (!(energyTolerance >= 0.0) || !std::isfinite(energyTolerance))
    throw ParameterError("energy tolerance must be a finite number >= 0");
  if (!(stall >= 0.0) || !std::isfinite(stall))
    throw ParameterError("stall must be a finite number >= 0");
  if (!(stallEnergy >= 0.0) || !std::isfinite(stallEnergy))
    throw ParameterError("stall energy must be a finite number >= 0");
  if (stallWindow < 1)
    throw ParameterError("stall window must be >= 1, got " + std::to_string(stallWindow));
  if (stuckWindow < 1)
    throw ParameterError("stuck window must be >= 1, got " + std::to_string(stuckWindow));
  if (!(activeTolerance >= 0.0) || !std::isfinite(activeTolerance))
    throw ParameterError("active tolerance must be a finite number >= 0");
  if (!(settledQuality >= 0.0) || !std::isfinite(settledQuality))
    throw ParameterError("settled quality must be a finite number >= 0");
  if (settledQuality <= 1.0 &&
      (!(settledTolerance >= activeTolerance) || !std::isfinite(settledTolerance) ||
       !(settledSlidingTolerance >= activeTolerance) || !std::isfinite(settledSlidingTolerance)))
    throw ParameterError("settled tolerances must be finite and at least the active tolerance");
  if (!(focusMargin >= 0.0) || !std::isfinite(focusMargin))
    throw ParameterError("focus margin must be a finite number >= 0");
}

namespace {

// Where each table key goes in OptimiserOptions, given its checked number.
const OptionSetters<OptimiserOptions>& setters() {
  static const OptionSetters<OptimiserOptions> table = {
      {"optimise", [](OptimiserOptions& o, double v) { o.maxIterations = static_cast<int>(v); }},
      {"optimise_seconds", [](OptimiserOptions& o, double v) { o.timeLimit = v; }},
      {"facet_weight", [](OptimiserOptions& o, double v) { o.facetWeight = v; }},
      {"fidelity_weight", [](OptimiserOptions& o, double v) { o.fidelityWeight = v; }},
      {"threads", [](OptimiserOptions& o, double v) { o.threads = static_cast<int>(v); }},
      {"functional",
       [](OptimiserOptions& o, double v) { o.functional = static_cast<Functional>(v); }},
      {"tolerance", [](OptimiserOptions& o, double v) { o.tolerance = v; }},
      {"region",
       [](OptimiserOptions& o, double v) {
         o.regionThreshold = v > 0.0 ? std::optional<double>(v) : std::nullopt;
       }},
      {"region_layers",
       [](OptimiserOptions& o, double v) { o.regionLayers = static_cast<int>(v); }},
      {"focus", [](OptimiserOptions& o, double v) { o.focusPasses = static_cast<int>(v); }},
      {"free_interfaces", [](OptimiserOptions& o, double v) { o.freeInterfaces = v != 0.0; }},
  };
  return table;
}

}  // namespace

std::vector<std::string> OptimiserOptions::keys() {
  return optionKeys(setters());
}

void OptimiserOptions::apply(const OptionMap& values) {
  applyOptions(*this, values, setters(), {}, "to the optimiser");
  // A neighbourhood of nothing: the user meant a region and left it out.
  if (values.count("region_layers") != 0 && !regionThreshold)
    throw ParameterError(std::string(parameterDefinition("region_layers").label) + " need a " +
                         parameterDefinition("region").label + " (a scaled Jacobian > 0)");
  validate();
}

}  // namespace homesh
