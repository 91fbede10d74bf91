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

}  // namespace homesh
