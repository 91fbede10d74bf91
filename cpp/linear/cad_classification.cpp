#include "linear/cad_classification.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/parameters.hpp"
#include "linear/edge_split.hpp"

namespace homesh {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A box around sampled points of an entity, grown by `margin`: points farther out cannot lie on
// the entity (the margin covers the bulge between samples).
struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(std::numeric_limits<double>::lowest());
  void add(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void grow(double fraction, double absolute) {
    const double m = fraction * (hi - lo).norm() + absolute;
    lo.array() -= m;
    hi.array() += m;
  }
  bool contains(const Eigen::Vector3d& p) const {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  }
};

// Where a boundary node lies.
struct Place {
  int dim = -1, index = 0;
  double u = kNaN, v = kNaN;
  Eigen::Vector3d point;
  double distance = 0.0;
};

class Classifier {
 public:
  Classifier(const CadModel& cad, double tolerance) : cad_(cad), tol_(tolerance) {
    const int kSamples = 9;
    edgeBoxes_.resize(cad.numEdges() + 1);
    faceBoxes_.resize(cad.numFaces() + 1);
    vertexEdges_.resize(cad.numVertices() + 1);
    edgeFaces_.resize(cad.numEdges() + 1);
    for (int e = 1; e <= cad.numEdges(); ++e) {
      for (const int v : cad.subShapeIndices(1, e, 0)) vertexEdges_[v].push_back(e);
      if (cad.isDegenerated(e)) continue;
      const ParameterRange r = cad.edgeRange(e);
      for (int k = 0; k <= 2 * kSamples; ++k)
        edgeBoxes_[e].add(
            cad.evaluateCurve(e, r.first + (r.last - r.first) * k / (2 * kSamples)).point);
      edgeBoxes_[e].grow(0.25, tol_);
    }
    for (int f = 1; f <= cad.numFaces(); ++f) {
      for (const int e : cad.subShapeIndices(2, f, 1)) edgeFaces_[e].push_back(f);
      const SurfaceBounds b = cad.faceBounds(f);
      for (int i = 0; i <= kSamples; ++i)
        for (int j = 0; j <= kSamples; ++j)
          faceBoxes_[f].add(cad.evaluateSurface(f, b.uMin + (b.uMax - b.uMin) * i / kSamples,
                                                b.vMin + (b.vMax - b.vMin) * j / kSamples)
                                .point);
      faceBoxes_[f].grow(0.25, tol_);
    }
  }

  // The lowest-dimensional entity `p` lies on, or dim -1 (with the nearest face's distance in
  // `nearestFace`).
  Place classify(const Eigen::Vector3d& p, std::pair<int, double>& nearestFace) const {
    Place best;
    for (int v = 1; v <= cad_.numVertices(); ++v) {
      const Eigen::Vector3d q = cad_.vertexPoint(v);
      const double d = (q - p).norm();
      if (d <= tol_ + cad_.tolerance(0, v) && (best.dim < 0 || d < best.distance)) {
        best = Place{0, v, kNaN, kNaN, q, d};
      }
    }
    if (best.dim >= 0) return best;
    for (int e = 1; e <= cad_.numEdges(); ++e) {
      if (cad_.isDegenerated(e) || !edgeBoxes_[e].contains(p)) continue;
      const CurveProjection c = cad_.projectOnCurve(e, p);
      if (c.distance <= tol_ + cad_.tolerance(1, e) && (best.dim < 0 || c.distance < best.distance))
        best = Place{1, e, c.t, kNaN, c.point, c.distance};
    }
    if (best.dim >= 0) return best;
    nearestFace = {0, std::numeric_limits<double>::infinity()};
    for (int f = 1; f <= cad_.numFaces(); ++f) {
      if (!faceBoxes_[f].contains(p)) continue;
      const SurfaceProjection s = cad_.projectOnSurface(f, p);
      if (s.distance < nearestFace.second) nearestFace = {f, s.distance};
      if (s.distance > tol_ + cad_.tolerance(2, f)) continue;
      if (!cad_.faceContains(f, cad_.wrapIntoPeriod(f, s.u, 0), cad_.wrapIntoPeriod(f, s.v, 1)))
        continue;
      if (best.dim < 0 || s.distance < best.distance)
        best = Place{2, f, s.u, s.v, s.point, s.distance};
    }
    return best;
  }

  // The CAD faces a node on entity (dim, index) may belong to.
  std::set<int> facesOf(int dim, int index) const {
    std::set<int> out;
    if (dim == 2) out.insert(index);
    if (dim == 1) out.insert(edgeFaces_[index].begin(), edgeFaces_[index].end());
    if (dim == 0)
      for (const int e : vertexEdges_[index])
        out.insert(edgeFaces_[e].begin(), edgeFaces_[e].end());
    return out;
  }

  // The CAD edges a node on entity (dim, index) may belong to.
  std::set<int> edgesOf(int dim, int index) const {
    std::set<int> out;
    if (dim == 1) out.insert(index);
    if (dim == 0) out.insert(vertexEdges_[index].begin(), vertexEdges_[index].end());
    return out;
  }

 private:
  const CadModel& cad_;
  double tol_;
  std::vector<Box> edgeBoxes_, faceBoxes_;
  std::vector<std::vector<int>> vertexEdges_, edgeFaces_;
};

using Face = std::array<std::int64_t, 3>;

std::string describe(const Eigen::Vector3d& p) {
  std::ostringstream s;
  s << "(" << formatNumber(p.x()) << ", " << formatNumber(p.y()) << ", " << formatNumber(p.z())
    << ")";
  return s.str();
}

// The tetrahedra of `linear`, refusing a mesh or CAD that cannot be put together.
const ElementBlock& checkedTetrahedra(const Mesh& linear, const CadModel& cad) {
  if (linear.dim != 3 || linear.order != 1)
    throw ParameterError("only a linear (order 1) tetrahedral mesh can be put on the CAD");
  const ElementBlock* tets = nullptr;
  for (const ElementBlock& b : linear.blocks)
    if (b.type == CellType::Tetrahedron) tets = &b;
  if (tets == nullptr || tets->count() == 0)
    throw ParameterError("the mesh has no tetrahedra to put on the CAD");
  if (cad.numSolids() != 1)
    throw ParameterError("the CAD must be one solid to put a mesh on it, " + cad.sourceName() +
                         " has " + std::to_string(cad.numSolids()));
  return *tets;
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

// Makes the tetrahedra of `cells` positive and returns their faces that no other tetrahedron
// shares, pointing out.
std::vector<Face> orientAndFindBoundary(const Mesh& mesh, ElementBlock& cells) {
  const std::size_t n = mesh.numNodes();
  std::map<Face, std::pair<int, Face>> faces;  // sorted face -> (count, outward face)
  for (std::size_t e = 0; e < cells.count(); ++e) {
    std::int64_t* t = cells.nodes.data() + 4 * e;
    for (int k = 0; k < 4; ++k)
      if (t[k] < 0 || static_cast<std::size_t>(t[k]) >= n)
        throw ParameterError("tetrahedron " + std::to_string(e + 1) + " refers to node " +
                             std::to_string(t[k] + 1) + " of " + std::to_string(n));
    const Eigen::Vector3d a = nodePoint(mesh, t[0]);
    const double volume =
        (nodePoint(mesh, t[1]) - a).cross(nodePoint(mesh, t[2]) - a).dot(nodePoint(mesh, t[3]) - a);
    if (volume == 0.0)
      throw ParameterError("tetrahedron " + std::to_string(e + 1) + " is flat (zero volume)");
    if (volume < 0.0) std::swap(t[1], t[2]);
    // Outward faces of a positive tetrahedron (Gmsh's corner order).
    const std::array<Face, 4> out = {Face{t[0], t[2], t[1]}, Face{t[0], t[1], t[3]},
                                     Face{t[0], t[3], t[2]}, Face{t[1], t[2], t[3]}};
    for (const Face& f : out) {
      Face key = f;
      std::sort(key.begin(), key.end());
      auto [it, fresh] = faces.try_emplace(key, 0, f);
      ++it->second.first;
    }
  }
  std::vector<Face> boundary;
  for (const auto& [key, entry] : faces) {
    if (entry.first > 2)
      throw ParameterError("a triangle is a face of " + std::to_string(entry.first) +
                           " tetrahedra: the mesh is not a manifold volume");
    if (entry.first == 1) boundary.push_back(entry.second);
  }
  return boundary;
}

// Boundary nodes on the CAD (snapped onto it: within the tolerance of where they were).
CadClassificationStats placeBoundaryNodes(Mesh& mesh, const std::vector<Face>& boundary,
                                          const Classifier& classifier, const CadModel& cad) {
  const std::size_t n = mesh.numNodes();
  std::vector<char> onBoundary(n, 0);
  for (const Face& f : boundary)
    for (const std::int64_t v : f) onBoundary[static_cast<std::size_t>(v)] = 1;
  CadClassificationStats s;
  for (std::size_t i = 0; i < n; ++i) {
    if (onBoundary[i] == 0) continue;
    const Eigen::Vector3d p = nodePoint(mesh, static_cast<std::int64_t>(i));
    std::pair<int, double> nearest{0, 0.0};
    const Place place = classifier.classify(p, nearest);
    if (place.dim < 0)
      throw MeshingError("boundary node " + std::to_string(i + 1) + " at " + describe(p) +
                         " lies on no face of " + cad.sourceName() +
                         (nearest.first > 0
                              ? " (nearest: " + cadEntityName(2, nearest.first) + " at distance " +
                                    formatNumber(nearest.second) + ")"
                              : "") +
                         ": is the mesh of this shape?");
    mesh.nodeCadDim[i] = static_cast<std::uint8_t>(place.dim);
    mesh.nodeCadIndex[i] = place.index;
    mesh.nodeCadParam[2 * i] = place.u;
    mesh.nodeCadParam[2 * i + 1] = place.v;
    Eigen::Vector3d::Map(&mesh.xyz[3 * i]) = place.point;
    ++s.boundaryNodes;
    ++(place.dim == 0 ? s.onVertices : place.dim == 1 ? s.onEdges : s.onFaces);
    s.maxDistance = std::max(s.maxDistance, place.distance);
  }
  return s;
}

// The CAD face a boundary triangle lies on: the one its nodes share (nearest its centroid when
// several do).
int faceOfTriangle(const Face& f, const Mesh& mesh, const Classifier& classifier,
                   const CadModel& cad) {
  std::set<int> common = classifier.facesOf(mesh.nodeCadDim[f[0]], mesh.nodeCadIndex[f[0]]);
  for (int k = 1; k < 3; ++k) {
    const std::set<int> other = classifier.facesOf(mesh.nodeCadDim[f[k]], mesh.nodeCadIndex[f[k]]);
    std::set<int> both;
    std::set_intersection(common.begin(), common.end(), other.begin(), other.end(),
                          std::inserter(both, both.begin()));
    common = std::move(both);
  }
  const Eigen::Vector3d centroid =
      (nodePoint(mesh, f[0]) + nodePoint(mesh, f[1]) + nodePoint(mesh, f[2])) / 3.0;
  if (common.empty())
    throw MeshingError("the boundary triangle of nodes " + std::to_string(f[0] + 1) + ", " +
                       std::to_string(f[1] + 1) + ", " + std::to_string(f[2] + 1) + " near " +
                       describe(centroid) + " spans more than one face of " + cad.sourceName() +
                       ": the mesh does not follow the CAD's faces");
  int face = *common.begin();
  if (common.size() > 1) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const int c : common) {
      const double d = cad.projectOnSurface(c, centroid).distance;
      if (d < nearest) nearest = d, face = c;
    }
  }
  return face;
}

// The CAD edge the segment (a, b) lies on, or 0 when it lies on none.
int edgeOfSegment(std::int64_t a, std::int64_t b, const Mesh& mesh, const Classifier& classifier,
                  const CadModel& cad, double tolerance) {
  const std::set<int> ea = classifier.edgesOf(mesh.nodeCadDim[a], mesh.nodeCadIndex[a]);
  const std::set<int> eb = classifier.edgesOf(mesh.nodeCadDim[b], mesh.nodeCadIndex[b]);
  std::vector<int> shared;
  std::set_intersection(ea.begin(), ea.end(), eb.begin(), eb.end(), std::back_inserter(shared));
  if (shared.empty()) return 0;
  // A chord of its edge bulges from it by at most 0.29 of its length for arcs up to 120
  // degrees; a segment across a face between two vertices of one edge (a cap of two
  // half circles) lies 0.5 of its length away: not on the edge.
  const Eigen::Vector3d pa = nodePoint(mesh, a), pb = nodePoint(mesh, b);
  const Eigen::Vector3d mid = 0.5 * (pa + pb);
  int edge = 0;
  double nearest = std::numeric_limits<double>::infinity();
  for (const int e : shared) {
    if (cad.isDegenerated(e)) continue;
    const double d = cad.projectOnCurve(e, mid).distance;
    if (d < nearest) nearest = d, edge = e;
  }
  if (edge == 0 || nearest > 0.3 * (pb - pa).norm() + tolerance) return 0;
  return edge;
}

// Boundary triangles on the face their nodes share; segments on the edge theirs share.
std::pair<ElementBlock, ElementBlock> boundaryCells(const Mesh& mesh,
                                                    const std::vector<Face>& boundary,
                                                    const Classifier& classifier,
                                                    const CadModel& cad, double tolerance) {
  ElementBlock tris, lines;
  tris.type = CellType::Triangle;
  lines.type = CellType::Line;
  std::set<std::pair<std::int64_t, std::int64_t>> seen;
  for (const Face& f : boundary) {
    const int face = faceOfTriangle(f, mesh, classifier, cad);
    tris.nodes.insert(tris.nodes.end(), f.begin(), f.end());
    tris.entity.push_back(face);
    for (int k = 0; k < 3; ++k) {
      std::int64_t a = f[k], b = f[(k + 1) % 3];
      if (!seen.insert({std::min(a, b), std::max(a, b)}).second) continue;
      const int edge = edgeOfSegment(a, b, mesh, classifier, cad, tolerance);
      if (edge == 0) continue;
      lines.nodes.insert(lines.nodes.end(), {a, b});
      lines.entity.push_back(edge);
    }
  }
  return {std::move(tris), std::move(lines)};
}

}  // namespace

Mesh classifyOnCad(const Mesh& linear, const CadModel& cad, double tolerance,
                   CadClassificationStats* stats) {
  const ElementBlock& tets = checkedTetrahedra(linear, cad);
  if (!(tolerance > 0.0))
    tolerance = parameterDefault("classify_tolerance") * cad.boundingDiagonal();
  Mesh mesh = nodesInSolid(linear);
  ElementBlock cells;
  cells.type = CellType::Tetrahedron;
  cells.nodes = tets.nodes;
  cells.entity.assign(tets.count(), 1);
  const std::vector<Face> boundary = orientAndFindBoundary(mesh, cells);
  const Classifier classifier(cad, tolerance);
  CadClassificationStats s = placeBoundaryNodes(mesh, boundary, classifier, cad);
  auto [tris, lines] = boundaryCells(mesh, boundary, classifier, cad, tolerance);
  s.boundaryTriangles = tris.count();
  s.boundarySegments = lines.count();
  mesh.blocks = {std::move(cells), std::move(tris), std::move(lines)};
  compactNodes(mesh);  // nodes no tetrahedron uses (a quadratic mesh's mid-edge nodes)
  mesh.checkConsistency();
  if (stats != nullptr) *stats = s;
  return mesh;
}

}  // namespace homesh
