#include "pipeline/curved_mesh.hpp"

#include <limits>

namespace homesh {

std::vector<CellField> qualityFields(const QualitySummary& quality) {
  CellField scaled{"scaled_jacobian", quality.scaledJacobian};
  scaled.values.insert(scaled.values.end(), quality.boundaryScaledJacobian.begin(),
                       quality.boundaryScaledJacobian.end());
  CellField distortion{"distortion", quality.distortion};
  distortion.values.insert(distortion.values.end(), quality.boundaryDistortion.begin(),
                           quality.boundaryDistortion.end());
  // 1 proven valid, -1 invalid, 0 undecided; boundary cells have no verdict (NaN).
  CellField validity{"validity", {}};
  for (const Validity v : quality.validity)
    validity.values.push_back(v == Validity::Valid ? 1.0 : v == Validity::Invalid ? -1.0 : 0.0);
  validity.values.resize(scaled.values.size(), std::numeric_limits<double>::quiet_NaN());
  return {scaled, distortion, validity};
}

void writeMeshFiles(const CurvedMesh& curved, const std::vector<std::string>& paths,
                    const WriteOptions& options) {
  const std::vector<CellField> fields = qualityFields(curved.quality);
  for (const std::string& path : paths) writeMesh(curved.mesh, path, fields, options);
}

}  // namespace homesh
