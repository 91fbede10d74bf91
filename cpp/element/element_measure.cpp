#include "element/element_measure.hpp"

#include <array>
#include <memory>

#include "element/cell_table_cache.hpp"
#include "element/quadrature.hpp"

namespace homesh {
namespace {

struct MeasureRule {
  QuadratureRule rule;
  std::unique_ptr<JacobianSampler> sampler;
};

// J's degree (per variable for boxes and prisms), so that the rule is exact.
int jacobianDegree(CellType type, int p) {
  switch (type) {
    case CellType::Line:
      return 4 * p;  // |x'| is not polynomial: over-integrate
    case CellType::Triangle:
      return 2 * (p - 1) + 2;
    case CellType::Quadrilateral:
      return 2 * p;
    case CellType::Tetrahedron:
      return 3 * (p - 1);
    default:  // prisms, hexahedra, and pyramids (J: degree 3p - 1 in collapsed coordinates)
      return 3 * p;
  }
}

const MeasureRule& rule(CellType type, int order) {
  static CellTableCache<MeasureRule> cache;
  return cache.get(type, order, [&] {
    auto slot = std::make_unique<MeasureRule>();
    slot->rule = quadratureRule(type, jacobianDegree(type, order));
    slot->sampler = std::make_unique<JacobianSampler>(ReferenceElement::get(type, order),
                                                      pointRows(slot->rule));
    return slot;
  });
}

}  // namespace

double elementMeasure(CellType type, int order, const NodeCoordinates& x,
                      const Eigen::Vector3d* normal) {
  const MeasureRule& r = rule(type, order);
  Eigen::VectorXd j;
  r.sampler->jacobians(x, normal, j);
  double sum = 0.0;
  for (int q = 0; q < r.rule.size(); ++q) sum += r.rule.weights[q] * j(q);
  return sum;
}

std::vector<double> elementMeasures(const Mesh& mesh) {
  std::vector<double> out;
  for (const ElementBlock& b : mesh.blocks) {
    if (cellDimension(b.type) != mesh.dim) continue;
    const int n = b.nodesPerElement();
    NodeCoordinates x(n, 3);
    for (std::size_t e = 0; e < b.count(); ++e) {
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) x(i, c) = mesh.xyz[3 * b.element(e)[i] + c];
      // A surface mesh's cells: their curved area (|x_xi1 x x_xi2|), not its projection.
      const std::array<double, 3> n3 = mesh.cellNormal(b.element(e));
      const Eigen::Vector3d normal(n3[0], n3[1], n3[2]);
      out.push_back(elementMeasure(b.type, b.order, x,
                                   mesh.dim == 2 && !mesh.isSurface() ? &normal : nullptr));
    }
  }
  return out;
}

}  // namespace homesh
