#include "curving/order_elevation.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/error.hpp"
#include "element/reference_element.hpp"

namespace homesh {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A node by its support: the global vertices with a non-zero barycentric index, sorted by vertex.
struct NodeKey {
  std::array<std::int64_t, 4> vertex{-1, -1, -1, -1};
  std::array<int, 4> index{0, 0, 0, 0};
  int size = 0;
  bool operator==(const NodeKey& o) const {
    return size == o.size && vertex == o.vertex && index == o.index;
  }
};

struct NodeKeyHash {
  std::size_t operator()(const NodeKey& k) const {
    auto h = static_cast<std::size_t>(k.size);
    for (int i = 0; i < k.size; ++i) {
      h = h * 1000003u ^ static_cast<std::size_t>(k.vertex[i]);
      h = h * 1000003u ^ static_cast<std::size_t>(k.index[i]);
    }
    return h;
  }
};

using EdgeKey = std::array<std::int64_t, 2>;
using FaceKey = std::array<std::int64_t, 3>;

template <std::size_t N>
std::array<std::int64_t, N> sorted(std::array<std::int64_t, N> a) {
  std::sort(a.begin(), a.end());
  return a;
}

// Which CAD entity the edges and faces of the linear mesh lie on.
struct BoundaryClassification {
  std::map<EdgeKey, int> edgeCurve;  // edge on a CAD curve
  std::map<EdgeKey, int> edgeFace;   // edge inside a CAD face
  std::map<FaceKey, int> faceFace;   // triangle on a CAD face (3D)

  explicit BoundaryClassification(const Mesh& linear) {
    for (const ElementBlock& block : linear.blocks) {
      const bool boundaryFaces = block.type == CellType::Triangle;
      for (std::size_t e = 0; e < block.count(); ++e) {
        const std::int64_t* v = block.element(e);
        if (block.type == CellType::Line) {
          edgeCurve[sorted<2>({v[0], v[1]})] = block.entity[e];
        } else if (boundaryFaces) {
          // In 2D the cells themselves are the face's triangles; in 3D the boundary triangles.
          if (linear.dim == 3) faceFace[sorted<3>({v[0], v[1], v[2]})] = block.entity[e];
          for (int k = 0; k < 3; ++k)
            edgeFace.emplace(sorted<2>({v[k], v[(k + 1) % 3]}), block.entity[e]);
        }
      }
    }
  }
};

struct Elevator {
  const Mesh& linear;
  const int order;
  const BoundaryClassification classes;
  Mesh out;
  std::unordered_map<NodeKey, std::int64_t, NodeKeyHash> ids;

  Elevator(const Mesh& lin, int p) : linear(lin), order(p), classes(lin) {
    out.dim = lin.dim;
    out.order = p;
    out.planeNormal = lin.planeNormal;
    out.xyz = lin.xyz;
    out.nodeCadDim = lin.nodeCadDim;
    out.nodeCadIndex = lin.nodeCadIndex;
    out.nodeCadParam = lin.nodeCadParam;
  }

  // CAD dimension and index of a new node with support `key`, inside element of `block`.
  std::pair<int, int> classify(const NodeKey& key, CellType cell, int cellEntity) const {
    const int cellDim = cellDimension(cell);
    if (key.size == 2) {
      const EdgeKey edge{key.vertex[0], key.vertex[1]};
      if (auto it = classes.edgeCurve.find(edge); it != classes.edgeCurve.end())
        return {1, it->second};
      if (auto it = classes.edgeFace.find(edge); it != classes.edgeFace.end())
        return {2, it->second};
    } else if (key.size == 3 && linear.dim == 3) {
      const FaceKey face{key.vertex[0], key.vertex[1], key.vertex[2]};
      if (auto it = classes.faceFace.find(face); it != classes.faceFace.end())
        return {2, it->second};
    }
    return {cellDim, cellEntity};
  }

  // `curved`: the position from the source element's own map (null: on the straight element).
  std::int64_t node(const NodeKey& key, CellType cell, int cellEntity, const double* curved) {
    if (key.size == 1) return key.vertex[0];
    const auto [it, inserted] = ids.try_emplace(key, 0);
    if (!inserted) return it->second;
    double p[3] = {0.0, 0.0, 0.0};
    if (curved != nullptr) {
      std::copy(curved, curved + 3, p);
    } else {
      for (int i = 0; i < key.size; ++i)
        for (int c = 0; c < 3; ++c)
          p[c] += linear.xyz[3 * key.vertex[i] + c] * key.index[i] / static_cast<double>(order);
    }
    const auto [dim, entity] = classify(key, cell, cellEntity);
    it->second = out.addNode(p, dim, entity, kNaN, kNaN);
    return it->second;
  }

  void elevateBlock(const ElementBlock& block) {
    if (block.type != CellType::Line && block.type != CellType::Triangle &&
        block.type != CellType::Tetrahedron)
      throw ParameterError("changing the order supports lines, triangles and tetrahedra, not " +
                           cellShortName(block.type));
    const ReferenceElement& ref = ReferenceElement::get(block.type, order);
    const int nv = cellNumVertices(block.type);
    ElementBlock high;
    high.type = block.type;
    high.order = order;
    high.entity = block.entity;
    high.nodes.reserve(block.count() * ref.numNodes());
    // A curved source: its basis at the new nodes (new nodes x source nodes).
    const bool curvedSource = block.order > 1;
    Eigen::MatrixXd interpolation;
    if (curvedSource)
      interpolation = ReferenceElement::get(block.type, block.order).valuesAt(ref.nodes());
    const int sourceNodes = block.nodesPerElement();
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* v = block.element(e);
      for (int r = 0; r < ref.numNodes(); ++r) {
        const LatticePoint& point = ref.lattice()[static_cast<std::size_t>(r)];
        double curved[3] = {0.0, 0.0, 0.0};
        if (curvedSource)
          for (int j = 0; j < sourceNodes; ++j)
            for (int c = 0; c < 3; ++c) curved[c] += interpolation(r, j) * linear.xyz[3 * v[j] + c];
        const std::array<int, 4> a = simplexBarycentric(point, ref.dim(), order);
        std::array<std::pair<std::int64_t, int>, 4> support{};
        int n = 0;
        for (int k = 0; k < nv; ++k)
          if (a[k] > 0) support[n++] = {v[k], a[k]};
        for (int i = 1; i < n; ++i)  // insertion sort of at most 4 entries
          for (int j = i; j > 0 && support[j] < support[j - 1]; --j)
            std::swap(support[j], support[j - 1]);
        NodeKey key;
        key.size = n;
        for (int i = 0; i < n; ++i) {
          key.vertex[i] = support[i].first;
          key.index[i] = support[i].second;
        }
        high.nodes.push_back(
            node(key, block.type, block.entity[e], curvedSource ? curved : nullptr));
      }
    }
    out.blocks.push_back(std::move(high));
  }
};

// Moves the nodes created by elevation (ids >= firstNew) that lie on a CAD curve or face onto it.
void projectNewNodes(Mesh& mesh, std::size_t firstNew, const CadModel& cad) {
  for (auto id = static_cast<std::int64_t>(firstNew);
       id < static_cast<std::int64_t>(mesh.numNodes()); ++id) {
    const int dim = static_cast<int>(mesh.nodeCadDim[id]);
    const int entity = mesh.nodeCadIndex[id];
    if (dim != 1 && dim != 2) continue;
    double* x = &mesh.xyz[3 * id];
    const Eigen::Vector3d straight(x[0], x[1], x[2]);
    if (dim == 1) {
      const CurveProjection proj = cad.projectOnCurve(entity, straight);
      mesh.nodeCadParam[2 * id] = proj.t;
      for (int c = 0; c < 3; ++c) x[c] = proj.point[c];
    } else {
      const SurfaceProjection proj = cad.projectOnSurface(entity, straight);
      mesh.nodeCadParam[2 * id] = proj.u;
      mesh.nodeCadParam[2 * id + 1] = proj.v;
      for (int c = 0; c < 3; ++c) x[c] = proj.point[c];
    }
  }
}

// Drops the nodes no cell uses (the source's high-order nodes after an order change) and
// renumbers the rest in their original order.
void compactNodes(Mesh& mesh) {
  std::vector<std::int64_t> newId(mesh.numNodes(), -1);
  for (const ElementBlock& block : mesh.blocks)
    for (const std::int64_t id : block.nodes) newId[id] = 0;
  std::int64_t next = 0;
  for (std::size_t i = 0; i < newId.size(); ++i) {
    if (newId[i] < 0) continue;
    newId[i] = next;
    const auto j = static_cast<std::size_t>(next++);
    for (int c = 0; c < 3; ++c) mesh.xyz[3 * j + c] = mesh.xyz[3 * i + c];
    mesh.nodeCadDim[j] = mesh.nodeCadDim[i];
    mesh.nodeCadIndex[j] = mesh.nodeCadIndex[i];
    mesh.nodeCadParam[2 * j] = mesh.nodeCadParam[2 * i];
    mesh.nodeCadParam[2 * j + 1] = mesh.nodeCadParam[2 * i + 1];
  }
  const auto n = static_cast<std::size_t>(next);
  mesh.xyz.resize(3 * n);
  mesh.nodeCadDim.resize(n);
  mesh.nodeCadIndex.resize(n);
  mesh.nodeCadParam.resize(2 * n);
  for (ElementBlock& block : mesh.blocks)
    for (std::int64_t& id : block.nodes) id = newId[id];
}

}  // namespace

Mesh changeOrder(const Mesh& mesh, int order, const CadModel* cad) {
  if (order < 1 || order > 10)
    throw ParameterError("order must be between 1 and 10, got " + std::to_string(order));
  Elevator elevator(mesh, order);
  for (const ElementBlock& block : mesh.blocks) elevator.elevateBlock(block);
  if (cad != nullptr) projectNewNodes(elevator.out, mesh.numNodes(), *cad);
  compactNodes(elevator.out);
  elevator.out.checkConsistency();
  return std::move(elevator.out);
}

Mesh elevateOrder(const Mesh& linear, int order, const CadModel* cad) {
  if (linear.order != 1)
    throw ParameterError("order elevation needs a linear mesh, got order " +
                         std::to_string(linear.order));
  if (order < 1 || order > 10)
    throw ParameterError("order must be between 1 and 10, got " + std::to_string(order));
  Elevator elevator(linear, order);
  for (const ElementBlock& block : linear.blocks) elevator.elevateBlock(block);
  if (cad != nullptr) projectNewNodes(elevator.out, linear.numNodes(), *cad);
  elevator.out.checkConsistency();
  return std::move(elevator.out);
}

}  // namespace homesh
