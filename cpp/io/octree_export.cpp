#include "io/octree_export.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <map>

#include <Eigen/Geometry>

#include "sizing/sizing_octree.hpp"

namespace homesh {

OctreeMesh octreeLeavesMesh(const SizingOctree& octree) {
  OctreeMesh out;
  Mesh& mesh = out.mesh;
  const int dim = octree.dim();
  mesh.dim = dim;
  mesh.order = 1;
  const Eigen::Matrix3d& axes = octree.axes();
  const Eigen::Vector3d normal = axes.col(2);
  mesh.planeNormal = {normal.x(), normal.y(), normal.z()};
  // Leaf corners in model coordinates, shared between leaves (keyed by their rounded position).
  const Eigen::Vector3d e0 = axes.col(0), e1 = axes.col(1);
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < octree.numLeaves(); ++i)
    smallest = std::min(smallest, octree.leaf(i).halfWidth);
  const double key = 1e-3 * smallest;
  std::map<std::array<long long, 3>, std::int64_t> nodes;
  const auto node = [&](const Eigen::Vector3d& p) {
    const std::array<long long, 3> k{std::llround(p.x() / key), std::llround(p.y() / key),
                                     std::llround(p.z() / key)};
    const auto [it, inserted] = nodes.emplace(k, 0);
    if (inserted) {
      const double xyz[3] = {p.x(), p.y(), p.z()};
      it->second = mesh.addNode(xyz, 3, 0, std::nan(""), std::nan(""));
    }
    return it->second;
  };
  ElementBlock block;
  block.type = dim == 3 ? CellType::Hexahedron : CellType::Quadrilateral;
  CellField delta{"delta", {}}, fraction{"inside_fraction", {}}, level{"level", {}},
      location{"location", {}};
  // Corner offsets in Gmsh's vertex order (counter-clockwise bottom, then top).
  static const int kCorner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                    {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  for (std::size_t i = 0; i < octree.numLeaves(); ++i) {
    const SizingOctree::Leaf leaf = octree.leaf(i);
    if (!(leaf.insideFraction > 0.0)) continue;
    const Eigen::Vector3d ez = dim == 3 ? Eigen::Vector3d(Eigen::Vector3d::UnitZ())
                                        : Eigen::Vector3d(Eigen::Vector3d::Zero());
    for (int c = 0; c < (dim == 3 ? 8 : 4); ++c) {
      const Eigen::Vector3d p =
          leaf.centre +
          leaf.halfWidth * (kCorner[c][0] * e0 + kCorner[c][1] * e1 + kCorner[c][2] * ez);
      block.nodes.push_back(node(p));
    }
    block.entity.push_back(0);
    delta.values.push_back(leaf.delta);
    fraction.values.push_back(leaf.insideFraction);
    level.values.push_back(leaf.level);
    location.values.push_back(leaf.location == SizingOctree::Location::Inside ? 2.0 : 1.0);
  }
  mesh.blocks.push_back(std::move(block));
  out.fields = {delta, fraction, level, location};
  return out;
}

void writeOctree(const SizingOctree& octree, const std::string& path) {
  const OctreeMesh m = octreeLeavesMesh(octree);
  writeMesh(m.mesh, path, m.fields);
}

}  // namespace homesh
