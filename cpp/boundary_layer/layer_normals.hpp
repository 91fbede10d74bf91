// The macro layer's wall normals: a layer cell's curved wall's normal at a wall point, a CAD
// curve's normal in a planar mesh, the columns of nodes (wall node, top node, normal) of every
// layer cell, the normals summed per column with the sharp-corner test, and the unit normal
// below each top node (layerTopNormals) that the optimiser keeps the layer's top moving across.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <vector>

#include "boundary_layer/layer_cells.hpp"
#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "element/element_map.hpp"
#include "element/reference_element.hpp"

namespace homesh {

// A wall node is at a sharp corner when the mean of its cells' unit wall normals is shorter than
// this (cos 15 degrees: the normals spread by more than about 30 degrees).
constexpr double kCornerMeanNormal = 0.966;

// The unit normal of a layer cell's curved wall (a prism's triangle or a hexahedron's
// quadrilateral at zeta 0; in 2D a quadrilateral's edge, in the plane) at wall coordinates (a, b),
// on the side of `towards`.
Eigen::Vector3d wallNormal(const Mesh& mesh, const ReferenceElement& ref, const std::int64_t* v,
                           double a, double b, const Eigen::Vector3d& towards);
// The same on the cell's map (element/element_map.hpp), `plane` the mesh's plane normal in 2D.
Eigen::Vector3d wallNormal(const ElementMap& map, double a, double b, const Eigen::Vector3d& plane,
                           const Eigen::Vector3d& towards);

// The unit normal of CAD curve `curve` in the mesh's plane at mesh node `node` (on the curve,
// or one of its vertices: the end nearer parameter `near`), on the side of `towards`; zero
// where the curve's derivative vanishes or OCCT cannot evaluate it.
Eigen::Vector3d curveNormal(const Mesh& mesh, const CadModel& cad, std::int64_t node, int curve,
                            double near, const Eigen::Vector3d& towards);

// Calls visit(wall, top, normal) for every column of nodes of every layer cell of `mesh`: the
// wall node, the top node above it, and the cell's unit wall normal there (towards the top).
template <class Visit>
void forEachColumn(const Mesh& mesh, Visit&& visit) {
  for (const ElementBlock& b : mesh.blocks) {
    if (!isLayerCell(mesh, b)) continue;
    const int p = b.order;
    const std::size_t across = layerShape(b.type).across;
    const ReferenceElement& ref = ReferenceElement::get(b.type, p);
    const std::map<LatticePoint, int> index = latticeIndex(ref);
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      const ElementMap map(ref, mesh.xyz.data(), v);  // one per cell: nothing moves here
      const Eigen::Vector3d plane(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
      for (int r = 0; r < ref.numNodes(); ++r) {
        LatticePoint c = ref.lattice()[static_cast<std::size_t>(r)];
        if (c[across] != 0) continue;
        c[across] = p;
        const std::int64_t top = v[index.at(c)];
        const Eigen::Vector3d rise = Eigen::Vector3d(&mesh.xyz[3 * static_cast<std::size_t>(top)]) -
                                     Eigen::Vector3d(&mesh.xyz[3 * static_cast<std::size_t>(v[r])]);
        visit(v[r], top,
              wallNormal(map, double(c[0]) / p, across == 2 ? double(c[1]) / p : 0.0, plane, rise));
      }
    }
  }
}

// The unit normals of the cells meeting at a node, each and summed.
struct NormalSum {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> normals;
  void add(const Eigen::Vector3d& n) {
    sum += n;
    normals.push_back(n);
  }
  // The smallest component of `v` along the normals added (+infinity when none).
  double minAlong(const Eigen::Vector3d& v) const {
    double least = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& n : normals) least = std::min(least, v.dot(n));
    return least;
  }
  // A sharp corner: the normals spread by more than about 30 degrees (their mean is shorter
  // than cos 15 degrees).
  bool sharp() const {
    return sum.norm() < kCornerMeanNormal * static_cast<double>(normals.size());
  }
};

// Per node (3 values): for the nodes of a macro layer's top (prisms' and hexahedra's, in 2D the
// quadrilaterals' far side), the unit wall normal below them (averaged over the cells sharing
// the node); NaN for every other node and for nodes above a sharp corner (the cells' normals
// spread by more than about 30 degrees: they may move freely). OptimiserOptions::normalLocked
// takes it.
std::vector<double> layerTopNormals(const Mesh& mesh);

}  // namespace homesh
