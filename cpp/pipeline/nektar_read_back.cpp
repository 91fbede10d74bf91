#include "pipeline/nektar_read_back.hpp"

#include <cstdio>

#include "io/mesh_readers.hpp"
#include "quality/mesh_quality.hpp"

namespace homesh {

std::string NektarReadBack::line() const {
  char figures[96];
  std::snprintf(figures, sizeof figures, "scaled Jacobian min %.4f; %zu invalid, %zu undecided",
                worst, invalid, undecided);
  return path + " as Nektar++ builds it (element interiors from the faces): " + figures;
}

NektarReadBack checkNektarReadBack(const std::string& path, int threads) {
  const QualitySummary q = evaluateQuality(readMesh(path), threads);
  return {path, q.scaled.min, q.invalid, q.undecided};
}

}  // namespace homesh
