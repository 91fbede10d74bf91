#include "pipeline/geometry_check.hpp"

#include <chrono>

#include "cad/cad_healing.hpp"
#include "pipeline/case_setup.hpp"

namespace homesh {

GeometryCheck checkGeometryAgainstCad(const Mesh& mesh, const std::string& cadPath, int threads,
                                      double relativeTolerance) {
  const auto start = std::chrono::steady_clock::now();
  const CaseSetup setup = setupCase(cadPath);
  HealingRecord healing;
  const CadModel cad = healModel(setup.source.load(), HealingOptions{}, healing);
  GeometryCheck check;
  const double tolerance =
      relativeTolerance > 0.0 ? relativeTolerance * cad.boundingDiagonal() : 0.0;
  const Mesh onCad = boundaryOnCad(mesh, cad, tolerance, &check.attachment);
  check.accuracy = measureGeometryAccuracy(onCad, cad, threads);
  check.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return check;
}

}  // namespace homesh
