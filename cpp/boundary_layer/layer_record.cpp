#include "boundary_layer/layer_record.hpp"

namespace homesh {

const char* layerReleaseName(LayerRelease release) {
  switch (release) {
    case LayerRelease::Parallel:
      return "parallel";
    case LayerRelease::Sides:
      return "parallel_and_sides";
    case LayerRelease::Free:
      return "free";
    case LayerRelease::None:
      break;
  }
  return "none";
}

std::vector<LayerShrink> BoundaryLayerRecord::shrunk() const {
  std::vector<LayerShrink> out;
  for (const LayerShrink& f : faces)
    if (f.nodes > 0) out.push_back(f);
  return out;
}

}  // namespace homesh
