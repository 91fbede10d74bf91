#include "pipeline/meshing_options.hpp"

#include <algorithm>

#include "core/error.hpp"

namespace homesh {

void MeshingOptions::validate() const {
  checkParameter("order", order);
  if (size) checkParameter("size", *size);
  if (threads != 0) checkParameter("threads", threads);  // 0: every core
  checkParameter("optimise", optimiseIterations);
  checkParameter("optimise_seconds", optimiseSeconds);
  checkParameter("facet_weight", facetWeight);
  checkParameter("fidelity_weight", fidelityWeight);
  checkParameter("linear_seconds", linearSeconds);
  checkParameter("job_seconds", jobSeconds);
  checkParameter("repair_rounds", repairRounds);
  checkParameter("classify_tolerance", classifyTolerance);
  if (boundaryLayer) boundaryLayer->validate();
  if (surface && boundaryLayer)
    throw ParameterError(
        "a boundary layer needs a volume or planar mesh, not a surface mesh "
        "(--surface)");
  healing().validate();
  if (size && !octreeOutput.empty())
    throw ParameterError("writing the sizing octree needs octree sizing, not a uniform size");
  if (size && sizing)
    throw ParameterError(
        "give either a uniform size or octree sizing (MinDelta, MaxDelta, EPS, refinement "
        "sources), not both");
  if (sizing) {
    SizingParameters check = *sizing;  // automatic values are checked once known
    if (check.maxDelta == 0.0) check.maxDelta = std::max(1.0, check.minDelta);
    if (check.minDelta == 0.0) check.minDelta = check.maxDelta;
    check.validate();
  }
}

namespace {

SizingParameters& sizingOf(MeshingOptions& o) {
  if (!o.sizing) o.sizing = SizingParameters{};
  return *o.sizing;
}

// Where each table key goes in MeshingOptions, given its checked number.
const OptionSetters<MeshingOptions>& setters() {
  static const OptionSetters<MeshingOptions> table = {
      {"order", [](MeshingOptions& o, double v) { o.order = static_cast<int>(v); }},
      {"size",
       [](MeshingOptions& o, double v) {
         if (v > 0.0) o.size = v;
       }},
      {"optimise", [](MeshingOptions& o, double v) { o.optimiseIterations = static_cast<int>(v); }},
      {"optimise_seconds", [](MeshingOptions& o, double v) { o.optimiseSeconds = v; }},
      {"facet_weight", [](MeshingOptions& o, double v) { o.facetWeight = v; }},
      {"fidelity_weight", [](MeshingOptions& o, double v) { o.fidelityWeight = v; }},
      {"linear_seconds", [](MeshingOptions& o, double v) { o.linearSeconds = v; }},
      {"job_seconds", [](MeshingOptions& o, double v) { o.jobSeconds = v; }},
      {"repair_rounds", [](MeshingOptions& o, double v) { o.repairRounds = static_cast<int>(v); }},
      {"classify_tolerance", [](MeshingOptions& o, double v) { o.classifyTolerance = v; }},
      {"threads", [](MeshingOptions& o, double v) { o.threads = static_cast<int>(v); }},
      {"verbosity", [](MeshingOptions& o, double v) { o.verbosity = static_cast<int>(v); }},
      {"heal", [](MeshingOptions& o, double v) { o.heal = v != 0.0; }},
      {"solids_only", [](MeshingOptions& o, double v) { o.solidsOnly = v != 0.0; }},
      {"imprint", [](MeshingOptions& o, double v) { o.imprint = v != 0.0; }},
      {"surface", [](MeshingOptions& o, double v) { o.surface = v != 0.0; }},
      {"auto", [](MeshingOptions& o, double v) { o.automatic = v != 0.0; }},
      // 0 (automatic) still asks for the octree: completeSizing fills it in.
      {"min_delta", [](MeshingOptions& o, double v) { sizingOf(o).minDelta = v; }},
      {"max_delta", [](MeshingOptions& o, double v) { sizingOf(o).maxDelta = v; }},
      {"eps", [](MeshingOptions& o, double v) { sizingOf(o).eps = v; }},
  };
  return table;
}

}  // namespace

std::vector<std::string> MeshingOptions::keys(const std::vector<std::string>& allowed) {
  return optionKeys(setters(), allowed);
}

void MeshingOptions::apply(const OptionMap& values, const std::vector<std::string>& allowed) {
  const bool sizes =
      values.count("min_delta") + values.count("max_delta") + values.count("eps") > 0;
  applyOptions(*this, values, setters(), allowed, "here");
  if (size && !sizes) sizing.reset();  // asked for together, validate() names both
  validate();
}

MeshingOptions MeshingOptions::fromMap(const OptionMap& values,
                                       const std::vector<std::string>& allowed) {
  MeshingOptions options;
  options.apply(values, allowed);
  return options;
}

}  // namespace homesh
