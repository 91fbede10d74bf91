#include "pipeline/geometry_check.hpp"

#include "cad/cad_healing.hpp"
#include "pipeline/case_setup.hpp"
#include "quality/boundary_on_cad.hpp"

namespace homesh {

GeometryAccuracy checkGeometryAgainstCad(const Mesh& mesh, const std::string& cadPath, int threads,
                                         double relativeTolerance) {
  const CaseSetup setup = setupCase(cadPath);
  HealingRecord healing;
  const CadModel cad = healModel(setup.source.load(), HealingOptions{}, healing);
  const double tolerance =
      relativeTolerance > 0.0 ? relativeTolerance * cad.boundingDiagonal() : 0.0;
  return measureGeometryAccuracy(boundaryOnCad(mesh, cad, tolerance), cad, threads);
}

}  // namespace homesh
