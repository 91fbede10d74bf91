#include "curving/interior_blend.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "element/node_ordering.hpp"

namespace homesh {

namespace {

// Silvester's polynomial R_a(z) = prod_{m < a} (z - m) / (m + 1): 1 at z = a, 0 at 0 .. a - 1.
// The equispaced Lagrange basis of a simplex of order P is prod_k R_{a_k}(P l_k).
double silvester(int a, double z) {
  double r = 1.0;
  for (int m = 0; m < a; ++m) r *= (z - m) / (m + 1);
  return r;
}

constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

using Bary = std::array<double, 4>;

// The local nodes of a tetrahedron of order P, Gmsh's order: their integer barycentric
// coordinates, those of each edge (by position along it) and of each face (by opposite vertex).
struct TetLattice {
  int order = 0;
  std::vector<std::array<int, 4>> a;
  std::array<std::vector<int>, 6> edge;  // edge[e][k]: the node k / P of the way from i to j
  std::array<std::vector<int>, 4> face;  // face[o]: the nodes with a_o = 0

  explicit TetLattice(int p) : order(p) {
    for (const LatticePoint& c : latticeOrder(CellType::Tetrahedron, p, NodeConvention::Gmsh))
      a.push_back(simplexBarycentric(c, 3, p));
    for (int e = 0; e < 6; ++e) edge[static_cast<std::size_t>(e)].assign(p + 1, -1);
    for (int n = 0; n < static_cast<int>(a.size()); ++n) {
      const std::array<int, 4>& b = a[static_cast<std::size_t>(n)];
      for (int e = 0; e < 6; ++e) {
        const int i = kEdges[e][0], j = kEdges[e][1];
        if (b[i] + b[j] == p) edge[static_cast<std::size_t>(e)][b[j]] = n;
      }
      for (int o = 0; o < 4; ++o)
        if (b[o] == 0) face[static_cast<std::size_t>(o)].push_back(n);
    }
  }

  Bary bary(int n) const {
    const std::array<int, 4>& b = a[static_cast<std::size_t>(n)];
    return {static_cast<double>(b[0]) / order, static_cast<double>(b[1]) / order,
            static_cast<double>(b[2]) / order, static_cast<double>(b[3]) / order};
  }
  int interiorCoordinates(int n) const {  // 2: edge, 3: face, 4: inside the cell
    int k = 0;
    for (const int v : a[static_cast<std::size_t>(n)]) k += v > 0 ? 1 : 0;
    return k;
  }
};

// One tetrahedron's nodes and their displacement from the straight-sided element.
class TetDisplacement {
 public:
  TetDisplacement(const TetLattice& lattice, const Mesh& mesh, const std::int64_t* cell)
      : l_(lattice), mesh_(mesh), d_(lattice.a.size()) {
    for (int k = 0; k < 4; ++k) v_[static_cast<std::size_t>(k)] = point(cell[k]);
    for (std::size_t n = 0; n < d_.size(); ++n)
      d_[n] = point(cell[n]) - straight(l_.bary(static_cast<int>(n)));
  }

  Eigen::Vector3d straight(const Bary& l) const {
    return l[0] * v_[0] + l[1] * v_[1] + l[2] * v_[2] + l[3] * v_[3];
  }

  // The longest edge between its vertices.
  double size() const {
    double h = 0.0;
    for (const auto& e : kEdges)
      h = std::max(
          h, (v_[static_cast<std::size_t>(e[0])] - v_[static_cast<std::size_t>(e[1])]).norm());
    return h;
  }

  // E(l): the edges' displacements, each carried along the lines through the opposite edge.
  Eigen::Vector3d edges(const Bary& l) const {
    const int p = l_.order;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int e = 0; e < 6; ++e) {
      const double s = l[kEdges[e][0]] + l[kEdges[e][1]];
      if (s <= 0.0) continue;
      const double t = l[kEdges[e][1]] / s;
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      for (int k = 1; k < p; ++k)  // (the ends are vertices: no displacement)
        d += silvester(k, p * t) * silvester(p - k, p * (1.0 - t)) *
             d_[static_cast<std::size_t>(l_.edge[static_cast<std::size_t>(e)][k])];
      sum += s * s * d;
    }
    return sum;
  }

  // E(l) plus the F_f(l) of the four faces.
  Eigen::Vector3d cell(const Bary& l) {
    const int p = l_.order;
    if (residual_.empty()) {  // what each face node adds to E: the same for every cell node
      residual_.assign(d_.size(), Eigen::Vector3d::Zero());
      for (std::size_t n = 0; n < d_.size(); ++n)
        if (l_.interiorCoordinates(static_cast<int>(n)) == 3)
          residual_[n] = d_[n] - edges(l_.bary(static_cast<int>(n)));
    }
    Eigen::Vector3d sum = edges(l);
    for (int o = 0; o < 4; ++o) {
      const double w = 1.0 - l[o];
      if (w <= 0.0) continue;
      Eigen::Vector3d r = Eigen::Vector3d::Zero();
      for (const int n : l_.face[static_cast<std::size_t>(o)]) {
        if (l_.interiorCoordinates(n) < 3) continue;  // on an edge: E is exact there
        const std::array<int, 4>& b = l_.a[static_cast<std::size_t>(n)];
        double basis = 1.0;
        for (int m = 0; m < 4; ++m)
          if (m != o) basis *= silvester(b[m], p * l[m] / w);
        r += basis * residual_[static_cast<std::size_t>(n)];
      }
      sum += w * w * w * r;
    }
    return sum;
  }

 private:
  Eigen::Vector3d point(std::int64_t id) const {
    return Eigen::Vector3d::Map(mesh_.xyz.data() + 3 * id);
  }

  const TetLattice& l_;
  const Mesh& mesh_;
  std::array<Eigen::Vector3d, 4> v_;
  std::vector<Eigen::Vector3d> d_;
  std::vector<Eigen::Vector3d> residual_;  // per face node, once cell() is first asked
};

}  // namespace

std::size_t blendInteriorNodes(Mesh& mesh) {
  if (mesh.dim != 3 || mesh.order < 3) return 0;
  // Free: inside the domain, and in no cell but tetrahedra.
  std::vector<char> free(mesh.numNodes(), 0);
  for (std::size_t i = 0; i < mesh.numNodes(); ++i) free[i] = mesh.nodeCadDim[i] == 3 ? 1 : 0;
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) == 3 && b.type != CellType::Tetrahedron)
      for (const std::int64_t id : b.nodes) free[static_cast<std::size_t>(id)] = 0;
  const TetLattice lattice(mesh.order);
  std::size_t moved = 0;
  // A displacement below 1e-12 of the element's size is rounding (a straight element's own
  // sums): such a node keeps its position to the bit.
  const auto place = [&](std::int64_t id, const Eigen::Vector3d& x, double size) {
    auto at = Eigen::Vector3d::Map(mesh.xyz.data() + 3 * id);
    if ((at - x).norm() > 1e-12 * size) {
      at = x;
      ++moved;
    }
    free[static_cast<std::size_t>(id)] = 0;  // placed once: a face's second tetrahedron agrees
  };
  // Faces first (their nodes from their own edges), then the cells (from their faces).
  for (const int kind : {3, 4})
    for (const ElementBlock& b : mesh.blocks) {
      if (b.type != CellType::Tetrahedron) continue;
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* cell = b.element(e);
        std::optional<TetDisplacement> tet;
        for (int n = 0; n < static_cast<int>(lattice.a.size()); ++n) {
          if (free[static_cast<std::size_t>(cell[n])] == 0 ||
              lattice.interiorCoordinates(n) != kind)
            continue;
          if (!tet) tet.emplace(lattice, mesh, cell);
          const Bary l = lattice.bary(n);
          place(cell[n], tet->straight(l) + (kind == 3 ? tet->edges(l) : tet->cell(l)),
                tet->size());
        }
      }
    }
  return moved;
}

}  // namespace homesh
