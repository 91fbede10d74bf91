#include "boundary_layer/layer_blend.hpp"

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "boundary_layer/layer_cells.hpp"
#include "boundary_layer/layer_normals.hpp"
#include "element/reference_element.hpp"

namespace homesh {

namespace {

// Where blendLayerInteriors puts the top node at lattice point `c` of layer cell `v` (order p,
// its wall node `w` below): nullopt where the wall's normal there is not defined.
std::optional<Eigen::Vector3d> topNodePosition(const Mesh& mesh, const CadModel* cad,
                                               const ReferenceElement& ref, const LayerShape& shape,
                                               const std::int64_t* v, const LatticePoint& c,
                                               std::int64_t w,
                                               const std::set<std::int64_t>* sharpColumns) {
  const int p = ref.order();
  const bool volume = shape.across == 2;
  const int walls = shape.walls;
  const auto x = [&](std::int64_t n) {
    return Eigen::Vector3d(&mesh.xyz[3 * static_cast<std::size_t>(n)]);
  };
  const auto top = [&](int k) { return shape.top(v, k); };
  // The top is the wall node offset along the wall's own normal there, corrected by
  // the vertices' climbs: parallel to the curved wall, meeting the top vertices.
  const std::array<double, 4> l = shape.weights(double(c[0]) / p, volume ? double(c[1]) / p : 0.0);
  // The wall vertices' reference coordinates (the triangle's are the first three).
  const double corner[4][2] = {{0, 0}, {1, 0}, {shape.walls == 4 ? 1.0 : 0.0, 1}, {0, 1}};
  Eigen::Vector3d rise = Eigen::Vector3d::Zero();
  for (int k = 0; k < walls; ++k) rise += l[static_cast<std::size_t>(k)] * (x(top(k)) - x(v[k]));
  // In 2D the CAD curve's own normals where the wall nodes are on it: the wall's
  // polynomial tilts its normal by degrees near the ends of a short wall around a
  // tight tip (T106's trailing edge, 3 degrees on a wall 0.0035 long), which the
  // top, 0.053 away, turns into a fold.
  const int curve =
      mesh.dim == 2 && cad != nullptr && mesh.nodeCadDim[w] == 1 ? mesh.nodeCadIndex[w] : 0;
  std::array<Eigen::Vector3d, 4> atCorner;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  bool exact = curve > 0;
  if (exact) {
    const double near = mesh.nodeCadParam[2 * static_cast<std::size_t>(w)];
    direction = curveNormal(mesh, *cad, w, curve, near, rise);
    for (int k = 0; k < walls; ++k)
      atCorner[static_cast<std::size_t>(k)] =
          curveNormal(mesh, *cad, v[k], curve, near, x(top(k)) - x(v[k]));
    exact = !direction.isZero() && !atCorner[0].isZero() && !atCorner[1].isZero();
  }
  if (!exact) {
    direction = wallNormal(mesh, ref, v, double(c[0]) / p, volume ? double(c[1]) / p : 0.0, rise);
    for (int k = 0; k < walls; ++k)
      atCorner[static_cast<std::size_t>(k)] =
          wallNormal(mesh, ref, v, corner[k][0], corner[k][1], x(top(k)) - x(v[k]));
  }
  bool leaning = false;  // a vertex's column at a sharp edge or corner
  for (int k = 0; k < walls; ++k)
    leaning = leaning || (sharpColumns != nullptr && sharpColumns->count(v[k]) != 0);
  if (!leaning) {
    // The vertices' unit climbs against their normals, interpolated, correct the
    // direction; the length is theirs, interpolated.
    double h = 0.0;
    for (int k = 0; k < walls; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      const Eigen::Vector3d climb = x(top(k)) - x(v[k]);
      h += l[kk] * climb.norm();
      direction += l[kk] * (climb.normalized() - atCorner[kk]);
    }
    if (!(direction.norm() > 0.0)) return std::nullopt;
    return Eigen::Vector3d(x(w) + h * direction.normalized());
  }
  // Beside a lengthened column the climbs split into their heights along their
  // normals and their leans across them, each interpolated: the wall node raised by
  // the height along its normal, then leant (at a vertex, its climb). The unit climbs
  // and lengths interpolated apart put a node between a column leaning 45 degrees at
  // a sharp edge and an upright one up to 12 % too high (midway).
  double height = 0.0;
  Eigen::Vector3d lean = Eigen::Vector3d::Zero();
  for (int k = 0; k < walls; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const Eigen::Vector3d climb = x(top(k)) - x(v[k]);
    const double along = climb.dot(atCorner[kk]);
    height += l[kk] * along;
    lean += l[kk] * (climb - along * atCorner[kk]);
  }
  if (!(direction.norm() > 0.0)) return std::nullopt;
  const Eigen::Vector3d n = direction.normalized();
  return Eigen::Vector3d(x(w) + height * n + lean - lean.dot(n) * n);
}

}  // namespace

void blendLayerInteriors(Mesh& mesh, const CadModel* cad, bool tops,
                         const std::set<std::int64_t>* sharpColumns) {
  std::vector<char> done(mesh.numNodes(), 0);
  const auto setOnCad = [&](std::size_t id, const Eigen::Vector3d& x) {
    if (mesh.dim == 3 && mesh.nodeCadDim[id] == 2 && cad != nullptr) {
      std::optional<std::array<double, 2>> guess;
      if (std::isfinite(mesh.nodeCadParam[2 * id]) && std::isfinite(mesh.nodeCadParam[2 * id + 1]))
        guess = std::array<double, 2>{mesh.nodeCadParam[2 * id], mesh.nodeCadParam[2 * id + 1]};
      const SurfaceProjection proj = cad->projectOnSurface(mesh.nodeCadIndex[id], x, guess);
      for (std::size_t d = 0; d < 3; ++d)
        mesh.xyz[3 * id + d] = proj.point(static_cast<Eigen::Index>(d));
      mesh.nodeCadParam[2 * id] = proj.u;
      mesh.nodeCadParam[2 * id + 1] = proj.v;
      return;
    }
    for (std::size_t d = 0; d < 3; ++d) mesh.xyz[3 * id + d] = x(static_cast<Eigen::Index>(d));
  };
  // Nodes this may place: inside the domain, or (3D, with the CAD) on a face, projected back.
  const auto movable = [&](std::size_t id) {
    return mesh.nodeCadDim[id] == mesh.dim ||
           (mesh.dim == 3 && mesh.nodeCadDim[id] == 2 && cad != nullptr);
  };
  for (int pass = tops ? 0 : 1; pass < 2; ++pass)  // tops first: the inner levels blend to them
    for (const ElementBlock& b : mesh.blocks) {
      // The layer's cells (layer_cells.hpp: the lattice axis across the layer is the last).
      if (!isLayerCell(mesh, b) || b.order < 2) continue;
      const LayerShape shape = layerShape(b.type);
      const bool volume = shape.across == 2;
      const int p = b.order;
      const std::size_t across = shape.across;
      const ReferenceElement& ref = ReferenceElement::get(b.type, p);
      const std::map<LatticePoint, int> index = latticeIndex(ref);
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* v = b.element(e);
        const auto x = [&](std::int64_t n) {
          return Eigen::Vector3d(&mesh.xyz[3 * static_cast<std::size_t>(n)]);
        };
        for (int r = 0; r < ref.numNodes(); ++r) {
          const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
          const auto id = static_cast<std::size_t>(v[r]);
          const bool vertex = (c[0] == 0 || c[0] == p) &&
                              (!volume || ((c[1] == 0 || c[1] == p) &&
                                           (shape.wall != CellType::Triangle || c[0] + c[1] <= p)));
          if (c[across] == 0 || !movable(id) || done[id] != 0 || (pass == 0) != (c[across] == p))
            continue;
          if (pass == 0 && vertex) continue;
          done[id] = 1;
          LatticePoint wallPoint = c;
          wallPoint[across] = 0;
          const std::int64_t w = v[index.at(wallPoint)];
          if (pass == 0) {
            const std::optional<Eigen::Vector3d> at =
                topNodePosition(mesh, cad, ref, shape, v, c, w, sharpColumns);
            if (at) setOnCad(id, *at);
            continue;
          }
          LatticePoint topPoint = c;
          topPoint[across] = p;
          const std::int64_t t = v[index.at(topPoint)];
          const double s = double(c[across]) / p;
          setOnCad(id, (1.0 - s) * x(w) + s * x(t));
        }
      }
    }
}

}  // namespace homesh
