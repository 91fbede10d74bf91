#include "linear/cad_classification.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include "cad/point_classifier.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/parameters.hpp"
#include "linear/edge_split.hpp"

namespace homesh {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A boundary face: 3 corners (a triangle, last entry -1) or 4 (a quadrilateral), pointing out.
using Face = std::array<std::int64_t, 4>;

int faceSize(const Face& f) {
  return f[3] < 0 ? 3 : 4;
}

std::string nodeList(const std::int64_t* nodes, int count) {
  std::string out;
  for (int k = 0; k < count; ++k) out += (k == 0 ? "" : ", ") + std::to_string(nodes[k] + 1);
  return out;
}

std::string nodeList(const Face& f) {
  return nodeList(f.data(), faceSize(f));
}

// The faces of a positive linear cell as local corners in Gmsh's order, pointing out, and the
// corner swaps that turn a negative cell positive (a mirror of its reference shape).
struct CellFaces {
  std::vector<std::vector<int>> faces;
  std::vector<std::pair<int, int>> mirror;
};

const CellFaces& cellFaces(CellType type) {
  static const CellFaces tet{{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}, {{1, 2}}};
  static const CellFaces prism{{{0, 2, 1}, {3, 4, 5}, {0, 1, 4, 3}, {1, 2, 5, 4}, {0, 3, 5, 2}},
                               {{1, 2}, {4, 5}}};
  static const CellFaces pyramid{{{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}},
                                 {{1, 3}}};
  static const CellFaces hex{
      {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {0, 4, 7, 3}},
      {{1, 3}, {5, 7}}};
  switch (type) {
    case CellType::Tetrahedron:
      return tet;
    case CellType::Prism:
      return prism;
    case CellType::Pyramid:
      return pyramid;
    case CellType::Hexahedron:
      return hex;
    default:
      throw ParameterError(cellShortName(type) + " cells cannot be put on the CAD");
  }
}

// The volume cells of `linear`, refusing a mesh or CAD that cannot be put together.
std::vector<const ElementBlock*> checkedCells(const Mesh& linear, const CadModel& cad) {
  if (linear.dim != 3 || linear.order != 1)
    throw ParameterError("only a linear (order 1) volume mesh can be put on the CAD");
  std::vector<const ElementBlock*> cells;
  for (const ElementBlock& b : linear.blocks)
    if (cellDimension(b.type) == 3 && b.count() > 0) {
      cellFaces(b.type);  // (refuses a type it has no faces for)
      cells.push_back(&b);
    }
  if (cells.empty()) throw ParameterError("the mesh has no volume cells to put on the CAD");
  if (cad.numSolids() != 1)
    throw ParameterError("the CAD must be one solid to put a mesh on it, " + cad.sourceName() +
                         " has " + std::to_string(cad.numSolids()));
  return cells;
}

// The nodes of `linear`, all inside solid 1 until the boundary is classified.
Mesh nodesInSolid(const Mesh& linear) {
  Mesh mesh;
  mesh.dim = 3;
  mesh.order = 1;
  const std::size_t n = linear.numNodes();
  mesh.xyz = linear.xyz;
  mesh.nodeCadDim.assign(n, 3);
  mesh.nodeCadIndex.assign(n, 1);
  mesh.nodeCadParam.assign(2 * n, kNaN);
  return mesh;
}

// Six times the volume a cell's faces enclose (each quadrilateral as two triangles), and the
// cube of its bounding box's diagonal (measured from corner 0, which keeps the rounding to the
// cell's size).
std::pair<double, double> enclosedVolume(const Mesh& mesh, const std::int64_t* c,
                                         const CellFaces& faces, int corners) {
  const Eigen::Vector3d origin = nodePoint(mesh, c[0]);
  PointBox box;
  for (int k = 0; k < corners; ++k) box.add(nodePoint(mesh, c[k]) - origin);
  double v = 0.0;
  for (const std::vector<int>& f : faces.faces)
    for (std::size_t k = 1; k + 1 < f.size(); ++k)
      v +=
          (nodePoint(mesh, c[f[0]]) - origin)
              .dot(
                  (nodePoint(mesh, c[f[k]]) - origin).cross(nodePoint(mesh, c[f[k + 1]]) - origin));
  return {v, std::pow((box.hi - box.lo).norm(), 3)};
}

// Face use: sorted corners -> how many cells have it, pointing out of the first, which is that.
struct FaceUse {
  int count = 0;
  Face out{};
  CellType type = CellType::Tetrahedron;  // the first cell's, and its index in its block
  std::size_t element = 0;
};
using FaceUses = std::map<Face, FaceUse>;

// Whether `b` runs round the same corners as `a` in the same direction.
bool sameTurn(const Face& a, const Face& b) {
  const int n = faceSize(a);
  const auto at = std::find(b.begin(), b.begin() + n, a[0]) - b.begin();
  for (int k = 0; k < n; ++k)
    if (b[static_cast<std::size_t>((at + k) % n)] != a[static_cast<std::size_t>(k)]) return false;
  return true;
}

// Makes the cells of `cells` positive and counts their faces in `uses`.
void orientAndCountFaces(const Mesh& mesh, ElementBlock& cells, FaceUses& uses) {
  const std::size_t n = mesh.numNodes();
  const CellFaces& faces = cellFaces(cells.type);
  const int nv = cellNumVertices(cells.type);
  const std::string name = cellShortName(cells.type);
  for (std::size_t e = 0; e < cells.count(); ++e) {
    std::int64_t* c = cells.nodes.data() + static_cast<std::size_t>(nv) * e;
    for (int k = 0; k < nv; ++k)
      if (c[k] < 0 || static_cast<std::size_t>(c[k]) >= n)
        throw ParameterError(name + " " + std::to_string(e + 1) + " refers to node " +
                             std::to_string(c[k] + 1) + " of " + std::to_string(n));
    const auto [volume, size] = enclosedVolume(mesh, c, faces, nv);
    // (1e-10: far above the rounding of the sum, eps times the size cubed; far below any cell
    // a mesher means, whose volume is a fair fraction of its size cubed.)
    if (!(std::abs(volume) > 1e-10 * size))
      throw ParameterError(name + " " + std::to_string(e + 1) + " of the given mesh (nodes " +
                           nodeList(c, nv) + ") is flat (volume " + formatNumber(volume / 6.0) +
                           ", " + formatNumber(std::abs(volume) / size) +
                           " of its size cubed): no curved cell made from it can be valid");
    if (volume < 0.0)
      for (const auto& [a, b] : faces.mirror) std::swap(c[a], c[b]);
    for (const std::vector<int>& f : faces.faces) {
      Face out{-1, -1, -1, -1};
      for (std::size_t k = 0; k < f.size(); ++k) out[k] = c[f[k]];
      Face key = out;
      std::sort(key.begin(), key.begin() + static_cast<std::ptrdiff_t>(f.size()));
      auto [it, fresh] = uses.try_emplace(key, FaceUse{0, out, cells.type, e});
      // Two positive cells on either side of a face see it turn opposite ways; the same way,
      // they lie on one side of it: the mesh folds there (a cell turned inside out by a moved
      // node, which making it positive hid).
      if (++it->second.count == 2 && sameTurn(it->second.out, out))
        throw MeshingError(cellShortName(it->second.type) + " " +
                           std::to_string(it->second.element + 1) + " and " + name + " " +
                           std::to_string(e + 1) +
                           " of the given mesh overlap: both lie on one side of their face of "
                           "nodes " +
                           nodeList(out) + " (a tangled mesh cannot be curved valid)");
    }
  }
}

// The faces no other cell shares, pointing out.
std::vector<Face> boundaryFaces(const FaceUses& uses) {
  std::vector<Face> boundary;
  for (const auto& [key, entry] : uses) {
    if (entry.count > 2)
      throw ParameterError("the face of nodes " + nodeList(entry.out) + " is a face of " +
                           std::to_string(entry.count) +
                           " cells: the mesh is not a manifold volume");
    if (entry.count == 1) boundary.push_back(entry.out);
  }
  return boundary;
}

// The error for a node (`what`: "boundary node", "node") that lies on no face: its number,
// position and the nearest entity of dimension `dim` (0: none found) at `distance`.
MeshingError offCad(const std::string& what, std::size_t i, const Eigen::Vector3d& p,
                    const CadModel& cad, int dim, int nearest, double distance) {
  return MeshingError{what + " " + std::to_string(i + 1) + " at " + describePoint(p) +
                      " lies on no face of " + cad.sourceName() +
                      (nearest > 0 ? " (nearest: " + cadEntityName(dim, nearest) + " at distance " +
                                         formatNumber(distance) + ")"
                                   : "") +
                      ": is the mesh of this shape?"};
}

// Node i moved onto where it lies on the CAD, with its records.
void setPlace(Mesh& mesh, std::size_t i, const CadPlace& place) {
  mesh.nodeCadDim[i] = static_cast<std::uint8_t>(place.dim);
  mesh.nodeCadIndex[i] = place.index;
  mesh.nodeCadParam[2 * i] = place.u;
  mesh.nodeCadParam[2 * i + 1] = place.v;
  Eigen::Vector3d::Map(&mesh.xyz[3 * i]) = place.point;
}

// Boundary nodes on the CAD (snapped onto it: within the tolerance of where they were).
CadClassificationStats placeBoundaryNodes(Mesh& mesh, const std::vector<Face>& boundary,
                                          const CadPointClassifier& classifier,
                                          const CadModel& cad) {
  const std::size_t n = mesh.numNodes();
  std::vector<char> onBoundary(n, 0);
  for (const Face& f : boundary)
    for (int k = 0; k < faceSize(f); ++k) onBoundary[static_cast<std::size_t>(f[k])] = 1;
  CadClassificationStats s;
  for (std::size_t i = 0; i < n; ++i) {
    if (onBoundary[i] == 0) continue;
    const Eigen::Vector3d p = nodePoint(mesh, static_cast<std::int64_t>(i));
    std::pair<int, double> nearest{0, 0.0};
    const CadPlace place = classifier.classify(p, nearest);
    if (place.dim < 0) throw offCad("boundary node", i, p, cad, 2, nearest.first, nearest.second);
    setPlace(mesh, i, place);
    ++s.boundaryNodes;
    ++(place.dim == 0 ? s.onVertices : place.dim == 1 ? s.onEdges : s.onFaces);
    s.maxDistance = std::max(s.maxDistance, place.distance);
  }
  return s;
}

// The CAD face a boundary face lies on: the one its nodes share (nearest its centroid when
// several do).
int faceOfBoundaryFace(const Face& f, const Mesh& mesh, const CadPointClassifier& classifier,
                       const CadModel& cad) {
  const int nf = faceSize(f);
  std::vector<std::pair<int, int>> places;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int k = 0; k < nf; ++k) {
    places.emplace_back(mesh.nodeCadDim[f[k]], mesh.nodeCadIndex[f[k]]);
    centroid += nodePoint(mesh, f[k]);
  }
  centroid /= nf;
  const int face = classifier.sharedFace(places, centroid);
  if (face == 0)
    throw MeshingError("the boundary " + std::string(nf == 3 ? "triangle" : "quadrilateral") +
                       " of nodes " + nodeList(f) + " near " + describePoint(centroid) +
                       " spans more than one face of " + cad.sourceName() +
                       ": the mesh does not follow the CAD's faces");
  return face;
}

// The CAD edge the segment (a, b) lies on, or 0 when it lies on none.
int edgeOfSegment(std::int64_t a, std::int64_t b, const Mesh& mesh,
                  const CadPointClassifier& classifier) {
  return classifier.sharedEdge({mesh.nodeCadDim[a], mesh.nodeCadIndex[a]},
                               {mesh.nodeCadDim[b], mesh.nodeCadIndex[b]}, nodePoint(mesh, a),
                               nodePoint(mesh, b));
}

// The boundary's cells: triangles and quadrilaterals on the CAD face their nodes share, segments
// on the CAD edge theirs share.
struct BoundaryCells {
  ElementBlock tris, quads, lines;
};

BoundaryCells boundaryCells(const Mesh& mesh, const std::vector<Face>& boundary,
                            const CadPointClassifier& classifier, const CadModel& cad) {
  BoundaryCells out;
  out.tris.type = CellType::Triangle;
  out.quads.type = CellType::Quadrilateral;
  out.lines.type = CellType::Line;
  std::set<std::pair<std::int64_t, std::int64_t>> seen;
  for (const Face& f : boundary) {
    const int nf = faceSize(f);
    ElementBlock& cells = nf == 3 ? out.tris : out.quads;
    cells.nodes.insert(cells.nodes.end(), f.begin(), f.begin() + nf);
    cells.entity.push_back(faceOfBoundaryFace(f, mesh, classifier, cad));
    for (int k = 0; k < nf; ++k) {
      const std::int64_t a = f[k], b = f[(k + 1) % nf];
      if (!seen.insert({std::min(a, b), std::max(a, b)}).second) continue;
      const int edge = edgeOfSegment(a, b, mesh, classifier);
      if (edge == 0) continue;
      out.lines.nodes.insert(out.lines.nodes.end(), {a, b});
      out.lines.entity.push_back(edge);
    }
  }
  return out;
}

// Twice the signed area of a linear 2D cell along `normal` (a quadrilateral's from its
// diagonals), and the square of its bounding box's diagonal.
std::pair<double, double> signedArea(const Mesh& mesh, const std::int64_t* c, int corners,
                                     const Eigen::Vector3d& normal) {
  const Eigen::Vector3d a = nodePoint(mesh, c[0]);
  PointBox box;
  for (int k = 0; k < corners; ++k) box.add(nodePoint(mesh, c[k]) - a);
  const Eigen::Vector3d d1 = nodePoint(mesh, c[corners == 3 ? 1 : 2]) - a;
  const Eigen::Vector3d d2 = corners == 3
                                 ? Eigen::Vector3d(nodePoint(mesh, c[2]) - a)
                                 : Eigen::Vector3d(nodePoint(mesh, c[3]) - nodePoint(mesh, c[1]));
  return {d1.cross(d2).dot(normal), (box.hi - box.lo).squaredNorm()};
}

// The 2D cells of `linear` made counter-clockwise around its plane's normal, with their sides
// counted (sorted pair -> uses, the first cell's direction).
struct SideUse {
  int count = 0;
  std::int64_t from = 0, to = 0;
};

void orientPlanarCells(Mesh& mesh, ElementBlock& cells,
                       std::map<std::pair<std::int64_t, std::int64_t>, SideUse>& sides) {
  const Eigen::Vector3d normal(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
  const int nv = cellNumVertices(cells.type);
  const std::string name = cellShortName(cells.type);
  for (std::size_t e = 0; e < cells.count(); ++e) {
    std::int64_t* c = cells.nodes.data() + static_cast<std::size_t>(nv) * e;
    for (int k = 0; k < nv; ++k)
      if (c[k] < 0 || static_cast<std::size_t>(c[k]) >= mesh.numNodes())
        throw ParameterError(name + " " + std::to_string(e + 1) + " refers to node " +
                             std::to_string(c[k] + 1) + " of " + std::to_string(mesh.numNodes()));
    const auto [area, size] = signedArea(mesh, c, nv, normal);
    // (1e-10 of its size squared: far above rounding, far below any cell a mesher means.)
    if (!(std::abs(area) > 1e-10 * size))
      throw ParameterError(name + " " + std::to_string(e + 1) + " of the given mesh (nodes " +
                           nodeList(c, nv) + ") is flat: no curved cell made from it can be valid");
    if (area < 0.0) std::swap(c[1], c[nv - 1]);  // a mirror keeps corner 0
    for (int k = 0; k < nv; ++k) {
      const std::int64_t a = c[k], b = c[(k + 1) % nv];
      SideUse& use = sides[{std::min(a, b), std::max(a, b)}];
      if (++use.count == 1) {
        use.from = a, use.to = b;
      } else if (use.from == a) {  // two counter-clockwise cells run a side the same way: a fold
        throw MeshingError(
            "two cells of the given mesh overlap: both lie on one side of their "
            "side of nodes " +
            std::to_string(a + 1) + ", " + std::to_string(b + 1) +
            " (a tangled mesh cannot be curved valid)");
      }
    }
  }
}

// A planar linear 2D mesh (triangles, quadrilaterals) on a CAD of faces without solids: every
// node classified (interior nodes on their face, with (u, v)), each cell on the face its nodes
// share, each boundary side a line on the CAD edge its nodes share.
Mesh classifyPlanarOnCad(const Mesh& linear, const CadModel& cad, double tolerance,
                         CadClassificationStats* stats) {
  if (linear.order != 1) throw ParameterError("only a linear (order 1) mesh can be put on the CAD");
  if (linear.isSurface())
    throw ParameterError(
        "a 2D mesh on curved faces (a surface mesh) cannot be put on the CAD: "
        "homesh curve takes volume meshes and 2D meshes in a plane");
  if (cad.numSolids() != 0 || cad.numFaces() < 1)
    throw ParameterError("a 2D mesh is put on a CAD of faces without solids, " + cad.sourceName() +
                         " has " + std::to_string(cad.numSolids()) + " solids and " +
                         std::to_string(cad.numFaces()) + " faces");
  if (!(tolerance > 0.0))
    tolerance = parameterDefault("classify_tolerance") * cad.boundingDiagonal();
  Mesh mesh;
  mesh.dim = 2;
  mesh.order = 1;
  mesh.planeNormal = linear.planeNormal;
  const std::size_t n = linear.numNodes();
  mesh.xyz = linear.xyz;
  mesh.nodeCadDim.assign(n, 2);
  mesh.nodeCadIndex.assign(n, 0);
  mesh.nodeCadParam.assign(2 * n, kNaN);
  std::map<std::pair<std::int64_t, std::int64_t>, SideUse> sides;
  std::vector<char> used(n, 0);
  for (const ElementBlock& b : linear.blocks) {
    if (cellDimension(b.type) != 2 || b.count() == 0) continue;
    ElementBlock cells;
    cells.type = b.type;
    cells.nodes = b.nodes;
    cells.entity.assign(b.count(), 0);
    orientPlanarCells(mesh, cells, sides);
    for (const std::int64_t id : cells.nodes) used[static_cast<std::size_t>(id)] = 1;
    mesh.blocks.push_back(std::move(cells));
  }
  if (mesh.blocks.empty()) throw ParameterError("the mesh has no 2D cells to put on the CAD");
  const CadPointClassifier classifier(cad, tolerance);
  CadClassificationStats s;
  for (std::size_t i = 0; i < n; ++i) {
    if (used[i] == 0) continue;
    const Eigen::Vector3d p = nodePoint(mesh, static_cast<std::int64_t>(i));
    std::pair<int, double> nearest{0, 0.0};
    const CadPlace place = classifier.classify(p, nearest);
    if (place.dim < 0) {
      // In the plane a node off the faces lies beyond their edges: the nearest edge says how far
      // (a face's own distance, that of its untrimmed plane, would be 0).
      int edge = 0;
      double distance = std::numeric_limits<double>::infinity();
      for (int e = 1; e <= cad.numEdges(); ++e) {
        if (cad.isDegenerated(e)) continue;
        const double d = cad.projectOnCurve(e, p).distance;
        if (d < distance) distance = d, edge = e;
      }
      throw offCad("node", i, p, cad, 1, edge, distance);
    }
    setPlace(mesh, i, place);
    if (place.dim < 2) {
      ++s.boundaryNodes;
      ++(place.dim == 0 ? s.onVertices : s.onEdges);
    } else {
      ++s.onFaces;
    }
    s.maxDistance = std::max(s.maxDistance, place.distance);
  }
  for (ElementBlock& b : mesh.blocks) {
    const int nv = cellNumVertices(b.type);
    for (std::size_t e = 0; e < b.count(); ++e) {
      // The face whose trimmed domain holds the cell's centroid: the faces its nodes share may
      // be none where a model's faces do not share their curves (a STEP file of a compound,
      // each face with its own copy of the curve between them).
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int k = 0; k < nv; ++k) centroid += nodePoint(mesh, b.element(e)[k]);
      std::pair<int, double> nearest{0, 0.0};
      const CadPlace inside = classifier.classify(centroid / nv, nearest);
      if (inside.dim == 2) {
        b.entity[e] = inside.index;
        continue;
      }
      Face f{-1, -1, -1, -1};
      std::copy(b.element(e), b.element(e) + nv, f.begin());
      b.entity[e] = faceOfBoundaryFace(f, mesh, classifier, cad);
    }
  }
  ElementBlock lines;
  lines.type = CellType::Line;
  for (const auto& [key, use] : sides) {
    if (use.count > 2)
      throw ParameterError("the side of nodes " + std::to_string(key.first + 1) + ", " +
                           std::to_string(key.second + 1) + " is a side of " +
                           std::to_string(use.count) + " cells: the mesh is not a manifold");
    // An inner side on a CAD curve (between two faces of the model) is a line too, so that it
    // is curved on the curve as `homesh mesh` curves it.
    const bool inner = use.count == 2;
    if (inner && (mesh.nodeCadDim[use.from] > 1 || mesh.nodeCadDim[use.to] > 1)) continue;
    const int edge = edgeOfSegment(use.from, use.to, mesh, classifier);
    if (edge == 0 && inner) continue;
    if (edge == 0)
      throw MeshingError(
          "the boundary side of nodes " + std::to_string(use.from + 1) + ", " +
          std::to_string(use.to + 1) + " near " +
          describePoint(0.5 * (nodePoint(mesh, use.from) + nodePoint(mesh, use.to))) +
          " lies on no edge of " + cad.sourceName() + ": the mesh does not follow the CAD's edges");
    lines.nodes.insert(lines.nodes.end(), {use.from, use.to});
    lines.entity.push_back(edge);
  }
  s.boundarySegments = lines.count();
  mesh.blocks.push_back(std::move(lines));
  compactNodes(mesh);
  mesh.checkConsistency();
  if (stats != nullptr) *stats = s;
  return mesh;
}

}  // namespace

Mesh classifyOnCad(const Mesh& linear, const CadModel& cad, double tolerance,
                   CadClassificationStats* stats) {
  if (linear.dim == 2) return classifyPlanarOnCad(linear, cad, tolerance, stats);
  const std::vector<const ElementBlock*> given = checkedCells(linear, cad);
  if (!(tolerance > 0.0))
    tolerance = parameterDefault("classify_tolerance") * cad.boundingDiagonal();
  Mesh mesh = nodesInSolid(linear);
  FaceUses uses;
  for (const ElementBlock* b : given) {
    ElementBlock cells;
    cells.type = b->type;
    cells.nodes = b->nodes;
    cells.entity.assign(b->count(), 1);
    orientAndCountFaces(mesh, cells, uses);
    mesh.blocks.push_back(std::move(cells));
  }
  const std::vector<Face> boundary = boundaryFaces(uses);
  const CadPointClassifier classifier(cad, tolerance);
  CadClassificationStats s = placeBoundaryNodes(mesh, boundary, classifier, cad);
  BoundaryCells cells = boundaryCells(mesh, boundary, classifier, cad);
  s.boundaryTriangles = cells.tris.count();
  s.boundaryQuadrilaterals = cells.quads.count();
  s.boundarySegments = cells.lines.count();
  for (ElementBlock* b : {&cells.tris, &cells.quads, &cells.lines})
    if (b->count() > 0) mesh.blocks.push_back(std::move(*b));
  compactNodes(mesh);  // nodes no cell uses (a quadratic mesh's mid-edge nodes)
  mesh.checkConsistency();
  if (stats != nullptr) *stats = s;
  return mesh;
}

const std::vector<std::vector<int>>& cellFaceCorners(CellType type) {
  return cellFaces(type).faces;
}

}  // namespace homesh
