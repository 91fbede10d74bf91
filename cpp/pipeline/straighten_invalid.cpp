#include "pipeline/straighten_invalid.hpp"

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "element/element_map.hpp"
#include "element/reference_element.hpp"

namespace homesh {

std::size_t straightenInvalidElements(Mesh& mesh, const QualitySummary& quality) {
  const auto elements = elementsOf(mesh);
  std::vector<char> moved(mesh.numNodes(), 0);
  std::size_t count = 0;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    if (quality.validity[e] == Validity::Valid) continue;
    const auto [block, i] = elements[e];
    const ReferenceElement& curved = ReferenceElement::get(block->type, block->order);
    const ElementMap straight(ReferenceElement::get(block->type, 1), mesh.xyz.data(),
                              block->element(i));  // (its vertices come first)
    for (int r = cellNumVertices(block->type); r < curved.numNodes(); ++r) {
      const auto id = static_cast<std::size_t>(block->element(i)[r]);
      if (mesh.nodeCadDim[id] != mesh.dim || moved[id] != 0) continue;
      const Eigen::VectorXd xi = curved.nodes().row(r).transpose();
      const Eigen::Vector3d x = straight.position(xi.data());
      for (std::size_t d = 0; d < 3; ++d) mesh.xyz[3 * id + d] = x(static_cast<Eigen::Index>(d));
      moved[id] = 1;
      ++count;
    }
  }
  return count;
}

}  // namespace homesh
