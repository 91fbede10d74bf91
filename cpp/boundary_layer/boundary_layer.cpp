#include "boundary_layer/boundary_layer.hpp"

#include <chrono>
#include <cstddef>

#include "boundary_layer/layer_grower_2d.hpp"
#include "boundary_layer/layer_solids.hpp"
#include "boundary_layer/wall_segment_split.hpp"

namespace homesh {

Mesh growBoundaryLayer(const Mesh& volume, const CadModel& cad,
                       const BoundaryLayerParameters& parameters, const LinearMeshOptions& fill,
                       BoundaryLayerRecord& record) {
  parameters.validate();
  const auto start = std::chrono::steady_clock::now();
  record = BoundaryLayerRecord();
  Mesh mesh;
  if (volume.dim == 2) {
    Mesh planar = volume;
    record.wallSplits =
        static_cast<std::size_t>(layer_growth::splitTightWallSegments(planar, cad, parameters));
    mesh = layer_growth::growLayer2D(planar, cad, parameters, fill, record);
  } else {
    mesh = layer_growth::growLayerInSolids(volume, cad, parameters, fill, record);
  }
  record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return mesh;
}

}  // namespace homesh
