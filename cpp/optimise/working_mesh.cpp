#include "optimise/working_mesh.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "element/symmetric_quadrature.hpp"
#include "optimise/functional.hpp"
#include "optimise/node_colouring.hpp"

namespace homesh::optimiser {

namespace {

// The symmetric rule the energy of (type, order) takes with EnergyRule::Symmetric, where it has
// fewer points than the collapsed one (tetrahedra of orders 3 and 4).
std::optional<QuadratureRule> symmetricSamples(CellType type, int order) {
  const int degree = std::max(1, 2 * order - 1);
  if (type != CellType::Tetrahedron) return std::nullopt;
  std::optional<QuadratureRule> rule = symmetricRule(type, degree);
  if (rule && rule->size() >= quadratureRule(type, degree).size()) rule.reset();
  return rule;
}

}  // namespace

bool takesSymmetricSamples(CellType type, int order) {
  return symmetricSamples(type, order).has_value();
}

QuadratureRule energySamples(CellType type, int order, const ReferenceElement& equispaced,
                             EnergyRule choice) {
  const std::optional<QuadratureRule> symmetric =
      choice == EnergyRule::Symmetric ? symmetricSamples(type, order) : std::nullopt;
  QuadratureRule rule = symmetric ? *symmetric : quadratureRule(type, std::max(1, 2 * order - 1));
  double measure = 0.0;
  for (const double w : rule.weights) measure += w;
  const Eigen::MatrixXd& nodes = equispaced.nodes();
  // With the symmetric rule, the vertices and edge nodes only (Gmsh's order lists them first),
  // where a curved element's J is most often lowest: 22 of an order-4 tetrahedron's 35.
  const Eigen::Index sampled = symmetric ? 4 + 6 * (order - 1) : nodes.rows();
  const double w = kNodeShare * measure / static_cast<double>(sampled);
  for (Eigen::Index n = 0; n < sampled; ++n) {
    for (Eigen::Index c = 0; c < nodes.cols(); ++c) rule.points.push_back(nodes(n, c));
    rule.weights.push_back(w);
  }
  return rule;
}

template <int D>
WorkingMesh<D>::WorkingMesh(Mesh& m, bool convert, const SpatialOrder* order)
    : mesh(m),
      // Pyramids have no optimal node set (node_sets.hpp) whose faces match the tetrahedra's
      // and hexahedra's: a mesh with pyramids moves its own, equispaced, nodes.
      converting(convert &&
                 std::none_of(m.blocks.begin(), m.blocks.end(),
                              [](const ElementBlock& b) { return b.type == CellType::Pyramid; })),
      elementRank(order != nullptr ? &order->originalElements() : nullptr),
      callersNodes(order != nullptr ? &order->newNodes() : nullptr),
      callersElements(order != nullptr ? &order->newElements() : nullptr) {}

template <int D>
void WorkingMesh<D>::build() {
  setFrame();
  buildBlocks();
  convertToWorkingSet();
  buildIncidence();
}

template <int D>
void WorkingMesh<D>::setFrame() {
  if constexpr (D == 3) {
    frame.setIdentity();
  } else {
    const Eigen::Vector3d n =
        Eigen::Vector3d(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]).normalized();
    Eigen::Vector3d t1 = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX().cross(n)
                                               : Eigen::Vector3d::UnitY().cross(n);
    t1.normalize();
    frame.row(0) = t1.transpose();
    frame.row(1) = n.cross(t1).transpose();  // t1 x t2 = n: counter-clockwise is positive
  }
  position.resize(mesh.numNodes());
  for (std::size_t i = 0; i < mesh.numNodes(); ++i)
    position[i] =
        frame * Eigen::Vector3d(mesh.xyz[3 * i], mesh.xyz[3 * i + 1], mesh.xyz[3 * i + 2]);
  start = position;
}

template <int D>
void WorkingMesh<D>::buildBlocks() {
  for (const ElementBlock& cells : mesh.blocks) {
    if (cellDimension(cells.type) != D || cells.count() == 0) continue;
    Block<D> b;
    b.cells = &cells;
    b.nodes = cells.nodesPerElement();
    b.affine = cells.type == CellType::Triangle || cells.type == CellType::Tetrahedron;
    const ReferenceElement& ref = ReferenceElement::get(
        cells.type, cells.order, converting ? kWorkingSet : NodeSet::Equispaced);
    const ReferenceElement& equi = ReferenceElement::get(cells.type, cells.order);
    b.toWorking = equi.valuesAt(ref.nodes());
    b.toEquispaced = ref.valuesAt(equi.nodes());
    blockOffset.push_back(totalElements);
    totalElements += cells.count();
    blocks.push_back(std::move(b));
  }
  if (blocks.empty())
    throw ParameterError("the mesh has no elements of dimension " + std::to_string(D) +
                         " to optimise");
}

template <int D>
void WorkingMesh<D>::buildSamples(EnergyRule choice) {
  energyRule = EnergyRule::Collapsed;
  for (std::size_t bi = 0; bi < blocks.size(); ++bi) {
    Block<D>& b = blocks[bi];
    const ElementBlock& cells = *b.cells;
    const ReferenceElement& ref = ReferenceElement::get(
        cells.type, cells.order, converting ? kWorkingSet : NodeSet::Equispaced);
    const ReferenceElement& equi = ReferenceElement::get(cells.type, cells.order);
    const ReferenceElement& lin = ReferenceElement::get(cells.type, 1);
    const QuadratureRule rule = energySamples(cells.type, cells.order, equi, choice);
    if (choice == EnergyRule::Symmetric && takesSymmetricSamples(cells.type, cells.order))
      energyRule = EnergyRule::Symmetric;
    b.points = rule.size();
    const Eigen::MatrixXd points = pointRows(rule);
    const std::vector<Eigen::MatrixXd> grad = ref.derivativesAt(points);
    const std::vector<Eigen::MatrixXd> linGrad = lin.derivativesAt(points);
    b.gradients.resize(static_cast<std::size_t>(b.points) * b.nodes * D);
    b.gradientTable.resize(b.nodes, static_cast<Eigen::Index>(b.points) * D);
    for (int q = 0; q < b.points; ++q)
      for (int n = 0; n < b.nodes; ++n)
        for (int k = 0; k < D; ++k) {
          const double g = grad[k](q, n);
          b.gradients[(static_cast<std::size_t>(n) * D + k) * b.points + q] = g;
          b.gradientTable(n, static_cast<Eigen::Index>(q) * D + k) = g;
        }
    const int nv = lin.numNodes();
    const std::size_t count = cells.count();
    const int idealPoints = b.affine ? 1 : b.points;
    b.idealInvT.resize(count * idealPoints);
    b.weights.resize(count * b.points);
    b.F.resize(count * D * D * b.points);
    b.J.resize(count * b.points);
    for (std::size_t e = 0; e < count; ++e) {
      const std::int64_t* v = cells.element(e);
      for (int q = 0; q < b.points; ++q) {
        // The ideal from the equispaced vertices (`start`): the working set's are the same
        // points, up to the conversion's rounding.
        Mat ideal = Mat::Zero();
        for (int n = 0; n < nv; ++n)
          for (int k = 0; k < D; ++k) ideal.col(k) += start[v[n]] * linGrad[k](q, n);
        const double det = functional_detail::determinant<D>(ideal);
        if (q < idealPoints) {
          if (!(std::abs(det) > 0.0))
            throw ParameterError("element " + std::to_string(callersElement(blockOffset[bi] + e)) +
                                 " (0-based, in block order)"
                                 " has a degenerate straight-sided shape (zero volume): "
                                 "the optimiser cannot measure its distortion");
          b.idealInvT[e * idealPoints + q] = ideal.inverse().transpose();
        }
        b.weights[e * b.points + q] = rule.weights[q] * std::abs(det);
      }
    }
  }
  buildNodeSizes();
}

// The same polynomial maps through the working node set's nodes (shared nodes get the same
// value from every element: the trace on a shared face depends on the face's nodes only).
template <int D>
void WorkingMesh<D>::convertToWorkingSet() {
  if (!converting) return;
  std::vector<Vec> working = position;
  forEachElementInCallersOrder([&](std::size_t bi, std::size_t e) {
    const Block<D>& b = blocks[bi];
    const std::int64_t* v = b.cells->element(e);
    for (int i = 0; i < b.nodes; ++i) {
      Vec x = Vec::Zero();
      for (int j = 0; j < b.nodes; ++j) x += b.toWorking(i, j) * position[v[j]];
      working[v[i]] = x;
    }
  });
  position.swap(working);
}

template <int D>
void WorkingMesh<D>::buildIncidence() {
  const std::size_t nn = mesh.numNodes();
  incidenceStart.assign(nn + 1, 0);
  for (const Block<D>& b : blocks)
    for (const std::int64_t id : b.cells->nodes) ++incidenceStart[id + 1];
  for (std::size_t i = 0; i < nn; ++i) incidenceStart[i + 1] += incidenceStart[i];
  incidence.resize(incidenceStart[nn]);
  // Filled in the caller's element order: each node's elements (and so its patch sums) in it.
  std::vector<std::size_t> fill(incidenceStart.begin(), incidenceStart.end() - 1);
  forEachElementInCallersOrder([&](std::size_t bi, std::size_t e) {
    const std::int64_t* v = blocks[bi].cells->element(e);
    for (int k = 0; k < blocks[bi].nodes; ++k)
      incidence[fill[v[k]]++] = {static_cast<int>(bi), k, e};
  });
}

template <int D>
void WorkingMesh<D>::buildNodeSizes() {
  nodeSize.assign(mesh.numNodes(), std::numeric_limits<double>::infinity());
  for (const Block<D>& b : blocks)
    for (std::size_t e = 0; e < b.cells->count(); ++e) {
      double volume = 0.0;
      for (int q = 0; q < b.points; ++q) volume += b.weights[e * b.points + q];
      volume /= 1.0 + kNodeShare;  // the weights add up to (1 + kNodeShare) x the volume
      const double size = std::pow(volume, 1.0 / D);
      const std::int64_t* v = b.cells->element(e);
      for (int k = 0; k < b.nodes; ++k) nodeSize[v[k]] = std::min(nodeSize[v[k]], size);
    }
}

template <int D>
void WorkingMesh<D>::computeGradients(const std::vector<std::size_t>& elements,
                                      const NodeColouring<D>& owners) {
  // One cache line or more per thread: resizing writes a matrix's header, and headers of two
  // threads in one line would move it between the CPUs at every element.
  struct alignas(64) Scratch {
    Eigen::Matrix<double, D, Eigen::Dynamic> x, dx;
  };
  std::vector<Scratch> scratch(static_cast<std::size_t>(owners.threads()));
  owners.forEachOwned(elements, 16, [&](std::size_t i, int thread) {
    auto& x = scratch[static_cast<std::size_t>(thread)].x;
    auto& dx = scratch[static_cast<std::size_t>(thread)].dx;
    const auto [bi, e] = locate(elements[i]);
    Block<D>& b = blocks[bi];
    const std::int64_t* v = b.cells->element(e);
    x.resize(D, b.nodes);
    for (int n = 0; n < b.nodes; ++n) x.col(n) = position[v[n]];
    dx.noalias() = x * b.gradientTable;
    for (int q = 0; q < b.points; ++q) {
      const Mat F =
          dx.template middleCols<D>(static_cast<Eigen::Index>(q) * D) * b.invT(e, q).transpose();
      for (int k = 0; k < D * D; ++k) b.componentF(e, k)[q] = F(k % D, k / D);
      b.J[e * b.points + q] = functional_detail::determinant<D>(F);
    }
  });
}

template <int D>
void WorkingMesh<D>::writeBack(std::int64_t node) {
  Vec x = position[node];
  if (converting) {
    const Incidence& inc = incidence[incidenceStart[node]];
    const Block<D>& b = blocks[inc.block];
    const std::int64_t* v = b.cells->element(inc.element);
    x.setZero();
    for (int j = 0; j < b.nodes; ++j) x += b.toEquispaced(inc.local, j) * position[v[j]];
  } else if constexpr (D == 3) {
    for (int c = 0; c < 3; ++c) mesh.xyz[3 * node + c] = x[c];  // exactly the CAD point
    start[node] = x;
    return;
  }
  const Eigen::Vector3d d = frame.transpose() * (x - start[node]);
  for (int c = 0; c < 3; ++c) mesh.xyz[3 * node + c] += d[c];
  start[node] = x;
}

template class WorkingMesh<2>;
template class WorkingMesh<3>;

}  // namespace homesh::optimiser
