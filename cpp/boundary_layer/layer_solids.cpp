#include "boundary_layer/layer_solids.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "boundary_layer/layer_grower_3d.hpp"
#include "boundary_layer/layer_growth.hpp"
#include "core/error.hpp"
#include "linear/edge_split.hpp"

namespace homesh::layer_growth {
namespace {

using Tri = std::array<std::int64_t, 3>;

Tri sortedTri(Tri t) {
  std::sort(t.begin(), t.end());
  return t;
}

std::string solidName(int solid) {
  return cadEntityName(3, solid);
}

// "Face7", "Edge3", "Vertex2": the CAD entity a surface node lies on.
std::string entityName(const Mesh& mesh, std::int64_t node) {
  const auto i = static_cast<std::size_t>(node);
  return cadEntityName(mesh.nodeCadDim[i], mesh.nodeCadIndex[i]);
}

// Whether node i of `a` and node j of `b` are the same point on the same CAD entity.
bool sameNode(const Mesh& a, std::size_t i, const Mesh& b, std::size_t j) {
  for (std::size_t d = 0; d < 3; ++d)
    if (a.xyz[3 * i + d] != b.xyz[3 * j + d]) return false;
  for (std::size_t d = 0; d < 2; ++d) {
    const double u = a.nodeCadParam[2 * i + d], v = b.nodeCadParam[2 * j + d];
    if (u != v && !(std::isnan(u) && std::isnan(v))) return false;
  }
  return a.nodeCadDim[i] == b.nodeCadDim[j] && a.nodeCadIndex[i] == b.nodeCadIndex[j];
}

// A boundary triangle of the volume mesh, its face, and the solids on its sides with the
// tetrahedron's fourth vertex there.
struct Facet {
  Tri nodes{};
  int face = 0;
  std::vector<std::pair<int, std::int64_t>> sides;
};

class SolidLayers {
 public:
  SolidLayers(const Mesh& volume, const CadModel& cad, const BoundaryLayerParameters& p)
      : volume_(volume), cad_(cad), p_(p) {
    findFacets();
  }

  Mesh grow(const LinearMeshOptions& fill, BoundaryLayerRecord& record) {
    std::set<int> meshed;
    for (const Facet& f : facets_) meshed.insert(f.face);
    requireLayerFaces(cad_, p_.faces, meshed);
    std::map<int, std::vector<int>> layerFaces;  // solid -> its layer faces
    for (const int f : p_.faces) layerFaces[growthSolid(f)].push_back(f);
    for (const auto& [solid, faces] : layerFaces) requireOwnSides(solid, faces);
    std::vector<std::pair<int, Mesh>> grown;
    std::vector<BoundaryLayerRecord> records;
    for (const auto& [solid, faces] : layerFaces) {
      BoundaryLayerParameters own = p_;
      own.faces = faces;
      records.emplace_back();
      grown.emplace_back(solid, growLayer3D(solidMesh(solid), cad_, own, fill, records.back()));
    }
    joinRecords(records, record);
    return join(grown);
  }

 private:
  const Mesh& volume_;
  const CadModel& cad_;
  const BoundaryLayerParameters& p_;
  std::vector<Facet> facets_;
  std::map<int, std::set<int>> faceSolids_;  // face -> the solids it bounds

  void findFacets() {
    std::map<Tri, std::size_t> index;
    for (const ElementBlock& b : volume_.blocks) {
      if (b.type != CellType::Triangle) continue;
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* t = b.element(e);
        Facet f;
        f.nodes = {t[0], t[1], t[2]};
        f.face = b.entity[e];
        index.emplace(sortedTri(f.nodes), facets_.size());
        facets_.push_back(f);
      }
    }
    for (const ElementBlock& b : volume_.blocks) {
      if (b.type != CellType::Tetrahedron) continue;
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* t = b.element(e);
        const int solid = b.entity[e];
        for (int k = 0; k < 4; ++k) {
          const Tri face{t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]};
          const auto it = index.find(sortedTri(face));
          if (it != index.end()) facets_[it->second].sides.emplace_back(solid, t[k]);
        }
      }
    }
    for (const Facet& f : facets_) {
      std::set<int>& s = faceSolids_[f.face];
      for (const auto& side : f.sides) s.insert(side.first);
    }
  }

  // The solid face f's layer grows into: the one it bounds, or of the two it lies between the
  // one named (BoundaryLayerParameters::solids); else ParameterError.
  int growthSolid(int f) const {
    const std::set<int>& s = faceSolids_.at(f);
    const std::string face =
        "boundary-layer face " + std::to_string(f) + " of " + cad_.sourceName();
    if (s.empty()) throw ParameterError(face + " bounds no solid");
    if (s.size() == 1) return *s.begin();
    const std::string pair = solidName(*s.begin()) + " and " + solidName(*s.rbegin());
    std::vector<int> named;
    for (const int solid : s)
      if (std::find(p_.solids.begin(), p_.solids.end(), solid) != p_.solids.end())
        named.push_back(solid);
    if (named.size() == 1) return named.front();
    if (named.empty())
      throw ParameterError(face + " lies between " + pair +
                           ": name the one the layer grows into (--bl-solids " +
                           std::to_string(*s.begin()) + " or " + std::to_string(*s.rbegin()) +
                           "; Python: boundary_layer's \"solids\"; FreeCAD: the layer's "
                           "Solids)");
    throw ParameterError(face + " lies between " + pair +
                         ", and both are named: a layer grown into both sides of a face is not "
                         "made yet; name one");
  }

  // Refuses a layer in `solid` on `faces` that would change what another solid touches, since
  // that solid's tetrahedra are kept: its side climbing a face between two solids, or a wall
  // node that the tetrahedra of a solid use other than this one and those across the layer faces
  // between two solids through it (there the wall stays and only the side climbs this solid's
  // own faces).
  void requireOwnSides(int solid, const std::vector<int>& faces) const {
    const auto isLayer = [&](int f) {
      return std::find(faces.begin(), faces.end(), f) != faces.end();
    };
    // Per wall node: the solids it may touch, the faces without a layer (of this solid) through
    // it, and the solids whose tetrahedra use it.
    struct WallNode {
      std::set<int> allowed, sides, users;
    };
    std::map<std::int64_t, WallNode> wall;
    for (const Facet& f : facets_)
      if (isLayer(f.face))
        for (const std::int64_t v : f.nodes)
          wall[v].allowed.insert(faceSolids_.at(f.face).begin(), faceSolids_.at(f.face).end());
    for (const Facet& f : facets_) {
      if (isLayer(f.face) || faceSolids_.at(f.face).count(solid) == 0) continue;
      for (const std::int64_t v : f.nodes) {
        const auto it = wall.find(v);
        if (it != wall.end()) it->second.sides.insert(f.face);
      }
    }
    for (const ElementBlock& b : volume_.blocks) {
      if (b.type != CellType::Tetrahedron) continue;
      for (std::size_t e = 0; e < b.count(); ++e)
        for (int k = 0; k < 4; ++k) {
          const auto it = wall.find(b.element(e)[k]);
          if (it != wall.end()) it->second.users.insert(b.entity[e]);
        }
    }
    for (const auto& [v, w] : wall) {
      for (const int side : w.sides) {
        const std::set<int>& s = faceSolids_.at(side);
        if (s.size() < 2) continue;
        throw ParameterError("the boundary layer in " + solidName(solid) + " would climb Face" +
                             std::to_string(side) + ", which it shares with " +
                             solidName(*s.begin() == solid ? *s.rbegin() : *s.begin()) + ", at " +
                             pointText(at(volume_, v)) +
                             ": a layer beside a face between two solids is not made yet");
      }
      for (const int other : w.users)
        if (w.allowed.count(other) == 0)
          throw ParameterError("the boundary layer in " + solidName(solid) + " meets " +
                               solidName(other) + " at " + pointText(at(volume_, v)) + " on " +
                               entityName(volume_, v) +
                               ": a layer beside a face, curve or corner that another solid "
                               "shares is not made yet");
    }
  }

  // The solid's part of the volume mesh: its tetrahedra, its boundary triangles turned outward
  // of it, and the lines along their edges (every node kept, so that the surface nodes keep
  // their order).
  Mesh solidMesh(int solid) const {
    Mesh part;
    part.xyz = volume_.xyz;
    part.nodeCadDim = volume_.nodeCadDim;
    part.nodeCadIndex = volume_.nodeCadIndex;
    part.nodeCadParam = volume_.nodeCadParam;
    ElementBlock tets, tris, lines;
    tets.type = CellType::Tetrahedron;
    tris.type = CellType::Triangle;
    lines.type = CellType::Line;
    for (const ElementBlock& b : volume_.blocks) {
      if (b.type != CellType::Tetrahedron) continue;
      for (std::size_t e = 0; e < b.count(); ++e) {
        if (b.entity[e] != solid) continue;
        const std::int64_t* t = b.element(e);
        tets.nodes.insert(tets.nodes.end(), t, t + 4);
        tets.entity.push_back(solid);
      }
    }
    std::set<MeshEdge> edges;
    for (const Facet& f : facets_) {
      const auto side = std::find_if(f.sides.begin(), f.sides.end(),
                                     [&](const auto& s) { return s.first == solid; });
      if (side == f.sides.end()) continue;
      Tri t = f.nodes;
      const Vec a = at(volume_, t[0]);
      const Vec n = (at(volume_, t[1]) - a).cross(at(volume_, t[2]) - a);
      if (n.dot(at(volume_, side->second) - a) > 0.0) std::swap(t[1], t[2]);
      tris.nodes.insert(tris.nodes.end(), t.begin(), t.end());
      tris.entity.push_back(f.face);
      for (int k = 0; k < 3; ++k) edges.insert(meshEdge(t[k], t[(k + 1) % 3]));
    }
    for (const ElementBlock& b : volume_.blocks) {
      if (b.type != CellType::Line) continue;
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* l = b.element(e);
        if (edges.count(meshEdge(l[0], l[1])) == 0) continue;
        lines.nodes.insert(lines.nodes.end(), l, l + 2);
        lines.entity.push_back(b.entity[e]);
      }
    }
    part.blocks = {std::move(tets), std::move(tris), std::move(lines)};
    return part;
  }

  // The grown solids joined with the others. Each grown mesh starts with the volume's surface
  // nodes in their order (growLayer3D keeps them first); its own nodes follow.
  Mesh join(const std::vector<std::pair<int, Mesh>>& grown) const {
    Mesh out;
    out.dim = 3;
    out.order = 1;
    std::vector<std::int64_t> id(volume_.numNodes(), -1);
    std::vector<std::size_t> surfaceNode;  // the volume's node of each surface node
    for (std::size_t i = 0; i < volume_.numNodes(); ++i)
      if (volume_.nodeCadDim[i] < 3) {
        id[i] = out.addNode(&volume_.xyz[3 * i], volume_.nodeCadDim[i], volume_.nodeCadIndex[i],
                            volume_.nodeCadParam[2 * i], volume_.nodeCadParam[2 * i + 1]);
        surfaceNode.push_back(i);
      }
    const std::size_t surface = out.numNodes();
    ElementBlock tets, prisms, tris, quads, lines;
    tets.type = CellType::Tetrahedron;
    prisms.type = CellType::Prism;
    tris.type = CellType::Triangle;
    quads.type = CellType::Quadrilateral;
    lines.type = CellType::Line;
    const auto append = [](ElementBlock& to, const ElementBlock& from,
                           const std::vector<std::int64_t>& map, std::size_t e) {
      const std::int64_t* v = from.element(e);
      for (int k = 0; k < from.nodesPerElement(); ++k)
        to.nodes.push_back(map[static_cast<std::size_t>(v[k])]);
      to.entity.push_back(from.entity[e]);
    };
    // Per face, the solid that owns it; the curves a layer climbed (their lines use its new
    // nodes) and the surface nodes it moved (its side faces' relaxed nodes).
    std::map<int, int> owner;
    for (const auto& [face, solids] : faceSolids_)
      if (solids.size() == 1) owner[face] = *solids.begin();
    std::set<int> climbed;
    std::vector<char> moved(surface, 0);
    for (const auto& [solid, mesh] : grown) {
      std::vector<std::int64_t> map(mesh.numNodes());
      for (std::size_t j = 0; j < mesh.numNodes(); ++j) {
        if (j >= surface) {
          map[j] = out.addNode(&mesh.xyz[3 * j], mesh.nodeCadDim[j], mesh.nodeCadIndex[j],
                               mesh.nodeCadParam[2 * j], mesh.nodeCadParam[2 * j + 1]);
          continue;
        }
        map[j] = static_cast<std::int64_t>(j);
        if (sameNode(volume_, surfaceNode[j], mesh, j)) continue;
        if (moved[j] != 0)  // (requireOwnSides keeps each solid's moves on its own faces)
          throw MeshingError("two solids' boundary layers move the node at " +
                             pointText(at(mesh, static_cast<std::int64_t>(j))));
        moved[j] = 1;
        copyNode(mesh, j, out, j);
      }
      std::set<int> changed;
      for (const ElementBlock& b : mesh.blocks)
        if (b.type == CellType::Line)
          for (std::size_t e = 0; e < b.count(); ++e)
            if (static_cast<std::size_t>(std::max(b.element(e)[0], b.element(e)[1])) >= surface)
              changed.insert(b.entity[e]);
      climbed.insert(changed.begin(), changed.end());
      for (const ElementBlock& b : mesh.blocks)
        for (std::size_t e = 0; e < b.count(); ++e) {
          if (b.type == CellType::Tetrahedron) append(tets, b, map, e);
          if (b.type == CellType::Prism) append(prisms, b, map, e);
          if (b.type == CellType::Quadrilateral) append(quads, b, map, e);
          if (b.type == CellType::Triangle && owner.count(b.entity[e]) != 0 &&
              owner.at(b.entity[e]) == solid)
            append(tris, b, map, e);
          if (b.type == CellType::Line && changed.count(b.entity[e]) != 0) append(lines, b, map, e);
        }
    }
    std::set<int> grownSolids;
    for (const auto& g : grown) grownSolids.insert(g.first);
    for (const ElementBlock& b : volume_.blocks)
      for (std::size_t e = 0; e < b.count(); ++e) {
        if (b.type == CellType::Tetrahedron && grownSolids.count(b.entity[e]) == 0) {
          for (int k = 0; k < 4; ++k) {
            const auto v = static_cast<std::size_t>(b.element(e)[k]);
            if (id[v] < 0)
              id[v] =
                  out.addNode(&volume_.xyz[3 * v], volume_.nodeCadDim[v], volume_.nodeCadIndex[v],
                              volume_.nodeCadParam[2 * v], volume_.nodeCadParam[2 * v + 1]);
          }
          append(tets, b, id, e);
        }
        if (b.type == CellType::Triangle &&
            (owner.count(b.entity[e]) == 0 || grownSolids.count(owner.at(b.entity[e])) == 0))
          append(tris, b, id, e);
        if (b.type == CellType::Line && climbed.count(b.entity[e]) == 0) append(lines, b, id, e);
      }
    out.blocks.push_back(std::move(tets));
    out.blocks.push_back(std::move(prisms));
    out.blocks.push_back(std::move(tris));
    if (quads.count() > 0) out.blocks.push_back(std::move(quads));
    out.blocks.push_back(std::move(lines));
    out.checkConsistency();
    return out;
  }

  static void copyNode(const Mesh& from, std::size_t i, Mesh& to, std::size_t j) {
    for (std::size_t d = 0; d < 3; ++d) to.xyz[3 * j + d] = from.xyz[3 * i + d];
    to.nodeCadDim[j] = from.nodeCadDim[i];
    to.nodeCadIndex[j] = from.nodeCadIndex[i];
    to.nodeCadParam[2 * j] = from.nodeCadParam[2 * i];
    to.nodeCadParam[2 * j + 1] = from.nodeCadParam[2 * i + 1];
  }

  // The solids' records as one: their faces in order, counts summed, heights over all.
  void joinRecords(const std::vector<BoundaryLayerRecord>& records,
                   BoundaryLayerRecord& record) const {
    record.parameters = p_;
    record.thicknessMin = std::numeric_limits<double>::infinity();
    record.thicknessMax = 0.0;
    for (const BoundaryLayerRecord& r : records) {
      record.thicknessMin = std::min(record.thicknessMin, r.thicknessMin);
      record.thicknessMax = std::max(record.thicknessMax, r.thicknessMax);
      record.faces.insert(record.faces.end(), r.faces.begin(), r.faces.end());
      record.cells += r.cells;
      record.sideQuadrilaterals += r.sideQuadrilaterals;
      record.wallNodes += r.wallNodes;
      record.lengthened.insert(r.lengthened.begin(), r.lengthened.end());
      record.sharpColumns.insert(r.sharpColumns.begin(), r.sharpColumns.end());
      record.shrinkPasses = std::max(record.shrinkPasses, r.shrinkPasses);
    }
    std::sort(record.faces.begin(), record.faces.end(),
              [](const LayerShrink& a, const LayerShrink& b) { return a.face < b.face; });
  }
};

}  // namespace

Mesh growLayerInSolids(const Mesh& volume, const CadModel& cad, const BoundaryLayerParameters& p,
                       const LinearMeshOptions& fill, BoundaryLayerRecord& record) {
  std::set<int> solids;
  for (const ElementBlock& b : volume.blocks)
    if (b.type == CellType::Tetrahedron) solids.insert(b.entity.begin(), b.entity.end());
  for (const int s : p.solids)
    if (s > cad.numSolids())
      throw ParameterError("boundary-layer solid " + std::to_string(s) + " does not exist: " +
                           cad.sourceName() + " has " + std::to_string(cad.numSolids()) +
                           (cad.numSolids() == 1 ? " solid" : " solids"));
  if (solids.size() <= 1) return growLayer3D(volume, cad, p, fill, record);
  return SolidLayers(volume, cad, p).grow(fill, record);
}

}  // namespace homesh::layer_growth
